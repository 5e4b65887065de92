#pragma once
// What PPO and TRPO share: a Gaussian actor-critic that collects a rollout from a vector
// of environments, turns its rewards into GAE advantages, and is saved and resumed
// exactly. The two differ only in update(): PPO takes clipped minibatch steps
// (algorithms/ppo.h), TRPO one natural-gradient step in a trust region (algorithms/trpo.h).
#include <torch/torch.h>

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "algorithms/actor_critic.h"
#include "algorithms/learner.h"
#include "algorithms/policy.h"
#include "core/distributed.h"
#include "core/recipe.h"
#include "core/rng.h"
#include "core/rollout_buffer.h"
#include "core/running_mean_std.h"
#include "core/vector_env.h"

namespace segue {

// Limits checked when a recipe is read, before anything is allocated.
constexpr int kMaxEnvs = 4096, kMaxStepsPerEnv = 100000;

// The rollout and its returns: the settings every on-policy learner reads from its own
// recipe section (`ppo:` or `trpo:`), with that learner's defaults.
struct OnPolicyConfig {
  int64_t total_steps = 2'000'000;  // environment (control) steps over the whole run
  int num_envs = 16;
  int steps_per_env = 512;          // rollout = num_envs * steps_per_env
  double gamma = 0.99;
  double lambda = 0.95;
  // A floor under the policy's log std, kept after every update: a continued run may need
  // exploration held open (PPO's entropy bonus did not do it at these scales).
  double min_log_std = -20.0;       // -20: no floor
  bool normalize_reward = true;     // scale rewards by the std of the discounted return
  double obs_clip = 10.0;           // normalised observations are clipped to +-obs_clip
  // 1: the environments collect the next rollout while the learner updates on this one, so
  // the update is off the rollout's critical path. That rollout is collected by the policy
  // before the update (one iteration of lag), which the ratio and surrogate account for:
  // they use the log-probabilities of the policy that acted. One process only.
  int policy_lag = 0;

  // Reads the keys above from `s`, over the values already set.
  void read_rollout(const Section& s);
  int64_t rollout_size() const { return int64_t(num_envs) * steps_per_env; }
};


class OnPolicyLearner : public Learner {
 public:
  // With `group` of several ranks, learning is data-parallel: each rank steps its share of
  // the environments (envs.first_index() says which), and every update is the one a single
  // process with all of them makes, to float tolerance (normalisers merged exactly; the
  // update made by rank 0 on the gathered rollout, whole_rollout()).
  OnPolicyLearner(std::string name, const OnPolicyConfig& config, const ActorCriticSpec& net, VectorEnv& envs,
                  uint64_t seed, const Distributed& group);
  const std::string& name() const override { return name_; }  // "ppo" or "trpo"

  // One update on a rollout of rollout_size() steps. With policy_lag 0 the rollout is
  // collected first, by the current policy; with 1, the rollout the previous iteration
  // collected beside its update is used, and the next one is collected beside this one.
  // Throws segue::Error if the loss or the rewards stop being finite.
  IterationStats iterate() override;
  // Collects a rollout with the current policy and turns it into advantages (what
  // iterate() does before update() with policy_lag 0).
  void collect_rollout(IterationStats& stats);
  // One update on the collected rollout; the rollout's policy copy follows at the next
  // refresh (iterate() does it once the environments stop reading it).
  virtual void update(IterationStats& stats) = 0;

  // Replaces the environment's rewards after a rollout is collected and before they are
  // scaled and turned into advantages: a transition policy's reward comes from its AIRL
  // discriminator (Eq. 3), not from the task. The hook sees raw observations, actions,
  // log pi_old and dones, and writes buf.raw_rewards.
  using RewardHook = std::function<void(RolloutBuffer& buf)>;
  void set_reward_hook(RewardHook hook) { reward_hook_ = std::move(hook); }
  const RolloutBuffer& buffer() const { return buf_; }

  // The deterministic policy (mean action, normaliser included).
  Policy policy() const override;
  int64_t iteration() const override { return iteration_; }
  int64_t global_step() const override { return global_step_; }
  double wall_seconds() const override { return wall_seconds_; }
  int64_t total_iterations() const;
  ActorCritic& net() { return net_; }
  const Distributed& group() const { return group_; }

  // log pi(a|s) of the current policy at raw (unnormalised) observations, no gradient:
  // AIRL's D needs the generator's density at the expert's actions (Eq. 2).
  torch::Tensor log_prob(const float* raw_obs, const float* actions, int64_t n);
  // Starts the actor from a trained policy (weights and observation normaliser); the log
  // std keeps its initial value. A transition policy can start as pi_b, whose behaviour it
  // is trained to match. The actor may have more outputs than the policy (Lee et al.'s
  // termination head): those start at zero weight and bias (set_action_bias sets one). The
  // policy may see a prefix of the trainer's observation (a walker skill, before the
  // obstacle pair): the other inputs start at zero weight, so the actor begins as exactly
  // that policy.
  void init_actor(const Policy& policy);
  // Sets the bias of one action dimension's mean (the output layer's), e.g. where Lee et
  // al.'s termination head starts, whether the actor began as a policy or at random.
  void set_action_bias(int dim, float bias);
  // Sets every action dimension's log std: a run continued from a converged checkpoint
  // has next to no exploration left.
  void set_log_std(double log_std);
  // A learning-rate schedule (PPO's) anneals from here to total_steps rather than over the
  // whole budget from step 0: a stage continued from another run's checkpoint gets the
  // full rate for its own steps. Saved with the checkpoint.
  void restart_lr_schedule() { schedule_start_ = iteration_; }

  // Checkpoint (algorithms/on_policy_checkpoint.cpp): network, optimiser, normalisers,
  // counters, the learner's name and `note` (the resolved recipe), written atomically;
  // with several ranks, save() and load() are collectives: rank 0 writes (every rank's
  // episodes in flight gathered in environment order, so the file is the one a single
  // process writes) and reads (the bytes sent to every rank). `extra` adds an owner's
  // state (a discriminator) to the same file, so the two can never be saved at different
  // iterations.
  using ArchiveWriter = std::function<void(torch::serialize::OutputArchive&)>;
  using ArchiveReader = std::function<void(torch::serialize::InputArchive&)>;
  // The episodes in flight are saved too where every environment can say its state
  // (Env::save_episode), and a load with `resume_episodes` puts them back, so a resumed
  // run is the unbroken one. Otherwise, loading another run's checkpoint to continue from,
  // the environments start fresh episodes, and a checkpoint of another learner gives its
  // networks and normalisers but not its optimiser.
  void save(const std::string& path, const std::string& note, const ArchiveWriter& extra) const;
  void load(const std::string& path, const ArchiveReader& extra = {}, bool resume_episodes = true);
  void save(const std::string& path, const std::string& note) const override { save(path, note, ArchiveWriter()); }
  void save(const std::string& path) const { save(path, "", ArchiveWriter()); }
  void load_checkpoint(const std::string& path, bool resume) override { load(path, {}, resume); }
  // The deterministic policy of a checkpoint already read.
  static Policy policy_from_checkpoint(torch::serialize::InputArchive& ar);

 protected:
  // One permutation of the whole rollout's rows (indices into whole_rollout()), cut into
  // minibatches of `size`.
  std::vector<torch::Tensor> shuffled_minibatches(int64_t size) const;
  // With several ranks, an update is rank 0's alone, on every rank's rollout, then sent to
  // the others: these updates are hundreds of small sequential steps, and an exchange per
  // step costs more than the step (docs/distributed.md). Rank 0's update is then the one a
  // single process makes. Every rank calls both, in this order.
  // The network inputs, actions, log pi_old, advantages and returns of every rank's
  // environments, laid out [T, every rank's environments, ...]; buf_ itself alone.
  const RolloutBuffer& whole_rollout();
  // Rank 0's `params` and its `n` `values` (the update's statistics), on every rank.
  void share_leader_update(const std::vector<torch::Tensor>& params, double* values, int n) const;
  // to[i] = from[rows[i]] for n rows of `width` numbers each (to is resized, which
  // allocates only while it grows).
  static void gather_rows(const std::vector<float>& from, int width, const int64_t* rows, int n,
                          std::vector<float>& to);
  // out[i] = (A[rows[i]] - mean) / (std + 1e-8) for n rows of the advantages A (rows null:
  // the first n), mean and standard deviation taken over those rows (out is resized).
  static void standardized_advantages(const std::vector<float>& advantages, const int64_t* rows, int64_t n,
                                      std::vector<float>& out);
  // Runs a() and b(), two independent parts of an update (one network's work each), at
  // once on the environments' pool when it has a second thread and no rollout runs beside
  // the update (policy_lag 0), or on rank 0's update_pool_; else one after the other.
  // Either way the same results.
  void run_both(const std::function<void()>& a, const std::function<void()>& b);
  int64_t global_rows() const { return int64_t(buf_.T) * global_envs_; }
  void refresh_inference_copy();

  OnPolicyConfig rollout_cfg_;
  VectorEnv& envs_;
  ActorCritic net_{nullptr};
  std::unique_ptr<torch::optim::Adam> optimizer_;  // set by the learner (its parameters, its rate)
  RolloutBuffer buf_;
  const Distributed& group_;
  uint64_t seed_;
  int64_t iteration_ = 0, global_step_ = 0;
  int64_t schedule_start_ = 0;  // the iteration the learning-rate annealing starts from

 private:
  void read_state(torch::serialize::InputArchive& ar, const std::string& path, bool same_run);  // load()'s body
  // policy_lag 1: what an update reads of a rollout collected but not yet used, by name.
  std::vector<std::pair<std::string, std::vector<float>*>> pending_rollout() const;
  bool read_pending_rollout(torch::serialize::InputArchive& ar, const std::string& path);
  struct InFlight;
  // A rollout in two parts: the environment steps, which read only the policy's Eigen copy
  // and the observation normaliser (and so can run beside an update), then what needs the
  // networks: rewards scaled, values, GAE advantages, the normalisers updated.
  void collect_steps(int64_t iteration, RolloutBuffer& buf);
  void finish_rollout(int64_t iteration);
  void episode_stats(IterationStats& stats);
  // Environment i's action at step t, from its network input, and log pi_old of it.
  void sample_action(RolloutBuffer& buf, int t, int i);
  // The networks' input for one raw observation: normalised, then the periodic features.
  void net_input(const float* raw, float* out) const;

  std::string name_;
  EigenMlp actor_copy_;  // Eigen mirror of net_->actor for the rollout
  RunningMeanStd obs_rms_, return_rms_;
  int64_t global_envs_;          // environments over every rank
  std::vector<Rng> env_rng_;     // action noise, one stream per environment (any rank layout draws alike)
  std::vector<float> return_samples_;  // the discounted returns of a rollout, for return_rms_
  std::vector<double> running_return_;  // discounted return per env, for reward scaling
  std::vector<float> mean_, log_std_;
  std::vector<EigenMlp::Workspace> actor_workspace_;  // one per environment: they act on any thread
  std::unique_ptr<ThreadPool> update_pool_;  // rank 0 of several whose own pool has one thread
  std::vector<uint8_t> cut_;  // per step of a rollout [T, N]: ended by a time limit, not a real end
  RewardHook reward_hook_;
  double wall_seconds_ = 0.0;
  // policy_lag 1: the rollout being collected beside an update, and whether buf_ holds a
  // collected rollout that no update has used yet (saved with a checkpoint).
  RolloutBuffer next_buf_;
  bool rollout_ready_ = false;
  RolloutBuffer whole_;  // several ranks: whole_rollout()'s gathered copy
};

}  // namespace segue
