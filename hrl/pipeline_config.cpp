#include "hrl/pipeline_config.h"

#include <algorithm>
#include <cmath>

#include "core/thread_pool.h"

namespace segue {
namespace {
// Bounds on what a run stores (rows of states or demonstrations, a replay buffer) and on a
// batch, so that a typo of 1e12 is refused before work rather than exhausting memory later.
constexpr double kMaxRows = 1e8, kMaxBatch = 1e6;
}  // namespace

CollectConfig CollectConfig::read(const Section& s) {
  CollectConfig c;
  c.start_states = s.get("start_states", c.start_states, Range::closed(1, kMaxRows));
  c.demonstrations = s.get("demonstrations", c.demonstrations, Range::closed(1, kMaxRows));
  return c;
}

TransitionPolicyConfig TransitionPolicyConfig::read(const Section& s) {
  TransitionPolicyConfig c;
  c.ppo.lr = 1e-4;  // policy Adam 1e-4, the paper's text (docs/reference/learners.md)
  c.ppo.total_steps = 1'000'000;
  c.ppo.steps_per_env = 256;
  c.ppo.minibatch_size = 512;
  c.ppo = PpoConfig::read(s.sub("ppo"), c.ppo);
  Section pol = s.sub("policy");
  c.net.pi_hidden = pol.layers("pi_hidden", c.net.pi_hidden);
  c.net.vf_hidden = pol.layers("vf_hidden", std::vector<int>{64, 64});
  c.net.init_log_std = pol.get("init_log_std", -1.0, Range::any());
  c.init_from_next = s.get("init_from_next", c.init_from_next);
  // airl: Eq. 3; airl_nonnegative: -log(1 - D).
  c.reward = s.choice("reward", c.reward, {"airl", "airl_absorbing", "airl_nonnegative"});
  Section d = s.sub("discriminator");
  c.discriminator.hidden = d.layers("hidden", c.discriminator.hidden);
  c.disc_lr = d.get("lr", c.disc_lr, Range::positive());
  c.disc_batch = d.get("batch", c.disc_batch, Range::closed(1, kMaxBatch));
  c.disc_steps = d.get("steps", c.disc_steps, Range::non_negative());
  return c;
}

ActorCriticSpec TransitionPolicyConfig::network(const EnvSpec& env, const Policy& next) const {
  ActorCriticSpec n = net;
  n.obs_dim = env.obs_dim;
  n.act_dim = env.act_dim;
  if (init_from_next) n.features = next.features();
  return n;
}

SwitchConfig SwitchConfig::read(const Section& s) {
  SwitchConfig c;
  c.net.hidden = s.layers("hidden", c.net.hidden);
  c.net.gamma = s.get("gamma", c.net.gamma, Range::open_closed(0, 1));
  c.lr = s.get("lr", c.lr, Range::positive());
  c.batch = s.get("batch", c.batch, Range::closed(1, kMaxBatch));
  c.replay = s.get("replay", c.replay, Range::closed(1, kMaxRows));
  c.target_every = s.get("target_every", c.target_every, Range::positive());
  c.r_success = s.get("r_success", c.r_success, Range::any());
  c.r_fail = s.get("r_fail", c.r_fail, Range::any());
  c.attempts = s.get("attempts", c.attempts, Range::non_negative());
  c.updates_per_attempt = s.get("updates_per_attempt", c.updates_per_attempt, Range::non_negative());
  c.warmup = s.get("warmup", c.warmup, Range::non_negative());
  c.epsilon_start = s.get("epsilon_start", c.epsilon_start, Range::closed(0, 1));
  c.epsilon_end = s.get("epsilon_end", c.epsilon_end, Range::closed(0, 1));
  c.explore_fraction = s.get("explore_fraction", c.explore_fraction, Range::open_closed(0, 1));
  c.max_subtask_steps = s.get("max_subtask_steps", c.max_subtask_steps, Range::positive());
  c.lookahead = s.get("lookahead", c.lookahead, Range::at_least(1));
  c.validation_starts = s.get("validation_starts", c.validation_starts, Range::non_negative());
  c.margins = s.get("margins", c.margins, Range::any());
  if (c.margins.empty()) throw s.error("margins", "lists no margin");
  if (c.replay < c.batch) throw s.error("replay", "must hold at least one batch");
  return c;
}

double SwitchConfig::epsilon(int attempt) const {
  const double frac = std::min(1.0, attempt / (explore_fraction * std::max(attempts, 1)));
  return epsilon_start + frac * (epsilon_end - epsilon_start);
}

LeeConfig LeeConfig::read(const Section& s) {
  LeeConfig c;
  c.enabled = s.get("enabled", c.enabled);
  c.hidden = s.layers("hidden", c.hidden);
  c.lr = s.get("lr", c.lr, Range::positive());
  c.batch = s.get("batch", c.batch, Range::closed(1, kMaxBatch));
  c.steps = s.get("steps", c.steps, Range::non_negative());
  c.decay = s.get("decay", c.decay, Range::open_closed(0, 1));
  c.max_rows = s.get("max_rows", c.max_rows, Range::positive());
  c.termination_bias = s.get("termination_bias", c.termination_bias, Range::any());
  c.max_steps = s.get("max_steps", c.max_steps, Range::non_negative());
  c.total_steps = s.get("total_steps", c.total_steps, Range::non_negative());
  return c;
}

TransitionPolicyConfig LeeConfig::transition(const TransitionPolicyConfig& tp) const {
  TransitionPolicyConfig c = tp;
  if (total_steps > 0) c.ppo.total_steps = total_steps;
  return c;
}

PipelineConfig PipelineConfig::read(const Section& root, const std::string& task) {
  PipelineConfig c;
  c.run_dir = root.get("run_dir", "runs/" + task);
  c.seed = root.get<uint64_t>("seed", c.seed);
  c.threads = root.get("threads", c.threads, Range::closed(0, kMaxThreads));
  c.collect = CollectConfig::read(root.sub("collect"));
  c.transition = TransitionPolicyConfig::read(root.sub("transition"));
  c.switching = SwitchConfig::read(root.sub("switch"));
  c.lee = LeeConfig::read(root.sub("lee"));
  return c;
}

}  // namespace segue
