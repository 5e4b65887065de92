// PPO loss pieces against values computed by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "algorithms/actor_critic.h"
#include "algorithms/ppo_loss.h"

namespace segue {

TEST(PpoLoss, ClippedSurrogateByHand) {
  // ratios: e^0.5 = 1.6487 (clipped to 1.2 for A > 0), e^-0.5 = 0.6065 (clipped to 0.8
  // for A < 0: max(-A r, -A clip) picks the larger, i.e. the pessimistic term), 1.
  auto logp = torch::tensor({0.5, -0.5, 0.0, 0.5});
  auto old = torch::zeros({4});
  auto adv = torch::tensor({2.0, -1.0, 3.0, -1.0});
  double clip = 0.2;
  // Per sample: max(-A r, -A clip(r)):
  //  0: max(-2*1.6487, -2*1.2) = -2.4
  //  1: max(1*0.6065, 1*0.8)  = 0.8
  //  2: max(-3, -3)           = -3
  //  3: max(1.6487, 1.2)      = 1.6487 (a harmful ratio is never clipped away)
  double want = (-2.4 + 0.8 - 3.0 + std::exp(0.5)) / 4.0;
  EXPECT_NEAR(clipped_surrogate(logp, old, adv, clip).item<double>(), want, 1e-6);
}

TEST(PpoLoss, ValueLossAndTotal) {
  auto v = torch::tensor({1.0, 2.0, 4.0});
  auto r = torch::tensor({0.0, 2.0, 1.0});
  EXPECT_NEAR(value_loss(v, r).item<double>(), 0.5 * (1 + 0 + 9) / 3.0, 1e-6);
  auto zero = torch::zeros({3});
  auto ones = torch::ones({3});
  auto entropy = torch::tensor(1.5);
  PpoLoss l = ppo_loss(zero, zero, ones, v, r, entropy, 0.2, 0.5, 0.01);
  // ratio 1, A = 1: policy term = -1; total = -1 + 0.5 * 5/3 - 0.01 * 1.5.
  EXPECT_NEAR(l.policy.item<double>(), -1.0, 1e-6);
  EXPECT_NEAR(l.total.item<double>(), -1.0 + 0.5 * 5.0 / 3.0 - 0.015, 1e-6);
  EXPECT_NEAR(l.approx_kl.item<double>(), 0.0, 1e-9);
  EXPECT_NEAR(l.clip_fraction.item<double>(), 0.0, 1e-9);
}

TEST(PpoLoss, ActionBoundLossByHand) {
  // Bounds [-1, 1] and [0, 2]. Row 0: 1.5 is 0.5 above, 2.5 is 0.5 above -> 0.25 + 0.25.
  // Row 1: -3 is 2 below, 1 is inside -> 4. Row 2: inside -> 0. Mean over rows: 4.5 / 3.
  auto mean = torch::tensor({{1.5, 2.5}, {-3.0, 1.0}, {0.0, 0.0}}, torch::requires_grad());
  auto low = torch::tensor({-1.0, 0.0}), high = torch::tensor({1.0, 2.0});
  auto loss = action_bound_loss(mean, low, high);
  EXPECT_NEAR(loss.item<double>(), 4.5 / 3.0, 1e-6);
  // Gradient 2 * excursion / rows, pointing back inside; zero within the bounds.
  loss.backward();
  auto g = mean.grad();
  EXPECT_NEAR(g[0][0].item<double>(), 2 * 0.5 / 3, 1e-6);
  EXPECT_NEAR(g[1][0].item<double>(), -2 * 2.0 / 3, 1e-6);
  EXPECT_NEAR(g[1][1].item<double>(), 0.0, 1e-9);
  EXPECT_NEAR(g[2][0].item<double>(), 0.0, 1e-9);
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
