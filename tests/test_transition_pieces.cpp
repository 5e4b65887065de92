// The transition method's learners against hand-computed values: the AIRL
// discriminator (f with shaping and done masking, D, the reward identity of Eq. 3, the
// loss), the double-DQN target (Eq. 4), and the proximity predictor's labels and reward.
#include <gtest/gtest.h>

#include <cmath>

#include "algorithms/discriminator.h"
#include "algorithms/proximity_predictor.h"
#include "algorithms/switch_q_network.h"

namespace segue {
namespace {

// Sets the single Linear layer of a no-hidden-layer MLP.
void set_linear(torch::nn::Sequential& net, std::vector<float> w, std::vector<float> b, int out, int in) {
  torch::NoGradGuard no_grad;
  auto* linear = net->ptr(0)->as<torch::nn::Linear>();
  ASSERT_NE(linear, nullptr);
  linear->weight.copy_(torch::tensor(w).reshape({out, in}));
  linear->bias.copy_(torch::tensor(b));
}

// Linear g and h, so every number can be worked out by hand: s and s' have 2 numbers, a 1,
// gamma 0.9, g(s, a) = s1 + 2 s2 + 3 a + 0.5 and h(s) = s1 - s2 + 0.25.
DiscriminatorSpec linear_spec() {
  DiscriminatorSpec spec;
  spec.obs_dim = 2;
  spec.act_dim = 1;
  spec.hidden = {};
  spec.gamma = 0.9;
  return spec;
}
Discriminator linear_discriminator() {
  Discriminator d(linear_spec());
  set_linear(d->g, {1, 2, 3}, {0.5}, 1, 3);
  set_linear(d->h, {1, -1}, {0.25}, 1, 2);
  return d;
}

}  // namespace

TEST(Discriminator, ShapedRewardWithDoneMaskingByHand) {
  Discriminator d = linear_discriminator();
  auto s = torch::tensor({{1.0f, 2.0f}, {1.0f, 2.0f}});
  auto a = torch::tensor({{0.5f}, {0.5f}});
  auto s2 = torch::tensor({{3.0f, 1.0f}, {3.0f, 1.0f}});
  auto done = torch::tensor({0.0f, 1.0f});
  // g = 1 + 4 + 1.5 + 0.5 = 7; h(s) = -0.75; h(s') = 2.25.
  // f = 7 + 0.9 * 2.25 + 0.75 = 9.775; at a true end gamma h(s') is dropped: 7.75.
  auto f = d->f(s, a, s2, done);
  EXPECT_NEAR(f[0].item<float>(), 9.775, 1e-5);
  EXPECT_NEAR(f[1].item<float>(), 7.75, 1e-5);
  // D = exp f / (exp f + pi); Eq. 3: log D - log(1 - D) = f - log pi.
  auto log_pi = torch::tensor({-1.2f, 0.3f});
  auto r = d->reward(s, a, s2, done, log_pi);
  for (int i = 0; i < 2; ++i) {
    double fi = f[i].item<double>(), pi = std::exp(log_pi[i].item<double>());
    double D = std::exp(fi) / (std::exp(fi) + pi);
    EXPECT_NEAR(r[i].item<double>(), std::log(D) - std::log(1 - D), 1e-4);
    EXPECT_NEAR(r[i].item<double>(), fi - std::log(pi), 1e-5);
  }
}

TEST(Discriminator, LogisticLossByHand) {
  DiscriminatorSpec spec;
  spec.obs_dim = 1;
  spec.act_dim = 1;
  Discriminator d(spec);
  // Both logits 0: D = 1/2 on each side, loss = log 2.
  EXPECT_NEAR(d->loss(torch::zeros({3}), torch::zeros({3})).item<double>(), std::log(2.0), 1e-6);
  // Expert logit 2, generator logit -1: 0.5 (log(1 + e^-2) + log(1 + e^-1)).
  double want = 0.5 * (std::log1p(std::exp(-2.0)) + std::log1p(std::exp(-1.0)));
  EXPECT_NEAR(d->loss(torch::tensor({2.0f}), torch::tensor({-1.0f})).item<double>(), want, 1e-6);
}

TEST(Discriminator, NormalisesInputsWithExpertStatisticsClippedAtFive) {
  DiscriminatorSpec spec;
  spec.obs_dim = 1;
  spec.act_dim = 1;
  spec.hidden = {};
  spec.gamma = 1.0;
  Discriminator d(spec);
  set_linear(d->g, {1, 0}, {0}, 1, 2);  // g = normalised s
  set_linear(d->h, {0}, {0}, 1, 1);     // no shaping
  d->set_normalizer(torch::tensor({10.0f}), torch::tensor({2.0f}), torch::tensor({0.0f}), torch::tensor({1.0f}));
  auto f = d->f(torch::tensor({{14.0f}, {100.0f}}), torch::zeros({2, 1}), torch::zeros({2, 1}), torch::zeros({2}));
  EXPECT_NEAR(f[0].item<float>(), 2.0, 1e-6);  // (14 - 10) / 2
  EXPECT_NEAR(f[1].item<float>(), 5.0, 1e-6);  // (100 - 10) / 2 = 45, clipped
}

TEST(SwitchQNetwork, DoubleDqnTargetByHand) {
  SwitchQSpec spec;
  spec.obs_dim = 1;
  spec.hidden = {};
  SwitchQNetwork online(spec), target(spec);
  set_linear(online->q, {1, 2}, {0, 0}, 2, 1);   // Q(s) = (s, 2s)
  set_linear(target->q, {3, -1}, {0, 1}, 2, 1);  // Q'(s) = (3s, 1 - s)
  auto next = torch::tensor({{2.0f}, {-1.0f}, {2.0f}});
  auto reward = torch::tensor({0.5f, 0.5f, 1.0f});
  auto done = torch::tensor({0.0f, 0.0f, 1.0f});
  auto y = double_dqn_target(online, target, reward, next, done, 0.9);
  // s' = 2: online picks switch (4 > 2), target values it 1 - 2 = -1: y = 0.5 - 0.9.
  // (Plain DQN would take max Q'(2) = 6.)
  EXPECT_NEAR(y[0].item<float>(), -0.4, 1e-6);
  // s' = -1: online picks stay (-1 > -2), target: -3: y = 0.5 - 2.7.
  EXPECT_NEAR(y[1].item<float>(), -2.2, 1e-6);
  // A terminal transition: y = r.
  EXPECT_NEAR(y[2].item<float>(), 1.0, 1e-6);
  // Loss at s = 1, a = switch: Q = 2, so (2 - y)^2 averaged.
  auto obs = torch::tensor({{1.0f}, {1.0f}, {1.0f}});
  auto act = torch::tensor({1, 1, 1});
  double want = (std::pow(2 + 0.4, 2) + std::pow(2 + 2.2, 2) + std::pow(2 - 1.0, 2)) / 3;
  EXPECT_NEAR(double_dqn_loss(online, target, obs, act, reward, next, done, 0.9).item<double>(), want, 1e-5);
  copy_weights(online, target);
  EXPECT_TRUE(torch::equal(online->forward(next), target->forward(next)));
}

TEST(ProximityPredictor, LabelsRewardsClippedOutputAndUnclippedLoss) {
  auto y = proximity_labels(4, true, 0.95);
  ASSERT_EQ(y.size(), 4u);
  EXPECT_NEAR(y[0], 0.857375, 1e-6);
  EXPECT_NEAR(y[1], 0.9025, 1e-6);
  EXPECT_NEAR(y[2], 0.95, 1e-6);
  EXPECT_NEAR(y[3], 1.0, 1e-6);
  for (float v : proximity_labels(3, false, 0.95)) EXPECT_EQ(v, 0.0f);
  // P along s_0..s_3 = 0.1, 0.3, 0.2, 0.6: rewards 0.2, -0.1, 0.4 + 0.6 (the final P).
  auto r = proximity_rewards({0.1f, 0.3f, 0.2f, 0.6f});
  ASSERT_EQ(r.size(), 3u);
  EXPECT_NEAR(r[0], 0.2, 1e-6);
  EXPECT_NEAR(r[1], -0.1, 1e-6);
  EXPECT_NEAR(r[2], 1.0, 1e-6);
  ProximitySpec spec;
  spec.obs_dim = 1;
  spec.hidden = {};
  ProximityPredictor p(spec);
  set_linear(p->net, {1}, {0}, 1, 1);
  auto out = p->forward(torch::tensor({{-2.0f}, {0.4f}, {3.0f}}));
  EXPECT_FLOAT_EQ(out[0].item<float>(), 0.0f);
  EXPECT_FLOAT_EQ(out[1].item<float>(), 0.4f);
  EXPECT_FLOAT_EQ(out[2].item<float>(), 1.0f);
  EXPECT_NEAR(p->loss(torch::tensor({{0.4f}}), torch::tensor({1.0f})).item<float>(), 0.36, 1e-6);
  // The loss sees the unclipped output: a positive state at -2 costs (-2 - 1)^2, not (0 - 1)^2.
  EXPECT_NEAR(p->loss(torch::tensor({{-2.0f}}), torch::tensor({1.0f})).item<float>(), 9.0, 1e-5);
}

}  // namespace segue
