#pragma once
// The switch Q-network q_ab of Algorithm 2: two actions, stay (0) and switch (1), trained
// by double DQN (van Hasselt et al. 2016; paper Eq. 4):
//   y = r + gamma (1 - done) Q_target(s', argmax_a Q(s', a))
// with a hard target copy every `target_every` updates.
#include <torch/torch.h>

#include "algorithms/mlp.h"

namespace segue {

struct SwitchQSpec {
  int obs_dim = 0;
  std::vector<int> hidden{128, 128};  // 2 x 128 ReLU, the reference's (docs/reference/learners.md)
  double gamma = 0.99;
};

class SwitchQNetworkImpl : public torch::nn::Module {
 public:
  static constexpr int kStay = 0, kSwitch = 1;
  explicit SwitchQNetworkImpl(const SwitchQSpec& spec);
  torch::Tensor forward(const torch::Tensor& obs) { return q->forward(obs); }
  SwitchQSpec spec;
  torch::nn::Sequential q{nullptr};
};
TORCH_MODULE(SwitchQNetwork);

// Eq. 4: the online network picks a', the target network values it.
torch::Tensor double_dqn_target(SwitchQNetwork& online, SwitchQNetwork& target, const torch::Tensor& reward,
                                const torch::Tensor& next_obs, const torch::Tensor& done, double gamma);
// Mean squared error between Q(s, a) and y.
torch::Tensor double_dqn_loss(SwitchQNetwork& online, SwitchQNetwork& target, const torch::Tensor& obs,
                              const torch::Tensor& action, const torch::Tensor& reward,
                              const torch::Tensor& next_obs, const torch::Tensor& done, double gamma);
// Hard copy of the online weights into the target network.
void copy_weights(SwitchQNetwork& from, SwitchQNetwork& to);

}  // namespace segue
