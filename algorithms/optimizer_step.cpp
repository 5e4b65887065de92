#include "algorithms/optimizer_step.h"

#include <Eigen/Core>
#include <cmath>
#include <memory>
#include <string>

#include "core/error.h"

namespace segue {

namespace {
Eigen::Map<Eigen::ArrayXf> array(const torch::Tensor& t) {
  return Eigen::Map<Eigen::ArrayXf>(t.data_ptr<float>(), t.numel());
}
}  // namespace

double clip_grad_norm(const std::vector<torch::Tensor>& params, double max_norm) {
  double squares = 0.0;
  for (const auto& p : params)
    if (p.grad().defined()) squares += array(p.grad()).cast<double>().square().sum();
  const double norm = std::sqrt(squares);
  const double scale = max_norm / (norm + 1e-6);
  if (scale < 1.0)
    for (const auto& p : params)
      if (p.grad().defined()) array(p.grad()) *= float(scale);
  return norm;
}

void adam_step(torch::optim::Adam& adam) {
  for (auto& group : adam.param_groups()) {
    const auto& options = static_cast<const torch::optim::AdamOptions&>(group.options());
    if (options.weight_decay() != 0.0 || options.amsgrad())
      throw Error("adam_step: weight decay and AMSGrad are not implemented");
    const double beta1 = std::get<0>(options.betas()), beta2 = std::get<1>(options.betas());
    for (const auto& p : group.params()) {
      if (!p.grad().defined()) continue;
      // LibTorch keys a parameter's state by its TensorImpl's address.
      auto& slot = adam.state()[c10::guts::to_string(p.unsafeGetTensorImpl())];
      if (!slot) {
        auto fresh = std::make_unique<torch::optim::AdamParamState>();
        fresh->exp_avg(torch::zeros_like(p));
        fresh->exp_avg_sq(torch::zeros_like(p));
        slot = std::move(fresh);
      }
      auto& state = static_cast<torch::optim::AdamParamState&>(*slot);
      state.step(state.step() + 1);
      const double correction1 = 1.0 - std::pow(beta1, double(state.step()));
      const double correction2 = 1.0 - std::pow(beta2, double(state.step()));
      auto g = array(p.grad()), m = array(state.exp_avg()), v = array(state.exp_avg_sq());
      auto theta = array(p.detach());
      m = float(beta1) * m + float(1.0 - beta1) * g;
      v = float(beta2) * v + float(1.0 - beta2) * g.square();
      theta -= float(options.lr() / correction1) * m / (v.sqrt() / float(std::sqrt(correction2)) + float(options.eps()));
    }
  }
}

}  // namespace segue
