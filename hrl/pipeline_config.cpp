#include "hrl/pipeline_config.h"

#include <cmath>

namespace segue {

CollectConfig CollectConfig::read(const Section& s) {
  CollectConfig c;
  c.start_states = s.get("start_states", c.start_states);
  c.demonstrations = s.get("demonstrations", c.demonstrations);
  if (c.start_states <= 0) throw s.error("start_states", "must be positive");
  if (c.demonstrations <= 0) throw s.error("demonstrations", "must be positive");
  return c;
}

TransitionPolicyConfig TransitionPolicyConfig::read(const Section& s, int obs_dim) {
  TransitionPolicyConfig c;
  c.ppo.lr = 1e-4;  // policy Adam 1e-4 (spec)
  c.ppo.total_steps = 1'000'000;
  c.ppo.steps_per_env = 256;
  c.ppo.minibatch_size = 512;
  c.ppo = PpoConfig::read(s.sub("ppo"), c.ppo);
  Section pol = s.sub("policy");
  c.net.pi_hidden = pol.layers("pi_hidden", c.net.pi_hidden);
  c.net.vf_hidden = pol.layers("vf_hidden", std::vector<int>{64, 64});
  c.net.init_log_std = pol.get("init_log_std", -1.0);
  c.init_from_next = s.get("init_from_next", c.init_from_next);
  c.reward = s.get("reward", c.reward);
  if (c.reward != "airl" && c.reward != "airl_absorbing" && c.reward != "airl_nonnegative")
    throw s.error("reward", "must be airl (Eq. 3), airl_absorbing or airl_nonnegative (-log(1 - D))");
  Section d = s.sub("discriminator");
  c.discriminator.hidden = d.layers("hidden", c.discriminator.hidden);
  c.disc_lr = d.get("lr", c.disc_lr);
  c.disc_batch = d.get("batch", c.disc_batch);
  c.disc_steps = d.get("steps", c.disc_steps);
  c.gradient_penalty = d.get("gradient_penalty", c.gradient_penalty);
  if (d.has("fourier")) c.discriminator.features = ObsFeatures::read(d.sub("fourier"), obs_dim);
  if (c.disc_batch <= 0) throw d.error("batch", "must be positive");
  if (c.disc_steps < 0) throw d.error("steps", "must be >= 0");
  if (!(c.disc_lr > 0)) throw d.error("lr", "must be positive");
  if (!(c.gradient_penalty >= 0)) throw d.error("gradient_penalty", "must be >= 0");
  return c;
}

ActorCriticSpec TransitionPolicyConfig::network(const EnvSpec& env, const Policy& next) const {
  ActorCriticSpec n = net;
  n.obs_dim = env.obs_dim;
  n.act_dim = env.act_dim;
  if (init_from_next) n.features = next.features();
  return n;
}

SwitchConfig SwitchConfig::read(const Section& s, int obs_dim) {
  SwitchConfig c;
  c.net.hidden = s.layers("hidden", c.net.hidden);
  c.net.gamma = s.get("gamma", c.net.gamma);
  c.lr = s.get("lr", c.lr);
  c.batch = s.get("batch", c.batch);
  c.replay = s.get("replay", c.replay);
  c.target_every = s.get("target_every", c.target_every);
  c.r_success = s.get("r_success", c.r_success);
  c.r_fail = s.get("r_fail", c.r_fail);
  c.attempts = s.get("attempts", c.attempts);
  c.updates_per_attempt = s.get("updates_per_attempt", c.updates_per_attempt);
  c.warmup = s.get("warmup", c.warmup);
  c.epsilon_start = s.get("epsilon_start", c.epsilon_start);
  c.epsilon_end = s.get("epsilon_end", c.epsilon_end);
  c.explore_fraction = s.get("explore_fraction", c.explore_fraction);
  c.max_subtask_steps = s.get("max_subtask_steps", c.max_subtask_steps);
  c.lookahead = s.get("lookahead", c.lookahead);
  c.validation_starts = s.get("validation_starts", c.validation_starts);
  c.margins = s.get("margins", c.margins);
  c.interval_features = s.get("interval_features", c.interval_features);
  c.ensemble = s.get("ensemble", c.ensemble);
  if (c.ensemble < 1) throw s.error("ensemble", "must be at least 1");
  if (s.has("fourier")) c.features = ObsFeatures::read(s.sub("fourier"), obs_dim);  // only when given
  if (!(c.net.gamma > 0 && c.net.gamma <= 1)) throw s.error("gamma", "must be in (0, 1]");
  if (c.validation_starts < 0) throw s.error("validation_starts", "must be >= 0");
  if (c.margins.empty()) throw s.error("margins", "lists no margin");
  for (double m : c.margins)
    if (!std::isfinite(m)) throw s.error("margins", "must be finite numbers");
  if (c.lookahead < 1) throw s.error("lookahead", "must be at least 1");
  if (c.batch <= 0) throw s.error("batch", "must be positive");
  if (c.replay < c.batch) throw s.error("replay", "must hold at least one batch");
  if (c.target_every <= 0) throw s.error("target_every", "must be positive");
  if (c.attempts < 0) throw s.error("attempts", "must be >= 0");
  if (!(c.lr > 0)) throw s.error("lr", "must be positive");
  if (!(c.explore_fraction > 0)) throw s.error("explore_fraction", "must be positive");
  return c;
}

LeeConfig LeeConfig::read(const Section& s) {
  LeeConfig c;
  c.enabled = s.get("enabled", c.enabled);
  c.hidden = s.layers("hidden", c.hidden);
  c.lr = s.get("lr", c.lr);
  c.batch = s.get("batch", c.batch);
  c.steps = s.get("steps", c.steps);
  c.decay = s.get("decay", c.decay);
  c.max_rows = s.get("max_rows", c.max_rows);
  c.termination_bias = s.get("termination_bias", c.termination_bias);
  if (c.batch <= 0) throw s.error("batch", "must be positive");
  if (c.max_rows <= 0) throw s.error("max_rows", "must be positive");
  if (!(c.decay > 0 && c.decay <= 1)) throw s.error("decay", "must be in (0, 1]");
  return c;
}

PipelineConfig PipelineConfig::read(const Section& root, const std::string& task, int obs_dim) {
  PipelineConfig c;
  c.run_dir = root.get("run_dir", "runs/" + task);
  c.seed = root.get<uint64_t>("seed", c.seed);
  c.threads = root.get("threads", c.threads);
  if (c.threads < 0) throw root.error("threads", "must be >= 0 (0: all cores)");
  c.collect = CollectConfig::read(root.sub("collect"));
  c.transition = TransitionPolicyConfig::read(root.sub("transition"), obs_dim);
  c.switching = SwitchConfig::read(root.sub("switch"), obs_dim);
  c.lee = LeeConfig::read(root.sub("lee"));
  return c;
}

}  // namespace segue
