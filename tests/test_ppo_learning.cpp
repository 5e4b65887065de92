// PPO learns: on a short walker horizon, a fixed-seed run improves the deterministic
// policy's return; and an interrupted run resumes from its checkpoint.
#include <gtest/gtest.h>

#include <fstream>

#include "algorithms/ppo.h"
#include "environments/registry.h"
#include "hrl/evaluation.h"
#include "tests/short_walker.h"
#include "tests/temp_dir.h"

namespace segue {
namespace {

struct ShortWalker : ShortWalkerTask<PpoConfig> {
  ShortWalker() {
    cfg.num_envs = 8;
    cfg.steps_per_env = 256;
    cfg.minibatch_size = 512;
    cfg.epochs = 10;
    cfg.lr = 1e-3;
    cfg.total_steps = 30 * 2048;
  }
};

double mean_return(const Policy& p, const ShortWalker& s) {
  return summarize(evaluate_policy(p, s.make, 16, 123, 1).returns).mean;
}

}  // namespace

TEST(PpoLearning, ImprovesReturnOnAShortWalkerHorizon) {
  // Synchronous, and with the next rollout collected beside each update (policy_lag 1).
  at::set_num_threads(1);
  for (int lag : {0, 1}) {
    ShortWalker s;
    s.cfg.policy_lag = lag;
    VectorEnv envs(s.make, s.cfg.num_envs, 2);
    PPO ppo(s.cfg, s.spec, envs, 7);
    double before = mean_return(ppo.policy(), s);
    while (ppo.global_step() < s.cfg.total_steps) ppo.iterate();
    double after = mean_return(ppo.policy(), s);
    // A random-init policy falls within ~40 steps (return ~60-100); after 60k steps it stays
    // up and moves forward for most of the 100 steps.
    EXPECT_GT(after, before + 50.0) << "policy_lag " << lag << ": before " << before << " after " << after;
  }
}

TEST(PpoLearning, TrainingDoesNotDependOnTheThreadCount) {
  // Two threads step the environments and run each minibatch's actor and critic passes
  // side by side (OnPolicyLearner::run_both); LibTorch and BLAS stay on one thread each.
  at::set_num_threads(1);
  expect_same_on_one_and_two_threads<PPO>(ShortWalker(), [](const IterationStats& s) { return s.approx_kl > 0; });
}

TEST(PpoLearning, RewardHookSeesNextObservationsAndReplacesRewards) {
  at::set_num_threads(1);
  ShortWalker s;
  s.cfg.normalize_reward = false;
  VectorEnv envs(s.make, s.cfg.num_envs, 1);
  PPO ppo(s.cfg, s.spec, envs, 4);
  int checked_next = 0, checked_falls = 0;
  ppo.set_reward_hook([&](RolloutBuffer& b) {
    const int D = b.obs_dim;
    for (int t = 0; t < b.T; ++t)
      for (int i = 0; i < b.N; ++i) {
        size_t k = size_t(t) * b.N + i;
        if (!b.dones[k] && t + 1 < b.T) {  // s' is the next row's s
          ASSERT_TRUE(std::equal(&b.next_raw_obs[k * D], &b.next_raw_obs[(k + 1) * D], &b.raw_obs[(k + b.N) * D]));
          ++checked_next;
        } else if (b.dones[k] && b.next_raw_obs[k * D] < 0.8f) {
          ++checked_falls;  // s' is the fallen state (torso height is observation 0), not a reset
        }
        b.raw_rewards[k] = 1.0;
      }
  });
  IterationStats st;
  ppo.collect_rollout(st);
  EXPECT_GT(checked_next, 1000);
  EXPECT_GT(checked_falls, 0);  // an untrained walker falls within 100 steps
  const RolloutBuffer& b = ppo.buffer();
  std::vector<uint8_t> bootstrapped(b.rewards.size(), 0);
  for (int k : b.truncated_index) bootstrapped[k] = 1;
  for (size_t k = 0; k < b.rewards.size(); ++k)
    if (!bootstrapped[k]) ASSERT_EQ(b.rewards[k], 1.0f) << k;
}

// Tests that write checkpoints, in a scratch folder removed afterwards.
class PpoCheckpoints : public TempDirTest {
 protected:
  PpoCheckpoints() : TempDirTest("ppo") {}
};

TEST_F(PpoCheckpoints, ResumeRestoresEverythingTheEpisodesInFlightIncluded) {
  at::set_num_threads(1);
  ShortWalker s;
  s.cfg.total_steps = 4 * 2048;
  const std::string ckpt = path("checkpoint.pt");

  VectorEnv e1(s.make, s.cfg.num_envs, 1);
  PPO a(s.cfg, s.spec, e1, 5);
  a.iterate();
  a.iterate();
  a.save(ckpt);
  VectorEnv e2(s.make, s.cfg.num_envs, 1);
  PPO b(s.cfg, s.spec, e2, 5);
  b.load(ckpt);
  EXPECT_EQ(b.iteration(), 2);
  EXPECT_EQ(b.global_step(), 2 * 2048);
  // Same weights, normaliser and optimiser moments: identical deterministic policy...
  std::vector<float> obs(26 * 3, 0.3f), pa(18), pb(18);
  a.policy().act(obs.data(), 3, pa.data());
  b.policy().act(obs.data(), 3, pb.data());
  EXPECT_EQ(pa, pb);
  auto pa_params = a.net()->parameters(), pb_params = b.net()->parameters();
  for (size_t i = 0; i < pa_params.size(); ++i) EXPECT_TRUE(torch::equal(pa_params[i], pb_params[i]));
  // ...and training goes on exactly as the unbroken run: the episodes in flight at the
  // checkpoint (their states, random streams, running totals and exploration noise) go on.
  for (int i = 0; i < 2; ++i) {
    IterationStats sa = a.iterate(), sb = b.iterate();
    EXPECT_EQ(sa.episodes, sb.episodes) << "iteration " << i;
    EXPECT_EQ(sa.episode_return, sb.episode_return) << "iteration " << i;
    EXPECT_EQ(sa.policy_loss, sb.policy_loss) << "iteration " << i;
    EXPECT_EQ(sa.value_loss, sb.value_loss) << "iteration " << i;
  }
  pa_params = a.net()->parameters(), pb_params = b.net()->parameters();
  for (size_t i = 0; i < pa_params.size(); ++i) EXPECT_TRUE(torch::equal(pa_params[i], pb_params[i]));
  EXPECT_EQ(b.global_step(), 4 * 2048);
  // Continuing another run's checkpoint (init_from) starts fresh episodes instead.
  VectorEnv e3(s.make, s.cfg.num_envs, 1);
  PPO c(s.cfg, s.spec, e3, 5);
  c.load(ckpt, {}, /*resume_episodes=*/false);
  VectorEnv e4(s.make, s.cfg.num_envs, 1);
  PPO d(s.cfg, s.spec, e4, 5);
  d.load(ckpt);
  EXPECT_NE(c.iterate().episode_return, d.iterate().episode_return);
  // A file that is no checkpoint is refused in one line naming it.
  const std::string bad = path("not_a_checkpoint.pt");
  std::ofstream(bad) << "garbage";
  try {
    b.load(bad);
    ADD_FAILURE() << "garbage was loaded";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(bad + ": unreadable checkpoint: ", 0), 0u) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
}

TEST_F(PpoCheckpoints, ARestartedScheduleAnnealsOverTheStagesOwnSteps) {
  // Two iterations of a 4-iteration run, continued by a stage with a 6-iteration budget.
  // Its first update's rate is lr (1 - 2/6) if the schedule goes on, lr (1 - 0/4) if it
  // restarts; a resumed restarted stage keeps the restart: lr (1 - 1/4) next.
  at::set_num_threads(1);
  ShortWalker s;
  s.cfg.total_steps = 4 * 2048;
  const std::string first = path("first.pt"), stage = path("stage.pt");
  VectorEnv e1(s.make, s.cfg.num_envs, 1);
  PPO a(s.cfg, s.spec, e1, 5);
  a.iterate();
  a.iterate();
  EXPECT_DOUBLE_EQ(a.learning_rate(), s.cfg.lr * (1 - 1.0 / 4));
  a.save(first);
  s.cfg.total_steps = 6 * 2048;
  for (bool restart : {false, true}) {
    VectorEnv e(s.make, s.cfg.num_envs, 1);
    PPO b(s.cfg, s.spec, e, 5);
    b.load(first);
    if (restart) b.restart_lr_schedule();
    b.iterate();
    EXPECT_DOUBLE_EQ(b.learning_rate(), s.cfg.lr * (restart ? 1.0 : 1 - 2.0 / 6));
    if (restart) b.save(stage);
  }
  VectorEnv e3(s.make, s.cfg.num_envs, 1);
  PPO c(s.cfg, s.spec, e3, 5);
  c.load(stage);
  c.iterate();
  EXPECT_DOUBLE_EQ(c.learning_rate(), s.cfg.lr * (1 - 1.0 / 4));
}

TEST(PpoLearning, SetLogStdReopensExploration) {
  // A continued run's `init_log_std`: the Gaussian's log density at its own mean is then
  // sum_j (-log_std - log(2 pi) / 2) = 6 (1 - 0.9189385) for log std -1 in all 6 dims.
  at::set_num_threads(1);
  ShortWalker s;
  VectorEnv envs(s.make, 2, 1);
  PPO ppo(s.cfg, s.spec, envs, 5);
  ppo.set_log_std(-1.0);
  std::vector<float> obs(26, 0.2f), mean(6);
  ppo.policy().act(obs.data(), 1, mean.data());  // |mean| < 1 for a fresh net: not clipped
  double want = 6 * (1.0 - 0.5 * std::log(2 * M_PI));
  EXPECT_NEAR(ppo.log_prob(obs.data(), mean.data(), 1).item<double>(), want, 1e-4);
  EXPECT_NEAR(ppo.net()->log_std.mean().item<double>(), -1.0, 1e-7);
}

TEST(PpoLearning, MinLogStdHoldsExplorationOpen) {
  // From log std -3, one iteration of updates moves it by a few learning-rate steps at
  // most (Adam: 10 steps of lr 1e-3 move it under 0.01); with a floor at -2 it sits there.
  at::set_num_threads(1);
  for (double floor : {-20.0, -2.0}) {
    ShortWalker s;
    s.cfg.min_log_std = floor;
    VectorEnv envs(s.make, 2, 1);
    PPO ppo(s.cfg, s.spec, envs, 5);
    ppo.set_log_std(-3.0);
    ppo.iterate();
    auto ls = ppo.net()->log_std;
    if (floor < -3) {
      EXPECT_LT(ls.max().item<double>(), -2.9);
    } else {
      EXPECT_GE(ls.min().item<double>(), -2.0);
      EXPECT_LT(ls.max().item<double>(), -1.9);
    }
  }
}

}  // namespace segue
