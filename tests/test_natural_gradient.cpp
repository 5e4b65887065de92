// The pieces of TRPO's natural-gradient step against independent values: conjugate
// gradient against a direct solve, the Gaussian KL against a hand computation, and the
// Fisher-vector product against finite differences of the KL's gradient.
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
  auto kl = gaussian_kl(torch::zeros({1, 1}, torch::kFloat64), torch::zeros({1}, torch::kFloat64),
                        torch::ones({1, 1}, torch::kFloat64), torch::full({1}, std::log(2.0), torch::kFloat64));
  EXPECT_NEAR(kl.item<double>(), std::log(2.0) + 0.25 - 0.5, 1e-12);
  // Dimensions add; a distribution against itself is 0.
  auto mean = torch::tensor({{0.3, -0.2}}, torch::kFloat64), log_std = torch::tensor({-0.5, 0.1}, torch::kFloat64);
  EXPECT_NEAR(gaussian_kl(mean, log_std, mean, log_std).item<double>(), 0.0, 1e-15);
}

TEST(FisherVectorProduct, IsTheHessianOfTheMeanKlByFiniteDifferences) {
  torch::manual_seed(11);
  ActorCriticSpec spec;
  spec.obs_dim = 3, spec.act_dim = 2, spec.pi_hidden = {5}, spec.vf_hidden = {5};
  ActorCritic net(spec);
  net->to(torch::kFloat64);
  {  // an output layer away from its near-zero start, so the curvature is not trivial
    torch::NoGradGuard no_grad;
    for (auto& p : net->actor->parameters()) p.copy_(torch::randn_like(p) * 0.5);
    net->log_std.copy_(torch::tensor({-0.3, 0.2}, torch::kFloat64));
  }
  auto obs = torch::randn({16, 3}, torch::kFloat64);
  std::vector<torch::Tensor> params = net->actor->parameters();
  params.push_back(net->log_std);
  auto old_mean = net->mean(obs).detach();
  auto old_log_std = net->log_std.detach().clone();
  auto kl = [&] { return gaussian_kl(old_mean, old_log_std, net->mean(obs), net->log_std).mean(); };
  const auto theta = flatten(params).detach().clone();
  auto v = torch::randn_like(theta);
  auto hv = hessian_vector_product(kl, params, v);
  // (grad KL(theta + eps v) - grad KL(theta - eps v)) / (2 eps), with old fixed at theta.
  auto grad_at = [&](const torch::Tensor& at) {
    assign_flat(params, at);
    auto g = flatten(torch::autograd::grad({kl()}, params)).detach();
    assign_flat(params, theta);
    return g;
  };
  const double eps = 1e-5;
  auto fd = (grad_at(theta + eps * v) - grad_at(theta - eps * v)) / (2 * eps);
  EXPECT_LT((hv - fd).abs().max().item<double>(), 1e-6 * std::max(1.0, fd.abs().max().item<double>()))
      << "hv " << hv.slice(0, 0, 6) << " fd " << fd.slice(0, 0, 6);
  EXPECT_GT(hv.abs().max().item<double>(), 1e-3);  // not trivially zero
  // A Fisher matrix is positive semi-definite: v'Fv >= 0.
  EXPECT_GE(v.dot(hv).item<double>(), 0.0);
}

}  // namespace
}  // namespace segue
