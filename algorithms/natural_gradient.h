#pragma once
// The pieces of a natural-gradient step (Kakade 2001; Schulman et al. 2015, TRPO), kept
// apart so each can be checked on its own: conjugate gradient, the KL between two diagonal
// Gaussian policies, and the Fisher-vector product of such a policy.
#include <torch/torch.h>

#include <functional>
#include <vector>

#include "algorithms/mlp_backprop.h"

namespace segue {

// Solves A x = b for a symmetric positive-definite A known only through v -> A v, by at
// most `iterations` steps of conjugate gradient from x = 0 (Nocedal & Wright, Alg. 5.2);
// stops early once the squared residual is below `residual_tol`. In exact arithmetic it
// solves an n x n system in n steps.
torch::Tensor conjugate_gradient(const std::function<torch::Tensor(const torch::Tensor&)>& matrix_vector,
                                 const torch::Tensor& b, int iterations, double residual_tol = 1e-10);

// KL(pi_old(.|s) || pi(.|s)) of diagonal Gaussians summed over action dimensions and rows:
// per dimension log(s/s_old) + (s_old^2 + (mu_old - mu)^2) / (2 s^2) - 1/2 (s: standard
// deviation). Means [rows, act_dim] row-major, log standard deviations [act_dim].
double gaussian_kl_sum(const float* old_mean, const float* old_log_std, const float* mean, const float* log_std,
                       int64_t rows, int act_dim);

// The Fisher-vector product of a Gaussian policy N(mu(s), diag(sigma^2)) with a
// state-independent log sigma, F the Hessian of weight x sum over rows of KL(pi_old ||
// pi_theta) at theta = theta_old (TRPO, Appendix C). At theta_old the KL's Hessian has no
// term in mu's second derivatives, so for the mean network F = weight J^T diag(1/sigma^2)
// J (J = dmu/dtheta, summed over rows), for each log sigma_j 2 weight rows, and nothing
// between them: F v is one forward-mode and one backward pass (MlpBackprop::jvp and
// backward), no Hessian formed.
class GaussianFisher {
 public:
  // mean_net: forward() already run on the rows the product sums over (and not again
  // while this is used); log_std: sigma's logs at theta_old.
  GaussianFisher(MlpBackprop& mean_net, std::vector<float> log_std, double weight);
  // v and F v laid out as the mean network's parameters, then the log standard deviations.
  torch::Tensor product(const torch::Tensor& v);

 private:
  MlpBackprop& net_;
  std::vector<float> log_std_;
  double weight_;
  MlpBackprop::RowMatrix scaled_;  // weight J v / sigma^2
};

// The parameters as one flat vector, and back.
torch::Tensor flatten(const std::vector<torch::Tensor>& tensors);
void assign_flat(const std::vector<torch::Tensor>& params, const torch::Tensor& flat);

}  // namespace segue
