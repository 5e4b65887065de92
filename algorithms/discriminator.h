#pragma once
// The AIRL state-action discriminator (Fu et al. 2018; paper Eq. 2-3):
//   f(s, a, s') = g(s, a) + gamma h(s') - h(s)          (h(s') dropped at a true end)
//   D(s, a, s') = exp f / (exp f + pi(a|s))
// trained by logistic regression: expert transitions (pi_b's, label 1) against the
// generator's (pi_ab's, label 0). The logit of D is f - log pi(a|s), so
//   Discriminator::reward = log D - log(1 - D) = f - log pi(a|s)      (Eq. 3)
// Inputs are normalised with the expert data's mean and std, clipped to +-5 (reference).
#include <torch/torch.h>

#include "algorithms/mlp.h"

namespace segue {

struct DiscriminatorSpec {
  int obs_dim = 0, act_dim = 0;
  std::vector<int> hidden{100, 100};  // g and h: 2 x 100 ReLU each, the reference's (docs/reference/learners.md)
  double gamma = 0.99;
};

class DiscriminatorImpl : public torch::nn::Module {
 public:
  explicit DiscriminatorImpl(const DiscriminatorSpec& spec);
  // f for a batch; `done` (1 at a true episode end) removes gamma h(s').
  torch::Tensor f(const torch::Tensor& obs, const torch::Tensor& act, const torch::Tensor& next_obs,
                  const torch::Tensor& done);
  // Logit of D: f - log pi(a|s).
  torch::Tensor logit(const torch::Tensor& obs, const torch::Tensor& act, const torch::Tensor& next_obs,
                      const torch::Tensor& done, const torch::Tensor& log_pi);
  // Eq. 3, no gradient.
  torch::Tensor reward(const torch::Tensor& obs, const torch::Tensor& act, const torch::Tensor& next_obs,
                       const torch::Tensor& done, const torch::Tensor& log_pi);
  // Binary cross-entropy of D: expert labelled 1, generator 0 (mean over both batches).
  torch::Tensor loss(const torch::Tensor& expert_logit, const torch::Tensor& generator_logit) const;
  // Fixes the input normalisation from the expert data (mean, std of s and a).
  void set_normalizer(const torch::Tensor& obs_mean, const torch::Tensor& obs_std,
                      const torch::Tensor& act_mean, const torch::Tensor& act_std);

  DiscriminatorSpec spec;
  torch::nn::Sequential g{nullptr}, h{nullptr};
  torch::Tensor obs_mean, obs_std, act_mean, act_std;  // buffers

 private:
  // s's input to g and h: s normalised.
  torch::Tensor state_input(const torch::Tensor& o) const;
};
TORCH_MODULE(Discriminator);

}  // namespace segue
