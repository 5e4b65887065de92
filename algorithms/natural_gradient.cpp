#include "algorithms/natural_gradient.h"

#include <cmath>

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

double gaussian_kl_sum(const float* old_mean, const float* old_log_std, const float* mean, const float* log_std,
                       int64_t rows, int act_dim) {
  double kl = 0.0;
  for (int j = 0; j < act_dim; ++j) {
    const double old_var = std::exp(2.0 * old_log_std[j]), var = std::exp(2.0 * log_std[j]);
    double squares = 0.0;
    for (int64_t i = 0; i < rows; ++i) {
      const double d = double(old_mean[i * act_dim + j]) - mean[i * act_dim + j];
      squares += d * d;
    }
    kl += rows * (double(log_std[j]) - old_log_std[j] + old_var / (2.0 * var) - 0.5) + squares / (2.0 * var);
  }
  return kl;
}

GaussianFisher::GaussianFisher(MlpBackprop& mean_net, std::vector<float> log_std, double weight)
    : net_(mean_net), log_std_(std::move(log_std)), weight_(weight) {}

torch::Tensor GaussianFisher::product(const torch::Tensor& v) {
  const int64_t p = net_.parameter_count();
  const int k = int(log_std_.size());
  const torch::Tensor direction = v.to(torch::kFloat32).contiguous();
  const float* d = direction.data_ptr<float>();
  scaled_ = net_.jvp(d);
  for (int j = 0; j < k; ++j) scaled_.col(j) *= float(weight_ * std::exp(-2.0 * log_std_[j]));
  torch::Tensor fv = torch::empty({p + k});
  net_.backward(scaled_, fv.data_ptr<float>());
  const double rows = double(scaled_.rows());
  for (int j = 0; j < k; ++j) fv.data_ptr<float>()[p + j] = float(2.0 * weight_ * rows * d[p + j]);
  return fv;
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
