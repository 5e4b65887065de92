#pragma once
// Proximal Policy Optimization with a clipped surrogate (Schulman et al. 2017), in the
// spirit of CleanRL's single-file PPO: iterate() (algorithms/on_policy.h) is one rollout
// followed by update(), epochs of minibatch steps on the clipped objective. Each step's
// gradient is the objective's, written out (algorithms/ppo_loss.h) and backpropagated by
// hand (algorithms/mlp_backprop.h): the same mathematics as autograd, without its
// per-operator cost on networks this small.
#include <torch/torch.h>

#include "algorithms/mlp_backprop.h"
#include "algorithms/on_policy.h"

namespace segue {

struct PpoConfig : OnPolicyConfig {
  int epochs = 10;
  int minibatch_size = 2048;
  double lr = 3e-4;
  bool anneal_lr = true;
  double clip = 0.2;
  double vf_coef = 0.5;
  double ent_coef = 0.0;
  // Weight of action_bound_loss (ppo_loss.h) in the update; 0 leaves the mean unbounded.
  double bound_coef = 0.0;
  double max_grad_norm = 0.5;

  static PpoConfig read(const Section& s, PpoConfig defaults);
  static PpoConfig read(const Section& s) { return read(s, PpoConfig()); }
};

class PPO : public OnPolicyLearner {
 public:
  // With `group` of several ranks, each collects its share of the rollout and rank 0
  // updates on the whole of it (OnPolicyLearner::whole_rollout()).
  PPO(const PpoConfig& config, const ActorCriticSpec& net, VectorEnv& envs, uint64_t seed,
      const Distributed& group = Distributed::alone());

  // Epochs of minibatch steps of Adam on L^CLIP + vf_coef L^VF - ent_coef S (+ bound_coef
  // times the action-bound loss), the gradient clipped to max_grad_norm.
  void update(IterationStats& stats) override;
  std::vector<std::string> update_columns() const override {
    return {"policy_loss", "value_loss", "entropy", "approx_kl", "clip_fraction"};
  }
  std::vector<double> update_values(const IterationStats& s) const override {
    return {s.policy_loss, s.value_loss, s.entropy, s.approx_kl, s.clip_fraction};
  }
  double learning_rate() const;  // the rate the last update used

 private:
  // One minibatch's rows of the rollout, copied together; advantages normalised.
  void gather(const RolloutBuffer& rollout, const int64_t* rows, int n);

  PpoConfig cfg_;
  MlpBackprop actor_, critic_;
  struct {
    std::vector<float> obs, actions, old_log_prob, advantage, returns;
  } mb_;
  MlpBackprop::RowMatrix dmu_, dvalue_;  // dL/dmu, dL/dV of the minibatch
};

}  // namespace segue
