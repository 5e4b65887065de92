// The pieces of TRPO's natural-gradient step against independent values: conjugate
// gradient against a direct solve, the Gaussian KL against a hand computation, and the
// Fisher-vector product by hand against finite differences of autograd's KL gradient.
#include <gtest/gtest.h>

#include <cmath>

#include "algorithms/actor_critic.h"
#include "algorithms/natural_gradient.h"

namespace segue {
namespace {

TEST(ConjugateGradient, SolvesARandomSpdSystemInAtMostNSteps) {
  torch::manual_seed(3);
  const int n = 7;
  auto q = torch::randn({n, n}, torch::kFloat64);
  auto a = q.mm(q.t()) + 0.5 * torch::eye(n, torch::kFloat64);  // symmetric positive definite
  auto b = torch::randn({n}, torch::kFloat64);
  int products = 0;
  auto x = conjugate_gradient([&](const torch::Tensor& v) { ++products; return a.mv(v); }, b, n, 1e-20);
  EXPECT_LE(products, n);
  auto direct = torch::linalg_solve(a, b.unsqueeze(1)).squeeze(1);
  EXPECT_LT((x - direct).abs().max().item<double>(), 1e-8) << x << direct;
  EXPECT_LT((a.mv(x) - b).norm().item<double>(), 1e-8);
}

TEST(ConjugateGradient, StopsAtZeroResidual) {
  auto a = torch::eye(3, torch::kFloat64) * 2.0;
  int products = 0;
  auto x = conjugate_gradient([&](const torch::Tensor& v) { ++products; return a.mv(v); },
                              torch::zeros({3}, torch::kFloat64), 10);
  EXPECT_EQ(products, 0);
  EXPECT_EQ(x.abs().sum().item<double>(), 0.0);
}

TEST(GaussianKl, MatchesTheHandComputedValue) {
  // One dimension: N(0, 1) against N(1, 2^2): log 2 + (1 + 1) / (2 * 4) - 1/2.
  const float zero = 0.0f, one = 1.0f, log2 = float(std::log(2.0));
  EXPECT_NEAR(gaussian_kl_sum(&zero, &zero, &one, &log2, 1, 1), std::log(2.0) + 0.25 - 0.5, 1e-7);
  // Dimensions and rows add; a distribution against itself is 0.
  const float mean[4] = {0.3f, -0.2f, 1.0f, 0.5f}, log_std[2] = {-0.5f, 0.1f}, other[4] = {0.3f, -0.2f, 0.0f, 0.5f};
  EXPECT_NEAR(gaussian_kl_sum(mean, log_std, mean, log_std, 2, 2), 0.0, 1e-12);
  // Row 1's first mean 1 away at sigma e^-0.5: 1 / (2 e^-1) = e / 2.
  EXPECT_NEAR(gaussian_kl_sum(mean, log_std, other, log_std, 2, 2), std::exp(1.0) / 2, 1e-6);
}

// The mean KL(pi_old || pi_theta) of the test's network in double precision, by tensor
// operations, as the independent reference.
torch::Tensor mean_kl(ActorCritic& net, const torch::Tensor& obs, const torch::Tensor& old_mean,
                      const torch::Tensor& old_log_std) {
  auto old_var = torch::exp(2 * old_log_std), var = torch::exp(2 * net->log_std);
  auto mean = net->mean(obs);
  return (net->log_std - old_log_std + (old_var + (old_mean - mean).pow(2)) / (2 * var) - 0.5).sum(-1).mean();
}

TEST(FisherVectorProduct, IsTheHessianOfTheMeanKlByFiniteDifferences) {
  torch::manual_seed(11);
  for (Activation act : {Activation::Tanh, Activation::Relu}) {
    ActorCriticSpec spec;
    spec.obs_dim = 3, spec.act_dim = 2, spec.pi_hidden = {5, 4}, spec.vf_hidden = {5}, spec.activation = act;
    ActorCritic net(spec);
    {  // an output layer away from its near-zero start, so the curvature is not trivial
      torch::NoGradGuard no_grad;
      for (auto& p : net->actor->parameters()) p.copy_(torch::randn_like(p) * 0.5);
      net->log_std.copy_(torch::tensor({-0.3f, 0.2f}));
    }
    auto obs = torch::randn({16, 3});
    std::vector<torch::Tensor> params = net->actor->parameters();
    params.push_back(net->log_std);
    auto v = torch::randn({flatten(params).numel()});
    // The product by hand, in float, averaged over the 16 rows.
    MlpBackprop actor(net->actor, act);
    actor.forward(obs.data_ptr<float>(), 16);
    GaussianFisher fisher(actor, to_floats(net->log_std), 1.0 / 16);
    const torch::Tensor fv = fisher.product(v).to(torch::kFloat64);

    // (grad KL(theta + eps v) - grad KL(theta - eps v)) / (2 eps) in double, old fixed at theta.
    net->to(torch::kFloat64);
    params = net->actor->parameters();
    params.push_back(net->log_std);
    auto obs64 = obs.to(torch::kFloat64), v64 = v.to(torch::kFloat64);
    auto old_mean = net->mean(obs64).detach();
    auto old_log_std = net->log_std.detach().clone();
    const auto theta = flatten(params).detach().clone();
    auto grad_at = [&](const torch::Tensor& at) {
      assign_flat(params, at);
      auto g = flatten(torch::autograd::grad({mean_kl(net, obs64, old_mean, old_log_std)}, params)).detach();
      assign_flat(params, theta);
      return g;
    };
    const double eps = 1e-5;
    auto fd = (grad_at(theta + eps * v64) - grad_at(theta - eps * v64)) / (2 * eps);
    EXPECT_LT((fv - fd).abs().max().item<double>(), 1e-4 * std::max(1.0, fd.abs().max().item<double>()))
        << activation_name(act) << ": fv " << fv.slice(0, 0, 6) << " fd " << fd.slice(0, 0, 6);
    EXPECT_GT(fv.abs().max().item<double>(), 1e-3);  // not trivially zero
    // A Fisher matrix is positive semi-definite: v'Fv >= 0.
    EXPECT_GE(v64.dot(fv).item<double>(), 0.0);
  }
}

}  // namespace
}  // namespace segue
