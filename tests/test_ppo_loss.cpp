// The PPO objective (algorithms/ppo_loss.h) against values computed by hand, and its
// hand-written gradient against autograd's on the same formulas.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "algorithms/actor_critic.h"
#include "algorithms/ppo_loss.h"

namespace segue {
namespace {

constexpr double kHalfLog2Pi = 0.91893853320467274178;

// A one-dimensional minibatch whose rows have the given log-ratios: the action is the mean
// and sigma is 1, so log pi = -log(2 pi) / 2 and the old log-probability sets the ratio.
struct Rows {
  std::vector<float> mean, value, actions, old_log_prob, advantage, returns;
  std::vector<float> log_std{0.0f}, low{-10.0f}, high{10.0f};
  Rows(const std::vector<double>& log_ratio, const std::vector<double>& adv) {
    for (size_t i = 0; i < log_ratio.size(); ++i) {
      mean.push_back(0.0f), actions.push_back(0.0f), value.push_back(0.0f), returns.push_back(0.0f);
      old_log_prob.push_back(float(-kHalfLog2Pi - log_ratio[i]));
      advantage.push_back(float(adv[i]));
    }
  }
  PpoMinibatch batch() const {
    return {int(mean.size()), 1, mean.data(), value.data(), actions.data(), old_log_prob.data(),
            advantage.data(), returns.data(), log_std.data(), low.data(), high.data()};
  }
};

}  // namespace

TEST(PpoLoss, ClippedSurrogateByHand) {
  // ratios: e^0.5 = 1.6487 (clipped to 1.2 for A > 0), e^-0.5 = 0.6065 (clipped to 0.8
  // for A < 0: max(-A r, -A clip) picks the larger, i.e. the pessimistic term), 1.
  Rows rows({0.5, -0.5, 0.0, 0.5}, {2.0, -1.0, 3.0, -1.0});
  // Per sample: max(-A r, -A clip(r)):
  //  0: max(-2*1.6487, -2*1.2) = -2.4
  //  1: max(1*0.6065, 1*0.8)  = 0.8
  //  2: max(-3, -3)           = -3
  //  3: max(1.6487, 1.2)      = 1.6487 (a harmful ratio is never clipped away)
  const PpoLossTerms l = ppo_loss(rows.batch(), PpoCoefficients{0.2, 0.5, 0.0, 0.0});
  EXPECT_NEAR(l.policy, (-2.4 + 0.8 - 3.0 + std::exp(0.5)) / 4.0, 1e-6);
  EXPECT_NEAR(l.clip_fraction, 3.0 / 4.0, 1e-12);  // |r - 1| > 0.2 in rows 0, 1, 3
  // d L / d log pi = -A r / n where the max is -A r, 0 where the clipped term is flat
  // (rows 0 and 1); with the action at the mean, d L / d mu = 0 and d L / d log sigma =
  // sum of -(d L / d log pi).
  std::vector<float> d_mu(4), d_value(4), d_log_std(1);
  PpoGradient grad{d_mu.data(), d_value.data(), d_log_std.data()};
  ppo_loss(rows.batch(), PpoCoefficients{0.2, 0.5, 0.0, 0.0}, &grad);
  EXPECT_NEAR(d_log_std[0], -(-3.0 * 1.0 + 1.0 * std::exp(0.5)) / 4.0, 1e-6);
  EXPECT_EQ(d_mu, std::vector<float>(4, 0.0f));
}

TEST(PpoLoss, ValueLossAndTotal) {
  Rows rows({0.0, 0.0, 0.0}, {1.0, 1.0, 1.0});
  rows.value = {1.0f, 2.0f, 4.0f}, rows.returns = {0.0f, 2.0f, 1.0f};
  rows.log_std = {float(std::log(2.0))};
  for (float& old : rows.old_log_prob) old = float(-kHalfLog2Pi - std::log(2.0));  // ratio 1
  const PpoLossTerms l = ppo_loss(rows.batch(), PpoCoefficients{0.2, 0.5, 0.01, 0.0});
  EXPECT_NEAR(l.value, 0.5 * (1 + 0 + 9) / 3.0, 1e-6);
  EXPECT_NEAR(l.entropy, 0.5 * std::log(2 * M_PI * M_E * 4.0), 1e-6);  // N(0, 2^2)
  // ratio 1, A = 1: policy term = -1; total = -1 + 0.5 * 5/3 - 0.01 * entropy.
  EXPECT_NEAR(l.policy, -1.0, 1e-6);
  EXPECT_NEAR(l.total, -1.0 + 0.5 * 5.0 / 3.0 - 0.01 * l.entropy, 1e-6);
  EXPECT_NEAR(l.approx_kl, 0.0, 1e-9);
  EXPECT_NEAR(l.clip_fraction, 0.0, 1e-9);
  // d L / d V = vf_coef (V - R) / n.
  std::vector<float> d_mu(3), d_value(3), d_log_std(1);
  PpoGradient grad{d_mu.data(), d_value.data(), d_log_std.data()};
  ppo_loss(rows.batch(), PpoCoefficients{0.2, 0.5, 0.01, 0.0}, &grad);
  EXPECT_NEAR(d_value[0], 0.5 * 1.0 / 3, 1e-7);
  EXPECT_NEAR(d_value[1], 0.0, 1e-9);
  EXPECT_NEAR(d_value[2], 0.5 * 3.0 / 3, 1e-7);
}

TEST(PpoLoss, ActionBoundLossByHand) {
  // Bounds [-1, 1] and [0, 2]. Row 0: 1.5 is 0.5 above, 2.5 is 0.5 above -> 0.25 + 0.25.
  // Row 1: -3 is 2 below, 1 is inside -> 4. Row 2: inside -> 0. Mean over rows: 4.5 / 3.
  std::vector<float> mean{1.5f, 2.5f, -3.0f, 1.0f, 0.0f, 0.0f}, zeros(3, 0.0f), log_std(2, 0.0f);
  std::vector<float> low{-1.0f, 0.0f}, high{1.0f, 2.0f};
  // A = 0: the surrogate contributes no gradient, only the bound term does.
  const PpoMinibatch batch{3, 2, mean.data(), zeros.data(), mean.data(), zeros.data(), zeros.data(),
                           zeros.data(), log_std.data(), low.data(), high.data()};
  std::vector<float> d_mu(6), d_value(3), d_log_std(2);
  PpoGradient grad{d_mu.data(), d_value.data(), d_log_std.data()};
  const PpoLossTerms l = ppo_loss(batch, PpoCoefficients{0.2, 0.5, 0.0, 2.0}, &grad);
  EXPECT_NEAR(l.bound, 4.5 / 3.0, 1e-6);
  EXPECT_NEAR(l.total - l.policy - 0.5 * l.value, 2.0 * 4.5 / 3.0, 1e-6);
  // Gradient bound_coef * 2 * excursion / rows, pointing back inside; zero within the bounds.
  EXPECT_NEAR(d_mu[0], 2.0 * 2 * 0.5 / 3, 1e-6);
  EXPECT_NEAR(d_mu[2], 2.0 * -2 * 2.0 / 3, 1e-6);
  EXPECT_NEAR(d_mu[3], 0.0, 1e-9);
  EXPECT_NEAR(d_mu[4], 0.0, 1e-9);
}

TEST(PpoLoss, GradientEqualsAutogradOfTheSameObjective) {
  // Random rows with ratios on both sides of the clip interval and means outside the
  // bounds; autograd differentiates the objective written with tensor operations.
  torch::manual_seed(3);
  const int n = 64, k = 3;
  const PpoCoefficients c{0.2, 0.7, 0.03, 0.5};
  auto mean = torch::randn({n, k}) * 1.5, actions = mean + 0.4 * torch::randn({n, k});
  auto value = torch::randn({n}), returns = torch::randn({n}), adv = torch::randn({n});
  auto log_std = torch::tensor({-0.3f, 0.1f, -0.8f});
  auto low = torch::full({k}, -1.0f), high = torch::full({k}, 1.0f);
  auto z0 = (actions - mean) * torch::exp(-log_std);
  auto old = ((-0.5 * z0.pow(2) - log_std - kHalfLog2Pi).sum(-1) + 0.3 * torch::randn({n})).contiguous();
  auto f = [](const torch::Tensor& t) { return t.contiguous().data_ptr<float>(); };
  auto m = mean.contiguous(), a = actions.contiguous(), ls = log_std.contiguous();
  const PpoMinibatch batch{n, k, f(m), f(value), f(a), f(old), f(adv), f(returns), f(ls), f(low), f(high)};
  std::vector<float> d_mu(n * k), d_value(n), d_log_std(k);
  PpoGradient grad{d_mu.data(), d_value.data(), d_log_std.data()};
  const PpoLossTerms l = ppo_loss(batch, c, &grad);

  auto mu = m.clone().requires_grad_(), v = value.clone().requires_grad_(), s = ls.clone().requires_grad_();
  auto z = (a - mu) * torch::exp(-s);
  auto log_prob = (-0.5 * z.pow(2) - s - kHalfLog2Pi).sum(-1);
  auto ratio = torch::exp(log_prob - old);
  auto policy = torch::max(-adv * ratio, -adv * torch::clamp(ratio, 1.0 - c.clip, 1.0 + c.clip)).mean();
  auto value_term = 0.5 * (v - returns).pow(2).mean();
  auto entropy = (s + 0.5 + kHalfLog2Pi).sum();
  auto bound = (torch::relu(mu - high).pow(2) + torch::relu(low - mu).pow(2)).sum(-1).mean();
  auto total = policy + c.vf_coef * value_term - c.ent_coef * entropy + c.bound_coef * bound;
  total.backward();
  const double clipped = ((ratio - 1).abs() > c.clip).to(torch::kFloat64).mean().item<double>();
  ASSERT_GT(clipped, 0.1);  // the test reaches the flat parts
  EXPECT_NEAR(l.total, total.item<double>(), 1e-5);
  EXPECT_NEAR(l.clip_fraction, clipped, 1e-12);
  auto near = [](const std::vector<float>& got, const torch::Tensor& want) {
    auto g = torch::tensor(got).view(want.sizes());
    return (g - want).abs().max().item<double>() <= 1e-5 + 1e-4 * want.abs().max().item<double>();
  };
  EXPECT_TRUE(near(d_mu, mu.grad()));
  EXPECT_TRUE(near(d_value, v.grad()));
  EXPECT_TRUE(near(d_log_std, s.grad()));
}

TEST(PpoLoss, GaussianLogProbAndEntropy) {
  ActorCriticSpec spec;
  spec.obs_dim = 3;
  spec.act_dim = 2;
  spec.init_log_std = std::log(0.5);
  ActorCritic ac(spec);
  auto mean = torch::tensor({{0.0f, 1.0f}});
  auto a = torch::tensor({{0.5f, 0.0f}});
  // z = (0.5-0)/0.5 = 1 and (0-1)/0.5 = -2: log p = sum(-z^2/2 - log 0.5 - log(2 pi)/2).
  double want = -0.5 * (1 + 4) - 2 * std::log(0.5) - std::log(2 * M_PI);
  EXPECT_NEAR(ac->log_prob(mean, a).item<double>(), want, 1e-5);
  // The rollout's double-precision version agrees.
  float af[2] = {0.5f, 0.0f}, mf[2] = {0.0f, 1.0f}, ls[2] = {float(std::log(0.5)), float(std::log(0.5))};
  EXPECT_NEAR(gaussian_log_prob(af, mf, ls, 2), want, 1e-5);
  // Entropy of N(mu, 0.5^2) per dimension: 0.5 log(2 pi e 0.25).
  EXPECT_NEAR(ac->entropy().item<double>(), 2 * 0.5 * std::log(2 * M_PI * M_E * 0.25), 1e-5);
}

}  // namespace segue
