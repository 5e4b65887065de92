#pragma once
// A skill recipe: which task, which network, which learner and its settings, where the
// run lives.
//
//   task: walker_forward      # a task name (docs/reference/tasks.md; `segue keys` lists them)
//   seed: 1
//   threads: 0                # 0 = every core
//   run_dir: runs/walker_forward
//   checkpoint_every: 5       # iterations
//   init_from: runs/walker_jump/checkpoint.pt   # optional: continue an earlier run
//   init_log_std: -1.0        # optional, with init_from: reset the policy's log std
//   restart_lr_schedule: true # optional, with init_from: anneal ppo.lr over this stage only
//   init_policy: assets/policies/walker/walker_forward.pt  # optional: start the actor as a skill
//   env: {...}                # the task's settings (reference defaults)
//   policy: {pi_hidden: [32, 32], vf_hidden: [32, 32], activation: tanh, init_log_std: -0.5,
//            ignore_obs: [17, 26],   # optional: inputs neither net sees (here the qacc)
//            fourier: {inputs: [26], periods: [0.95, 1.9, 3.8]}}  # optional: sin and cos
//                                    # of 2 pi x_i / P appended to both nets' input
//                                    # (ObsFeatures; here the curb's distance)
//   learner: ppo              # ppo (default), trpo or sac: which section below is read
//   ppo: {...}                # with learner: ppo, see PpoConfig (algorithms/ppo.h)
//   trpo: {...}               # with learner: trpo, see TrpoConfig (algorithms/trpo.h)
//   sac: {...}                # with learner: sac, see SacConfig (algorithms/sac.h)
//   eval: {episodes: 50, seed: 1000, reference_task: false}
//   lead_in: {policy: FILE, when: {curb_ahead: [3, 4]}, share: 0.5}  # optional: training
//                             # episodes begin where another skill hands over (hrl/lead_in.h;
//                             # read by segue train, as it needs a composing skill)
//
// eval.reference_task: judge the trained skill on the task with every env key at its
// reference value (a recipe may train on an easier or reshaped version, e.g. a curb
// curriculum, and must still be measured on the reference's task).
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include "algorithms/actor_critic.h"
#include "algorithms/ppo.h"
#include "algorithms/sac.h"
#include "algorithms/trpo.h"
#include "core/recipe.h"

namespace segue {

struct SkillRecipe {
  std::string task;
  uint64_t seed = 1;
  int threads = 0;
  std::string run_dir;
  // A checkpoint a new run starts from (network, optimiser, normalisers and counters):
  // a later training stage, e.g. a harder curriculum, continues an earlier run's
  // budget. "" = from scratch.
  std::string init_from;
  double init_log_std = NAN;  // with init_from: the log std to restart exploration at (NaN: keep)
  // With init_from: anneal the learning rate over this stage's steps. By default the
  // schedule goes on from the checkpoint's iteration, so a short stage after a long run
  // trains at a small fraction of ppo.lr (the earlier stages' recipes were measured so).
  bool restart_lr_schedule = false;
  // A shipped skill (TorchScript) the actor starts as, e.g. walking for the jump: its
  // observation may be a prefix of this task's (the obstacle pair starts at zero weight).
  // The critic, the log std (policy.init_log_std) and the counters start fresh.
  std::string init_policy;
  int checkpoint_every = 5;
  int eval_episodes = 50;
  uint64_t eval_seed = 1000;
  std::function<std::unique_ptr<Env>()> make_env;
  std::function<std::unique_ptr<Env>()> eval_make_env;  // make_env, or the reference task
  ActorCriticSpec net;
  std::string learner = "ppo";  // "ppo", "trpo" or "sac": which of the configs below applies
  PpoConfig ppo;
  TrpoConfig trpo;
  SacConfig sac;
  // The recipe's learner's budget and environments.
  int64_t total_steps() const {
    return learner == "sac" ? sac.total_steps : learner == "trpo" ? trpo.total_steps : ppo.total_steps;
  }
  int num_envs() const { return learner == "sac" ? sac.num_envs : learner == "trpo" ? trpo.num_envs : ppo.num_envs; }

  // Reads every key (then call recipe.reject_unknown()). `default_run_dir` is used when
  // the recipe names none.
  static SkillRecipe read(const Recipe& recipe, const std::string& default_run_dir);
};

// The values of `learner:`, each also the name of its settings' section.
inline const std::array<const char*, 3> kLearners = {"ppo", "trpo", "sac"};

// The recipe's learner on `envs` (its share of num_envs where `group` has several ranks).
std::unique_ptr<Learner> make_learner(const SkillRecipe& s, VectorEnv& envs, const Distributed& group);

}  // namespace segue
