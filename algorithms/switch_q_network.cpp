#include "algorithms/switch_q_network.h"

namespace segue {

SwitchQNetworkImpl::SwitchQNetworkImpl(const SwitchQSpec& s) : spec(s) {
  q = register_module("q", make_mlp(s.obs_dim, s.hidden, 2, Activation::Relu, 1.0));
}

torch::Tensor double_dqn_target(SwitchQNetwork& online, SwitchQNetwork& target, const torch::Tensor& reward,
                                const torch::Tensor& next_obs, const torch::Tensor& done, double gamma) {
  torch::NoGradGuard no_grad;
  auto best = online->forward(next_obs).argmax(-1, /*keepdim=*/true);
  auto value = target->forward(next_obs).gather(-1, best).squeeze(-1);
  return reward + gamma * (1.0 - done) * value;
}

torch::Tensor double_dqn_loss(SwitchQNetwork& online, SwitchQNetwork& target, const torch::Tensor& obs,
                              const torch::Tensor& action, const torch::Tensor& reward,
                              const torch::Tensor& next_obs, const torch::Tensor& done, double gamma) {
  auto y = double_dqn_target(online, target, reward, next_obs, done, gamma);
  auto q = online->forward(obs).gather(-1, action.to(torch::kLong).unsqueeze(-1)).squeeze(-1);
  return (q - y).pow(2).mean();
}

void copy_weights(SwitchQNetwork& from, SwitchQNetwork& to) {
  torch::NoGradGuard no_grad;
  auto src = from->parameters(), dst = to->parameters();
  for (size_t i = 0; i < src.size(); ++i) dst[i].copy_(src[i]);
}

}  // namespace segue
