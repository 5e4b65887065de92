#pragma once
// Trust Region Policy Optimization (Schulman et al. 2015), as the reference trains its
// skills and its Single baseline (docs/reference/learners.md): after each rollout, one
// natural-gradient step on the surrogate
//     L(theta) = mean_t [ pi_theta(a_t|s_t) / pi_old(a_t|s_t) A_t ]          (TRPO, Eq. 14)
// subject to mean KL(pi_old || pi_theta) <= max_kl. The direction solves F x = g by
// conjugate gradient (F: the Fisher matrix, as the Hessian of the mean KL), the step is
// scaled to the trust region's edge, sqrt(2 max_kl / x.Fx) x, and a backtracking line
// search halves it until the surrogate improves and the KL stays within 1.5 max_kl (none
// accepted: the policy stays). The value network is then fitted by Adam on the GAE
// returns, in minibatches. pi_old is the policy that collected the rollout (its
// log-probabilities are in the buffer), so a rollout collected a policy behind is
// accounted for.
#include "algorithms/mlp_backprop.h"
#include "algorithms/on_policy.h"

namespace segue {

struct TrpoConfig : OnPolicyConfig {
  double max_kl = 0.01;     // the trust region: mean KL(pi_old || pi_new) per step
  int cg_iters = 10;        // conjugate-gradient steps for F x = g
  double cg_damping = 0.1;  // F + damping I: keeps the system well conditioned
  int fisher_stride = 5;    // the Fisher-vector product uses every fisher_stride-th row
  int line_search_steps = 10;  // halvings of the step tried before giving up
  double vf_lr = 1e-3;      // the value network's Adam
  int vf_epochs = 5;
  int vf_minibatch = 64;

  // The reference's: GAE lambda 0.98, observations clipped to +-5, raw rewards, 10,000
  // steps per rollout.
  TrpoConfig() {
    lambda = 0.98;
    obs_clip = 5.0;
    normalize_reward = false;
    steps_per_env = 625;
  }
  static TrpoConfig read(const Section& s);
};

class TRPO : public OnPolicyLearner {
 public:
  // With `group` of several ranks, each collects its share of the rollout and rank 0
  // updates on the whole of it (OnPolicyLearner::whole_rollout()).
  TRPO(const TrpoConfig& config, const ActorCriticSpec& net, VectorEnv& envs, uint64_t seed,
       const Distributed& group = Distributed::alone());

  void update(IterationStats& stats) override;
  std::vector<std::string> update_columns() const override {
    return {"policy_loss", "value_loss", "entropy", "approx_kl", "step_size"};
  }
  std::vector<double> update_values(const IterationStats& s) const override {
    return {s.policy_loss, s.value_loss, s.entropy, s.approx_kl, s.step_size};
  }

 private:
  void policy_step(const RolloutBuffer& rollout, IterationStats& stats);
  void fit_value(const RolloutBuffer& rollout, IterationStats& stats);
  TrpoConfig cfg_;
  // Both networks' gradients by hand (as PPO's, algorithms/ppo.h); the Fisher-vector
  // product by forward- and backward-mode passes (algorithms/natural_gradient.h).
  MlpBackprop actor_, critic_;
  std::vector<float> adv_, fisher_obs_;
  MlpBackprop::RowMatrix old_mean_, dmu_;
  std::vector<float> vf_obs_, vf_returns_;
  MlpBackprop::RowMatrix dvalue_;
};

}  // namespace segue
