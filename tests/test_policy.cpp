// Inference paths agree: the Eigen mirror with LibTorch, the exported TorchScript with the
// in-memory policy, and a checkpoint with both; the mirror's flat parameter view.
#include <gtest/gtest.h>
#include <torch/script.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "algorithms/actor_critic.h"
#include "algorithms/policy.h"
#include "algorithms/ppo.h"
#include "environments/registry.h"
#include "tests/temp_dir.h"

namespace segue {

TEST(EigenMlp, EqualsLibTorchForward) {
  for (Activation act : {Activation::Tanh, Activation::Relu}) {
    torch::manual_seed(3);
    auto net = make_mlp(26, {32, 32}, 6, act, 1.0);
    EigenMlp mirror(net, act);
    auto x = torch::randn({17, 26}) * 2;
    auto want = net->forward(x);
    std::vector<float> got(17 * 6);
    mirror.forward(x.data_ptr<float>(), 17, got.data());
    auto diff = (want - torch::from_blob(got.data(), {17, 6})).abs().max().item<float>();
    EXPECT_LT(diff, 1e-5f) << activation_name(act);
    // Batch size 1 after 17: scratch is resized, results unchanged up to rounding (Eigen
    // sums a 1-row product in another order than a 17-row one: about a millionth of the value;
    // the inputs are torch::randn draws, which differ between CPUs' vector units).
    std::vector<float> one(6);
    mirror.forward(x.data_ptr<float>() + 26 * 4, 1, one.data());
    for (int j = 0; j < 6; ++j) {
      const float ref = got[4 * 6 + j];
      EXPECT_NEAR(one[j], ref, 1e-6f * std::max(1.f, std::abs(ref)));
    }
  }
}

TEST(EigenMlp, FlatParametersRoundTripAndChangeTheOutput) {
  torch::manual_seed(4);
  EigenMlp mlp(make_mlp(5, {7}, 2, Activation::Tanh, 1.0), Activation::Tanh);
  ASSERT_EQ(mlp.parameter_count(), size_t(5 * 7 + 7 + 7 * 2 + 2));
  std::vector<float> theta = mlp.parameters();
  EXPECT_EQ(theta[5 * 7], mlp.biases()[0][0]);      // W_0 row-major, then b_0
  EXPECT_EQ(theta[5 * 7 + 7], mlp.weights()[1](0, 0));
  const float x[5] = {0.1f, -0.2f, 0.3f, 0.0f, 1.0f};
  float y0[2], y1[2];
  mlp.forward(x, 1, y0);
  theta.back() += 0.5f;  // the last bias: output 1 moves by exactly 0.5
  mlp.set_parameters(theta);
  mlp.forward(x, 1, y1);
  EXPECT_FLOAT_EQ(y1[0], y0[0]);
  EXPECT_NEAR(y1[1], y0[1] + 0.5f, 1e-6f);
  EXPECT_EQ(mlp.parameters(), theta);
  EXPECT_THROW(mlp.set_parameters(std::vector<float>(3)), Error);
}

class PolicyFiles : public TempDirTest {
 protected:
  PolicyFiles() : TempDirTest("policy") {}
  // One short PPO iteration on walk forward (a non-trivial normaliser and weights), saved
  // as p.pt (TorchScript) and ckpt.pt; returns the in-memory policy.
  Policy train_and_save(const std::vector<int>& ignore_obs = {}, const ObsFeatures& features = {}) {
    Recipe r = Recipe::parse("{}", "test");
    VectorEnv envs(task_factory("walker_forward", r.root().sub("env")), 4, 1);
    PpoConfig cfg;
    cfg.num_envs = 4;
    cfg.steps_per_env = 64;
    cfg.minibatch_size = 64;
    cfg.epochs = 2;
    ActorCriticSpec spec;
    spec.obs_dim = 26;
    spec.act_dim = 6;
    spec.ignore_obs = ignore_obs;
    spec.features = features;
    PPO ppo(cfg, spec, envs, 11);
    ppo.iterate();
    Policy mem = ppo.policy();
    mem.export_torchscript(path("p.pt"));
    ppo.save(path("ckpt.pt"));
    return mem;
  }
};

TEST_F(PolicyFiles, TorchScriptExportRoundTrip) {
  Policy mem = train_and_save();

  torch::jit::Module m = torch::jit::load(path("p.pt"));
  EXPECT_EQ(m.run_method("obs_dim").toInt(), 26);
  EXPECT_EQ(m.run_method("act_dim").toInt(), 6);
  torch::manual_seed(1);
  auto obs = torch::randn({9, 26}) * 5;  // wide enough to hit the normaliser clip and action bounds
  auto ts = m.forward({obs}).toTensor();
  std::vector<float> a(9 * 6);
  mem.act(obs.data_ptr<float>(), 9, a.data());
  EXPECT_LT((ts - torch::from_blob(a.data(), {9, 6})).abs().max().item<float>(), 1e-5f);
  EXPECT_LE(ts.max().item<float>(), 1.0f);
  EXPECT_GE(ts.min().item<float>(), -1.0f);

  // The reference mean action from the LibTorch actor itself, normalised by hand.
  // Loading either file gives the same function.
  for (const char* file : {"p.pt", "ckpt.pt"}) {
    Policy loaded = Policy::load(path(file));
    std::vector<float> b(9 * 6);
    loaded.act(obs.data_ptr<float>(), 9, b.data());
    for (int i = 0; i < 9 * 6; ++i) EXPECT_NEAR(a[i], b[i], 1e-6f) << file;
  }
  // What a policy is for travels with the exported file; a file without it reads as "".
  EXPECT_EQ(Policy::load(path("p.pt")).source(), "");
  mem.set_source("hurdle walk-jump policy.pt");
  mem.export_torchscript(path("p.pt"));
  EXPECT_EQ(Policy::load(path("p.pt")).source(), "hurdle walk-jump policy.pt");
  EXPECT_EQ(torch::jit::load(path("p.pt")).attr("source").toStringRef(), "hurdle walk-jump policy.pt");
}

// The Gaussian policy's log std travels with both files, and act() with noise samples
// N(mu, exp(log_std)^2) around the mean action (then bounded); a step cap travels too.
TEST_F(PolicyFiles, SampledActionsFollowTheSavedLogStd) {
  Policy mem = train_and_save();
  ASSERT_EQ(mem.log_std().size(), 6u);
  for (const char* file : {"p.pt", "ckpt.pt"}) {
    const auto saved = Policy::load(path(file)).log_std();
    ASSERT_EQ(saved.size(), 6u) << file;
    for (int j = 0; j < 6; ++j) EXPECT_FLOAT_EQ(saved[j], mem.log_std()[j]) << file;
  }
  // Wide bounds, so that no sample is clipped; log std -1 on every action.
  Policy p(mem.mlp(), mem.obs_mean(), mem.obs_inv_std(), 10.0f, std::vector<float>(6, -1e9f),
           std::vector<float>(6, 1e9f));
  std::vector<float> obs(26, 0.1f), mu(6), a(6);
  p.act(obs.data(), 1, mu.data());
  Rng rng(3);
  EXPECT_THROW(p.act(obs.data(), 1, a.data(), &rng), Error);  // no log std set
  p.set_log_std(std::vector<float>(6, -1.0f));
  const int n = 20000;
  std::vector<double> sum(6, 0.0), squares(6, 0.0);
  for (int k = 0; k < n; ++k) {
    p.act(obs.data(), 1, a.data(), &rng);
    for (int j = 0; j < 6; ++j) sum[j] += a[j] - mu[j], squares[j] += (a[j] - mu[j]) * (a[j] - mu[j]);
  }
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(sum[j] / n, 0.0, 0.01) << j;                       // standard error 0.0026
    EXPECT_NEAR(std::sqrt(squares[j] / n), std::exp(-1.0), 0.01) << j;
  }
  EXPECT_THROW(p.set_log_std(std::vector<float>(5, 0.0f)), Error);
  // A transition policy's step cap travels with the exported file too (none: 0).
  EXPECT_EQ(Policy::load(path("p.pt")).max_steps(), 0);
  mem.set_max_steps(100);
  mem.export_torchscript(path("p.pt"));
  EXPECT_EQ(Policy::load(path("p.pt")).max_steps(), 100);
}

// policy.ignore_obs: the trained policy, its checkpoint and its TorchScript all act the
// same whatever the ignored inputs (here the walker's qacc) hold.
TEST_F(PolicyFiles, IgnoredInputsDoNotMoveTheActionInAnyExport) {
  train_and_save({17, 26});
  torch::manual_seed(2);
  auto obs = torch::randn({5, 26});
  auto shaken = obs.clone();
  shaken.narrow(1, 17, 9).normal_().mul_(1000);
  auto moved = obs.clone();
  moved.narrow(1, 0, 17).add_(1.0);
  for (const char* file : {"p.pt", "ckpt.pt"}) {
    Policy p = Policy::load(path(file));
    std::vector<float> a(30), b(30), c(30);
    p.act(obs.data_ptr<float>(), 5, a.data());
    p.act(shaken.data_ptr<float>(), 5, b.data());
    p.act(moved.data_ptr<float>(), 5, c.data());
    EXPECT_EQ(a, b) << file;
    EXPECT_NE(a, c) << file;  // the inputs it does see still matter
  }
  torch::jit::Module m = torch::jit::load(path("p.pt"));
  auto ts = m.forward({obs}).toTensor(), ts_shaken = m.forward({shaken}).toTensor();
  EXPECT_TRUE(torch::equal(ts, ts_shaken));
}

TEST_F(PolicyFiles, RefusesMismatchedAndMissingPolicies) {
  EXPECT_THROW(Policy::load(path("absent.pt")), Error);
  std::ofstream(path("junk.pt")) << "not a model";
  EXPECT_THROW(Policy::load(path("junk.pt")), Error);
  torch::manual_seed(0);
  Policy small(EigenMlp(make_mlp(5, {4}, 2, Activation::Tanh, 1.0), Activation::Tanh),
               std::vector<float>(5, 0), std::vector<float>(5, 1), 10, {-1, -1}, {1, 1});
  EnvSpec spec;
  spec.name = "walker_forward";
  spec.obs_dim = 26;
  spec.act_dim = 6;
  try {
    small.check_fits(spec, "small.pt");
    FAIL() << "a 5-input policy was accepted for a 26-input task";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("obs_dim 5"), std::string::npos) << e.what();
  }
}

TEST(ObsFeatures, SinesAndCosinesOfTheChosenInputs) {
  ObsFeatures f{{1, 3}, {2.0, 0.5}};
  ASSERT_EQ(f.size(), 8);
  const float raw[4] = {9.0f, 0.25f, 9.0f, -1.0f};
  float out[8];
  f.write(raw, out);
  // x1 = 0.25: phase pi/4 at P = 2, pi at P = 0.5; x3 = -1: phase -pi, then -4 pi.
  const float want[8] = {0.70710678f, 0.70710678f, 0.0f, -1.0f, 0.0f, -1.0f, 0.0f, 1.0f};
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(out[k], want[k], 1e-6f) << k;
}

// policy.fourier: the trained policy, its TorchScript and its checkpoint compute the same
// features in the same order, and a checkpoint records them.
TEST_F(PolicyFiles, PeriodicFeaturesSurviveEveryExport) {
  const ObsFeatures f{{0, 5}, {0.3, 1.7}};
  Policy mem = train_and_save({}, f);
  EXPECT_EQ(mem.obs_dim(), 26);
  EXPECT_EQ(mem.in_dim(), 34);
  torch::jit::Module m = torch::jit::load(path("p.pt"));
  EXPECT_EQ(m.run_method("obs_dim").toInt(), 26);
  torch::manual_seed(4);
  auto obs = torch::randn({7, 26}) * 2;
  auto ts = m.forward({obs}).toTensor();
  std::vector<float> a(7 * 6);
  mem.act(obs.data_ptr<float>(), 7, a.data());
  EXPECT_LT((ts - torch::from_blob(a.data(), {7, 6})).abs().max().item<float>(), 1e-5f);
  for (const char* file : {"p.pt", "ckpt.pt"}) {
    Policy loaded = Policy::load(path(file));
    EXPECT_TRUE(loaded.features() == f) << file;
    std::vector<float> b(7 * 6);
    loaded.act(obs.data_ptr<float>(), 7, b.data());
    for (int i = 0; i < 7 * 6; ++i) EXPECT_NEAR(a[i], b[i], 1e-6f) << file;
  }
  // The features are inputs the network uses: moving only input 5 by a quarter of 1.7 m
  // changes the action even with its normalised value held at 0 (inv_std 0).
  std::vector<float> x(26, 0.0f), y(26, 0.0f), ax(6), ay(6);
  y[5] = 1.7f / 4;
  std::vector<float> inv_std = mem.obs_inv_std();
  inv_std[5] = 0.0f;
  Policy pinned(mem.mlp(), mem.obs_mean(), inv_std, 10.0f, std::vector<float>(6, -1e9f), std::vector<float>(6, 1e9f), f);
  pinned.act(x.data(), 1, ax.data());
  pinned.act(y.data(), 1, ay.data());
  EXPECT_NE(ax, ay);
}

// A featureless skill starts a trainer with features as exactly itself (the features'
// weights start at zero), the way a jump with curb-phase inputs starts as the shipped jump.
TEST_F(PolicyFiles, FeaturelessPolicyStartsATrainerWithFeatures) {
  Policy plain = train_and_save();
  Recipe r = Recipe::parse("{}", "test");
  VectorEnv envs(task_factory("walker_forward", r.root().sub("env")), 2, 1);
  PpoConfig cfg;
  cfg.num_envs = 2;
  ActorCriticSpec spec;
  spec.obs_dim = 26;
  spec.act_dim = 6;
  spec.features = ObsFeatures{{3}, {1.0}};
  PPO ppo(cfg, spec, envs, 5);
  ppo.init_actor(plain);
  Policy started = ppo.policy();
  ASSERT_EQ(started.in_dim(), 28);
  torch::manual_seed(6);
  auto obs = torch::randn({5, 26});
  std::vector<float> a(30), b(30);
  plain.act(obs.data_ptr<float>(), 5, a.data());
  started.act(obs.data_ptr<float>(), 5, b.data());
  for (int i = 0; i < 30; ++i) EXPECT_NEAR(a[i], b[i], 1e-6f);
  // A checkpoint with other features is refused by a trainer built from the recipe.
  ppo.save(path("feat.pt"));
  ActorCriticSpec other = spec;
  other.features.periods = {2.0};
  PPO mismatched(cfg, other, envs, 5);
  EXPECT_THROW(mismatched.load(path("feat.pt")), Error);
}

}  // namespace segue
