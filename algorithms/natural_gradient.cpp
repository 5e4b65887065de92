#include "algorithms/natural_gradient.h"

namespace segue {

torch::Tensor conjugate_gradient(const std::function<torch::Tensor(const torch::Tensor&)>& matrix_vector,
                                 const torch::Tensor& b, int iterations, double residual_tol) {
  torch::NoGradGuard no_grad;
  auto x = torch::zeros_like(b);
  auto r = b.clone();  // residual b - A x
  auto p = b.clone();  // search direction
  double rr = r.dot(r).item<double>();
  for (int i = 0; i < iterations && rr >= residual_tol; ++i) {
    auto ap = matrix_vector(p);
    const double alpha = rr / p.dot(ap).item<double>();
    x += alpha * p;
    r -= alpha * ap;
    const double rr_next = r.dot(r).item<double>();
    p = r + (rr_next / rr) * p;
    rr = rr_next;
  }
  return x;
}

torch::Tensor gaussian_kl(const torch::Tensor& old_mean, const torch::Tensor& old_log_std, const torch::Tensor& mean,
                          const torch::Tensor& log_std) {
  auto old_var = torch::exp(2 * old_log_std), var = torch::exp(2 * log_std);
  return (log_std - old_log_std + (old_var + (old_mean - mean).pow(2)) / (2 * var) - 0.5).sum(-1);
}

torch::Tensor hessian_vector_product(const std::function<torch::Tensor()>& f, const std::vector<torch::Tensor>& params,
                                     const torch::Tensor& v) {
  torch::AutoGradMode enable_grad(true);  // also inside conjugate_gradient's no-grad scope
  auto grads = torch::autograd::grad({f()}, params, {}, /*retain_graph=*/true, /*create_graph=*/true);
  auto grad_v = (flatten(grads) * v).sum();
  auto hv = torch::autograd::grad({grad_v}, params);
  return flatten(hv).detach();
}

torch::Tensor flatten(const std::vector<torch::Tensor>& tensors) {
  std::vector<torch::Tensor> flat;
  for (const auto& t : tensors) flat.push_back(t.reshape({-1}));
  return torch::cat(flat);
}

void assign_flat(const std::vector<torch::Tensor>& params, const torch::Tensor& flat) {
  torch::NoGradGuard no_grad;
  int64_t at = 0;
  for (const auto& p : params) {
    const int64_t n = p.numel();
    p.copy_(flat.slice(0, at, at + n).view_as(p));
    at += n;
  }
}

}  // namespace segue
