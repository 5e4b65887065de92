#include "algorithms/discriminator.h"

namespace segue {

DiscriminatorImpl::DiscriminatorImpl(const DiscriminatorSpec& s) : spec(s) {
  g = register_module("g", make_mlp(s.state_dim() + s.act_dim, s.hidden, 1, Activation::Relu, 1.0));
  h = register_module("h", make_mlp(s.state_dim(), s.hidden, 1, Activation::Relu, 1.0));
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
  auto s = ((o - obs_mean) / obs_std).clamp(-5.0, 5.0);
  if (spec.features.empty()) return s;
  // The order of ObsFeatures::write: per input, per period, sin then cos.
  constexpr double kTwoPi = 6.283185307179586476925;
  std::vector<torch::Tensor> cols{s};
  for (int i : spec.features.inputs)
    for (double p : spec.features.periods) {
      auto phase = o.select(-1, i).unsqueeze(-1) * (kTwoPi / p);
      cols.push_back(torch::sin(phase));
      cols.push_back(torch::cos(phase));
    }
  return torch::cat(cols, -1);
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

torch::Tensor DiscriminatorImpl::gradient_penalty(const torch::Tensor& obs, const torch::Tensor& act,
                                                 const torch::Tensor& next_obs, const torch::Tensor& done) {
  auto s = obs.detach().requires_grad_(true), a = act.detach().requires_grad_(true),
       s2 = next_obs.detach().requires_grad_(true);
  // f is a sum over rows of per-row functions, so the gradient of the sum holds each row's.
  auto grads = torch::autograd::grad({f(s, a, s2, done).sum()}, {s, a, s2}, {}, /*retain_graph=*/true,
                                     /*create_graph=*/true);
  return (grads[0].pow(2).sum(-1) + grads[1].pow(2).sum(-1) + grads[2].pow(2).sum(-1)).mean();
}

}  // namespace segue
