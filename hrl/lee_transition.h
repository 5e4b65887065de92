#pragma once
// The baseline of Lee et al. 2019 ("Composing complex skills by learning transition
// policies"): a transition policy rewarded by a proximity predictor P_b(s) in [0, 1], how
// close s is to states from which pi_b succeeds, and ending itself with a termination
// output. Per episode from a state of S_a:
//   pi_ab acts until its extra output is positive (or the interval ends, or its
//   lee.max_steps are spent, or a fall);
//   pi_b then runs its subtask; success labels the episode's states 0.95^k (k steps
//   before the hand-over), failure labels them 0; pi_b's own states (T_b) are labelled 1.
//   Rewards: P(s_{t+1}) - P(s_t), plus P(s_T) at the end (algorithms/proximity_predictor.h).
#include <memory>
#include <vector>

#include "algorithms/ppo.h"
#include "algorithms/proximity_predictor.h"
#include "core/running_mean_std.h"
#include "hrl/collection.h"
#include "hrl/pipeline_config.h"
#include "hrl/transition_env.h"

namespace segue {

// pi_ab's environment: pi_b's observation slice; pi_b's actions plus a termination output.
// Every episode ends as a true end at the hand-over; info.success is pi_b's outcome.
class LeeTransitionEnv : public Env {
 public:
  // Transition `transition` of `meta` in environments of `make_env`, from S_a's states;
  // pi_ab hands over after at most `max_steps` steps (0: when the interval ends); pi_b's
  // run after a hand-over is cut, and counted a success, after max_subtask_steps.
  LeeTransitionEnv(const EnvFactory& make_env, const std::vector<Skill>& skills, const MetaController& meta,
                   int transition, StartStates starts, int max_steps, int max_subtask_steps);
  const EnvSpec& spec() const override { return spec_; }
  void reset(uint64_t seed, float* obs) override;
  void reset(float* obs) override;
  StepResult step(const float* action, float* obs) override;
  void features(double* out) const override { inner_.features(out); }
  void save_state(std::vector<double>& out) const override { inner_.save_state(out); }
  void restore_state(const std::vector<double>& state, float* obs) override;
  // The inner episode, then the states of this episode so far (P_b's labels need them).
  bool save_episode(std::vector<double>& state, std::string& rng) const override;
  void restore_episode(const std::vector<double>& state, const std::string& rng, float* obs) override;

  // Episodes finished since the last call: their states s_0..s_T (pi_b's slice) and outcome.
  struct Episode {
    std::vector<float> states;
    bool success;
  };
  std::vector<Episode> take_finished() { return std::move(finished_); }

 private:
  int to_;
  TransitionEnv inner_;  // S_a starts, pi_b's slice, the interval's end
  int max_steps_, max_subtask_steps_;
  TransitionController pi_b_;  // pi_b alone judges a hand-over, as in Lee et al.
  EnvSpec spec_;
  std::vector<float> after_;
  Episode current_;
  std::vector<Episode> finished_;
};

class LeeTrainer {
 public:
  // `envs` are LeeTransitionEnvs; `expert` is T_b (its states are P_b's label-1 data).
  // With `group`, PPO is data-parallel (ppo.h) and P_b's gradients are averaged over the
  // ranks, each labelling its own episodes.
  LeeTrainer(const TransitionPolicyConfig& tp, const LeeConfig& config, VectorEnv& envs,
             const Demonstrations& expert, const Policy& next, uint64_t seed,
             const Distributed& group = Distributed::alone());
  struct Stats {
    IterationStats ppo;
    double predictor_loss = 0, handover_success = NAN;
  };
  Stats iterate();
  // pi_ab with its log std and lee.max_steps, which evaluation follows.
  Policy policy() const;
  const PPO& ppo() const { return ppo_; }
  // The checkpoint holds P_b, its optimiser, its labelled states and its input
  // normaliser too, so a resumed stage fits P_b on all it had seen.
  void save(const std::string& path, const std::string& note) const;
  void load(const std::string& path);
  // Transitions' states labelled so far (positive: from successful episodes; T_b's apart),
  // ring overwrites included.
  int64_t positives_seen() const { return pos_n_; }
  int64_t negatives_seen() const { return neg_n_; }

 private:
  void reward(RolloutBuffer& buf);  // PPO's reward hook
  void add(const float* s, float label);
  torch::Tensor normalize(const torch::Tensor& obs) const;

  LeeConfig cfg_;
  VectorEnv& envs_;
  PPO ppo_;
  ProximityPredictor p_{nullptr};
  std::unique_ptr<torch::optim::Adam> opt_;
  int obs_dim_;
  RunningMeanStd rms_;   // P_b's input normaliser: T_b's and every labelled state's moments, clip 5, std >= 0.01
  std::vector<float> tb_;                     // T_b: label 1, kept whole
  std::vector<float> pos_, pos_label_, neg_;  // transitions' labelled states: rings of max_rows
  std::vector<float> labelled_;               // one rollout's labelled states (scratch)
  int64_t pos_n_ = 0, neg_n_ = 0;
  Stats last_;
};

}  // namespace segue
