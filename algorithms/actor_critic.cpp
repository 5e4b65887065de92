#include "algorithms/actor_critic.h"

#include <cmath>

namespace segue {

ActorCriticImpl::ActorCriticImpl(const ActorCriticSpec& s) : spec(s) {
  actor = register_module("actor", make_mlp(s.in_dim(), s.pi_hidden, s.act_dim, s.activation, 0.01));
  critic = register_module("critic", make_mlp(s.in_dim(), s.vf_hidden, 1, s.activation, 1.0));
  log_std = register_parameter("log_std", torch::full({s.act_dim}, s.init_log_std));
}

torch::Tensor ActorCriticImpl::log_prob(const torch::Tensor& mean, const torch::Tensor& actions) const {
  auto z = (actions - mean) * torch::exp(-log_std);
  return (-0.5 * z.pow(2) - log_std - 0.5 * std::log(2.0 * M_PI)).sum(-1);
}

torch::Tensor ActorCriticImpl::entropy() const {
  return (log_std + 0.5 * (1.0 + std::log(2.0 * M_PI))).sum();
}

}  // namespace segue
