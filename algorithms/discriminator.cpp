#include "algorithms/discriminator.h"

namespace segue {

DiscriminatorImpl::DiscriminatorImpl(const DiscriminatorSpec& s) : spec(s) {
  g = register_module("g", make_mlp(s.obs_dim + s.act_dim, s.hidden, 1, Activation::Relu, 1.0));
  h = register_module("h", make_mlp(s.obs_dim, s.hidden, 1, Activation::Relu, 1.0));
  obs_mean = register_buffer("obs_mean", torch::zeros({s.obs_dim}));
  obs_std = register_buffer("obs_std", torch::ones({s.obs_dim}));
  act_mean = register_buffer("act_mean", torch::zeros({s.act_dim}));
  act_std = register_buffer("act_std", torch::ones({s.act_dim}));
}

void DiscriminatorImpl::set_normalizer(const torch::Tensor& om, const torch::Tensor& os, const torch::Tensor& am,
                                       const torch::Tensor& as) {
  torch::NoGradGuard no_grad;
  obs_mean.copy_(om);
  obs_std.copy_(os.clamp_min(1e-6));
  act_mean.copy_(am);
  act_std.copy_(as.clamp_min(1e-6));
}

torch::Tensor DiscriminatorImpl::state_input(const torch::Tensor& o) const {
  return ((o - obs_mean) / obs_std).clamp(-5.0, 5.0);
}

torch::Tensor DiscriminatorImpl::f(const torch::Tensor& obs, const torch::Tensor& act, const torch::Tensor& next_obs,
                                   const torch::Tensor& done) {
  auto s = state_input(obs), s2 = state_input(next_obs);
  auto a = ((act - act_mean) / act_std).clamp(-5.0, 5.0);
  auto reward = g->forward(torch::cat({s, a}, -1)).squeeze(-1);
  auto shaping = spec.gamma * (1.0 - done) * h->forward(s2).squeeze(-1) - h->forward(s).squeeze(-1);
  return reward + shaping;
}

torch::Tensor DiscriminatorImpl::logit(const torch::Tensor& obs, const torch::Tensor& act, const torch::Tensor& next_obs,
                                       const torch::Tensor& done, const torch::Tensor& log_pi) {
  return f(obs, act, next_obs, done) - log_pi;
}

torch::Tensor DiscriminatorImpl::reward(const torch::Tensor& obs, const torch::Tensor& act, const torch::Tensor& next_obs,
                                        const torch::Tensor& done, const torch::Tensor& log_pi) {
  torch::NoGradGuard no_grad;
  return logit(obs, act, next_obs, done, log_pi);
}

torch::Tensor DiscriminatorImpl::loss(const torch::Tensor& expert_logit, const torch::Tensor& generator_logit) const {
  // -log D on expert data, -log(1 - D) on generator data, in the stable logit form.
  auto expert = torch::nn::functional::softplus(-expert_logit).mean();
  auto generator = torch::nn::functional::softplus(generator_logit).mean();
  return 0.5 * (expert + generator);
}

}  // namespace segue
