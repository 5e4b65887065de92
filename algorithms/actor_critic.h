#pragma once
// The Gaussian actor-critic of PPO: a mean network mu(s), a state-independent log
// standard deviation, and a separate value network V(s). Inputs are normalised
// observations; the normaliser lives beside it in the trainer and the exported policy.
#include <torch/torch.h>

#include "algorithms/mlp.h"
#include "algorithms/obs_features.h"

namespace segue {

struct ActorCriticSpec {
  int obs_dim = 0, act_dim = 0;
  std::vector<int> pi_hidden{32, 32};
  std::vector<int> vf_hidden{32, 32};
  Activation activation = Activation::Tanh;
  double init_log_std = -0.5;
  // [begin, end) of the observation that neither network sees (the normaliser maps it to
  // 0); empty = none. E.g. the walker's qacc, [17, 26] (walker_jump_noqacc.yaml).
  std::vector<int> ignore_obs;
  // Periodic features of raw inputs, appended after the normalised observation (both nets).
  ObsFeatures features;
  int in_dim() const { return obs_dim + features.size(); }
};

class ActorCriticImpl : public torch::nn::Module {
 public:
  explicit ActorCriticImpl(const ActorCriticSpec& spec);
  torch::Tensor mean(const torch::Tensor& obs) { return actor->forward(obs); }
  torch::Tensor value(const torch::Tensor& obs) { return critic->forward(obs).squeeze(-1); }
  // log pi(a|s) summed over action dimensions, and the entropy of pi(.|s).
  torch::Tensor log_prob(const torch::Tensor& mean, const torch::Tensor& actions) const;
  torch::Tensor entropy() const;

  ActorCriticSpec spec;
  torch::nn::Sequential actor{nullptr}, critic{nullptr};
  torch::Tensor log_std;
};
TORCH_MODULE(ActorCritic);

// Log density of a diagonal Gaussian, summed over the last dimension. The same formula
// runs in the rollout (on doubles) and in the update (on tensors).
inline double gaussian_log_prob(const float* a, const float* mean, const float* log_std, int n) {
  constexpr double kHalfLog2Pi = 0.91893853320467274178;
  double s = 0.0;
  for (int i = 0; i < n; ++i) {
    double z = (double(a[i]) - mean[i]) / std::exp(double(log_std[i]));
    s += -0.5 * z * z - log_std[i] - kHalfLog2Pi;
  }
  return s;
}

// The gradient of weight x log pi(a|s) for one row: weight z_j / sigma_j for the mean
// (written to d_mean), weight (z_j^2 - 1) for each log sigma_j (added to d_log_std),
// z = (a - mu) / sigma. PPO's and TRPO's objectives reach the networks through it.
inline void gaussian_log_prob_gradient(const float* a, const float* mean, const float* log_std, int n, double weight,
                                       float* d_mean, float* d_log_std) {
  for (int i = 0; i < n; ++i) {
    const double inv_std = std::exp(-double(log_std[i]));
    const double z = (double(a[i]) - mean[i]) * inv_std;
    d_mean[i] = float(weight * z * inv_std);
    d_log_std[i] += float(weight * (z * z - 1.0));
  }
}

}  // namespace segue
