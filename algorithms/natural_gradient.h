#pragma once
// The pieces of a natural-gradient step (Kakade 2001; Schulman et al. 2015, TRPO), kept
// apart so each can be checked on its own: conjugate gradient, the mean KL between two
// diagonal Gaussian policies, and the Fisher-vector product as the Hessian-vector product
// of that KL.
#include <torch/torch.h>

#include <functional>
#include <vector>

namespace segue {

// Solves A x = b for a symmetric positive-definite A known only through v -> A v, by at
// most `iterations` steps of conjugate gradient from x = 0 (Nocedal & Wright, Alg. 5.2);
// stops early once the squared residual is below `residual_tol`. In exact arithmetic it
// solves an n x n system in n steps.
torch::Tensor conjugate_gradient(const std::function<torch::Tensor(const torch::Tensor&)>& matrix_vector,
                                 const torch::Tensor& b, int iterations, double residual_tol = 1e-10);

// KL(pi_old(.|s) || pi(.|s)) of diagonal Gaussians, summed over action dimensions, one
// value per row: log(s/s_old) + (s_old^2 + (mu_old - mu)^2) / (2 s^2) - 1/2 per dimension
// (s: standard deviation). mean: [B, A]; log_std: [A].
torch::Tensor gaussian_kl(const torch::Tensor& old_mean, const torch::Tensor& old_log_std, const torch::Tensor& mean,
                          const torch::Tensor& log_std);

// H v, H the Hessian of `f` with respect to `params` at their current values: the
// gradient of (grad f . v). With f the mean KL(pi_old || pi_theta) at theta = theta_old,
// H is the Fisher information matrix of the policy (TRPO, Appendix C).
torch::Tensor hessian_vector_product(const std::function<torch::Tensor()>& f, const std::vector<torch::Tensor>& params,
                                     const torch::Tensor& v);

// The parameters as one flat vector, and back.
torch::Tensor flatten(const std::vector<torch::Tensor>& tensors);
void assign_flat(const std::vector<torch::Tensor>& params, const torch::Tensor& flat);

}  // namespace segue
