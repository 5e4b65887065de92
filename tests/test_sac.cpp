// SAC (algorithms/sac.h): the soft Bellman target by hand; the temperature moves toward
// the target entropy; a fixed-seed run improves; a killed run resumes to the unbroken
// run's policy, byte for byte, its replay buffer included; the exported policy squashes
// its actions into the bounds, in Segue and in TorchScript alike.
#include <gtest/gtest.h>

#include <fstream>

#include "algorithms/sac.h"
#include "core/run_dir.h"
#include "environments/registry.h"
#include "hrl/evaluation.h"
#include "tests/cli_run.h"
#include "tests/csv.h"
#include "tests/short_walker.h"
#include "tests/temp_dir.h"

namespace segue {
namespace {

TEST(Sac, SoftTargetMatchesTheHandComputedRows) {
  // y = r + gamma (1 - terminal) (min(q1', q2') - alpha logp'), gamma 0.9, alpha 0.5:
  //   row 0: 1 + 0.9 (min(2, 3) - 0.5 (-1))  = 1 + 0.9 * 2.5 = 3.25
  //   row 1: -1 + 0.9 (min(4, 1) - 0.5 (2))  = -1 + 0.9 * 0 = -1
  //   row 2 (terminal): 0.5
  auto y = soft_q_target(torch::tensor({1.0, -1.0, 0.5}), torch::tensor({0.0, 0.0, 1.0}), torch::tensor({2.0, 4.0, 9.0}),
                         torch::tensor({3.0, 1.0, 9.0}), torch::tensor({-1.0, 2.0, 9.0}), 0.5, 0.9);
  EXPECT_NEAR(y[0].item<double>(), 3.25, 1e-12);
  EXPECT_NEAR(y[1].item<double>(), -1.0, 1e-12);
  EXPECT_NEAR(y[2].item<double>(), 0.5, 1e-12);
}

struct ShortWalker : ShortWalkerTask<SacConfig> {
  ShortWalker() {
    cfg.buffer_size = 100000;
    cfg.start_steps = 2000;
    cfg.update_after = 1000;
    cfg.batch_size = 128;
    spec.pi_hidden = {64, 64}, spec.vf_hidden = {64, 64};
    spec.activation = Activation::Relu;
  }
};

// A batch of random transitions from the task, stored through the learner's replay.
ReplayBuffer::Batch random_batch(SAC& sac, int rows, uint64_t seed) {
  torch::manual_seed(seed);
  ReplayBuffer& r = sac.replay();
  auto obs = torch::randn({rows, 26}), act = torch::rand({rows, 6}) * 2 - 1, next = torch::randn({rows, 26});
  for (int i = 0; i < rows; ++i)
    r.add(obs[i].data_ptr<float>(), act[i].data_ptr<float>(), 1.0, next[i].data_ptr<float>(), false);
  std::vector<int64_t> idx(rows);
  for (int i = 0; i < rows; ++i) idx[i] = i;
  return r.gather(idx);
}

TEST(Sac, TheTemperatureMovesTowardTheTargetEntropy) {
  at::set_num_threads(1);
  ShortWalker s;
  VectorEnv envs(s.make, 1, 1);
  // The untrained actor's entropy (log std near 0, six dimensions, squashed) is far above
  // the target -6: alpha falls, making entropy cheaper to give up.
  SAC sac(s.cfg, s.spec, envs, 1);
  auto batch = random_batch(sac, 64, 2);
  const double before = sac.alpha();
  SAC::UpdateStats u{};
  for (int i = 0; i < 20; ++i) u = sac.update(batch);
  EXPECT_GT(u.entropy, sac.target_entropy());
  EXPECT_LT(sac.alpha(), before);
  // With tune_alpha off, alpha stays where it started (the reference's fixed 0.2).
  SacConfig fixed = s.cfg;
  fixed.tune_alpha = false;
  SAC still(fixed, s.spec, envs, 1);
  auto b2 = random_batch(still, 64, 2);
  for (int i = 0; i < 5; ++i) still.update(b2);
  EXPECT_NEAR(still.alpha(), fixed.init_alpha, 1e-7);  // log alpha is a float
}

TEST(Sac, ImprovesReturnOnAShortWalkerHorizon) {
  at::set_num_threads(1);
  ShortWalker s;
  s.cfg.total_steps = 24000;
  VectorEnv envs(s.make, 1, 1);
  SAC sac(s.cfg, s.spec, envs, 7);
  auto mean_return = [&] { return summarize(evaluate_policy(sac.policy(), s.make, 16, 123, 1).returns).mean; };
  const double before = mean_return();
  while (sac.global_step() < s.cfg.total_steps) sac.iterate();
  const double after = mean_return();
  EXPECT_GT(after, before + 50.0) << "before " << before << " after " << after;
}

class SacRuns : public TempDirTest {
 protected:
  SacRuns() : TempDirTest("sac") {}
  std::string recipe(const std::string& name) {
    const std::string file = path(name + ".yaml");
    std::ofstream(file) << "task: walker_forward\n"
                           "threads: 1\n"
                           "run_dir: " << path(name) << "\n"
                           "checkpoint_every: 1\n"
                           "learner: sac\n"
                           "policy: {pi_hidden: [32, 32], vf_hidden: [32, 32], activation: relu}\n"
                           "env: {max_episode_steps: 50, success_steps: 50}\n"
                           "sac: {total_steps: 3000, num_envs: 2, steps_per_iteration: 500, update_every: 50, "
                           "start_steps: 600, update_after: 300, batch_size: 32, buffer_size: 5000}\n"
                           "eval: {episodes: 2}\n";
    return file;
  }
};

TEST_F(SacRuns, KilledTwiceResumesToTheUnbrokenRunsPolicy) {
  ASSERT_EQ(run_cli("train " + recipe("unbroken")).code, 0);
  const std::string file = recipe("killed"), checkpoint = path("killed/checkpoint.pt");
  for (int kill = 0; kill < 2; ++kill)  // each in the rollout after a new checkpoint
    ASSERT_TRUE(kill_after_next_checkpoint(file, checkpoint)) << "the run ended before kill " << kill;
  ASSERT_EQ(run_cli("train " + file).code, 0);
  auto a = csv(path("killed/metrics.csv")), b = csv(path("unbroken/metrics.csv"));
  ASSERT_EQ(a.size(), 7u);  // header and 6 iterations
  for (size_t r = 1; r < a.size(); ++r)
    for (size_t c = 0; c < a[0].size(); ++c)
      if (a[0][c].find("seconds") == std::string::npos) EXPECT_EQ(a[r][c], b[r][c]) << a[0][c] << " row " << r;
  EXPECT_TRUE(read_file(path("killed/policy.pt")) == read_file(path("unbroken/policy.pt")));
  // The export squashes into the bounds: Segue's reading of it agrees with TorchScript's
  // (Policy::load checks that on a batch), and actions stay inside [-1, 1].
  Policy p = Policy::load(path("killed/policy.pt"));
  EXPECT_TRUE(p.tanh_output());
  std::vector<float> obs(26 * 4, 3.0f), act(6 * 4);
  p.act(obs.data(), 4, act.data());
  for (float x : act) EXPECT_LE(std::abs(x), 1.0f);
}

TEST_F(SacRuns, BadSettingsAreRefusedInOneLine) {
  auto one_line = [](const CliRun& r, const std::string& needle) {
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos) << r.output;
  };
  const std::string file = recipe("bad");
  one_line(run_cli("train " + file + " --check --set sac.update_every=51"), "key 'sac.update_every'");
  one_line(run_cli("train " + file + " --check --set sac.tau=0"), "key 'sac.tau'");
  one_line(run_cli("train " + file + " --check --set ppo.lr=0.1"), "key 'ppo': applies to learner: ppo");
  one_line(run_cli("train " + file + " --check --set init_policy=x.pt"), "key 'init_policy'");
  EXPECT_EQ(run_cli("train " + file + " --check").code, 0);
}

}  // namespace
}  // namespace segue
