#include "hrl/skill_recipe.h"

#include "core/thread_pool.h"
#include "environments/registry.h"

namespace segue {

SkillRecipe SkillRecipe::read(const Recipe& recipe, const std::string& default_run_dir) {
  Section root = recipe.root();
  SkillRecipe s;
  s.task = root.require<std::string>("task");
  s.seed = root.get<uint64_t>("seed", s.seed);
  s.threads = root.get("threads", s.threads, Range::closed(0, kMaxThreads));  // 0: all cores
  s.run_dir = root.get("run_dir", default_run_dir);
  s.checkpoint_every = root.get("checkpoint_every", s.checkpoint_every, Range::positive());
  s.init_from = root.get<std::string>("init_from", "");
  s.init_log_std = root.get("init_log_std", s.init_log_std, Range::any());
  s.init_policy = root.get<std::string>("init_policy", "");
  if (!s.init_policy.empty() && !s.init_from.empty())
    throw root.error("init_policy", "a run starts from init_from or init_policy, not both");
  if (!std::isnan(s.init_log_std) && s.init_from.empty())
    throw root.error("init_log_std", "applies to a run that starts from init_from");
  s.restart_lr_schedule = root.get("restart_lr_schedule", s.restart_lr_schedule);
  if (s.restart_lr_schedule && s.init_from.empty())
    throw root.error("restart_lr_schedule", "applies to a run that starts from init_from");
  EnvSpec spec;
  s.make_env = read_task(root, s.task, spec);
  Section pol = root.sub("policy");
  s.net.pi_hidden = pol.layers("pi_hidden", s.net.pi_hidden);
  s.net.vf_hidden = pol.layers("vf_hidden", s.net.vf_hidden);
  s.net.activation = parse_activation(pol.choice("activation", "tanh", {"tanh", "relu"}));
  s.net.init_log_std = pol.get("init_log_std", s.net.init_log_std, Range::any());
  s.net.ignore_obs = pol.get("ignore_obs", s.net.ignore_obs, Range::non_negative());
  s.learner = root.choice("learner", s.learner, {kLearners.begin(), kLearners.end()});
  for (const std::string other : kLearners)
    if (other != s.learner && root.has(other))
      throw root.error(other, "applies to learner: " + other + " (the recipe's learner is " + s.learner + ")");
  if (s.learner == "ppo") s.ppo = PpoConfig::read(root.sub("ppo"));
  else if (s.learner == "trpo") s.trpo = TrpoConfig::read(root.sub("trpo"));
  else s.sac = SacConfig::read(root.sub("sac"));
  // SAC starts from random weights with its own exploration: the on-policy starts do not apply.
  if (s.learner == "sac") {
    const char* key = !s.init_policy.empty() ? "init_policy" : !std::isnan(s.init_log_std) ? "init_log_std"
                      : s.restart_lr_schedule ? "restart_lr_schedule" : nullptr;
    if (key) throw root.error(key, "applies to learner ppo or trpo, not sac");
  }
  Section ev = root.sub("eval");
  s.eval_episodes = ev.get("episodes", s.eval_episodes, Range::positive());
  s.eval_seed = ev.get<uint64_t>("seed", s.eval_seed);
  s.eval_make_env = s.make_env;
  if (ev.get("reference_task", false))
    s.eval_make_env = reference_task_factory(s.task);
  s.net.obs_dim = spec.obs_dim;
  const auto& ig = s.net.ignore_obs;
  if (!ig.empty() && (ig.size() != 2 || ig[0] >= ig[1] || ig[1] > s.net.obs_dim))
    throw pol.error("ignore_obs", "must be [begin, end) with 0 <= begin < end <= " + std::to_string(s.net.obs_dim));
  // Read only when given, so older runs' resolved recipes stay the same.
  if (pol.has("fourier")) s.net.features = ObsFeatures::read(pol.sub("fourier"), s.net.obs_dim);
  s.net.act_dim = spec.act_dim;
  return s;
}

std::unique_ptr<Learner> make_learner(const SkillRecipe& s, VectorEnv& envs, const Distributed& group) {
  if (s.learner == "sac") {
    if (!group.single()) throw Error("learner sac runs on one process (drop --nproc)");
    return std::make_unique<SAC>(s.sac, s.net, envs, s.seed);
  }
  if (s.learner == "trpo") return std::make_unique<TRPO>(s.trpo, s.net, envs, s.seed, group);
  return std::make_unique<PPO>(s.ppo, s.net, envs, s.seed, group);
}

}  // namespace segue
