// TRPO (algorithms/trpo.h): one update on a collected batch stays in the trust region and
// raises the surrogate, both computed here independently of the learner; a batch without
// advantage leaves the policy where it was; a fixed-seed run learns; an interrupted run
// resumes to the unbroken one's policy, byte for byte; bad settings are refused in one line.
#include <gtest/gtest.h>

#include <fstream>

#include "algorithms/ppo.h"
#include "algorithms/trpo.h"
#include "core/error.h"
#include "core/run_dir.h"
#include "environments/registry.h"
#include "hrl/evaluation.h"
#include "tests/cli_run.h"
#include "tests/csv.h"
#include "tests/short_walker.h"
#include "tests/temp_dir.h"

namespace segue {
namespace {

struct ShortWalker : ShortWalkerTask<TrpoConfig> {
  ShortWalker() {
    cfg.num_envs = 8;
    cfg.steps_per_env = 256;
    cfg.total_steps = 40 * 2048;
    spec.init_log_std = 0.0;
  }
};

// The surrogate mean_t[exp(logp - logp_old) A_t] with A standardised over the batch, and
// the mean KL(pi_before || pi_now) over the batch, written out per dimension.
struct Measured {
  double surrogate, kl;
};
Measured measure(TRPO& trpo, const torch::Tensor& before_mean, const torch::Tensor& before_std) {
  torch::NoGradGuard no_grad;
  const RolloutBuffer& b = trpo.buffer();
  const int64_t m = int64_t(b.T) * b.N;
  auto obs = torch::from_blob(const_cast<float*>(b.obs.data()), {m, b.in_dim}).to(torch::kFloat64);
  auto act = torch::from_blob(const_cast<float*>(b.actions.data()), {m, b.act_dim}).to(torch::kFloat64);
  auto old_logp = torch::from_blob(const_cast<float*>(b.log_probs.data()), {m}).to(torch::kFloat64);
  auto adv = torch::from_blob(const_cast<float*>(b.advantages.data()), {m}).to(torch::kFloat64);
  adv = (adv - adv.mean()) / (adv.std() + 1e-8);
  auto net = trpo.net();
  auto mean = net->mean(obs.to(torch::kFloat32)).to(torch::kFloat64);
  auto std = torch::exp(net->log_std.to(torch::kFloat64));
  auto z = (act - mean) / std;
  auto logp = (-0.5 * z * z - torch::log(std) - 0.5 * std::log(2 * M_PI)).sum(1);
  const double surrogate = (torch::exp(logp - old_logp) * adv).mean().item<double>();
  // KL(N(m0, s0^2) || N(m1, s1^2)) = log(s1 / s0) + (s0^2 + (m0 - m1)^2) / (2 s1^2) - 1/2
  auto kl = (torch::log(std / before_std) + (before_std.pow(2) + (before_mean - mean).pow(2)) / (2 * std.pow(2)) - 0.5)
                .sum(1)
                .mean()
                .item<double>();
  return {surrogate, kl};
}

torch::Tensor batch_mean(TRPO& trpo) {
  torch::NoGradGuard no_grad;
  const RolloutBuffer& b = trpo.buffer();
  auto obs = torch::from_blob(const_cast<float*>(b.obs.data()), {int64_t(b.T) * b.N, b.in_dim});
  return trpo.net()->mean(obs).to(torch::kFloat64);
}

}  // namespace

TEST(Trpo, OneUpdateStaysInTheTrustRegionAndRaisesTheSurrogate) {
  at::set_num_threads(1);
  ShortWalker s;
  VectorEnv envs(s.make, s.cfg.num_envs, 1);
  TRPO trpo(s.cfg, s.spec, envs, 3);
  for (int i = 0; i < 2; ++i) {
    IterationStats st;
    trpo.collect_rollout(st);
    auto before_mean = batch_mean(trpo);
    auto before_std = torch::exp(trpo.net()->log_std.detach().to(torch::kFloat64)).clone();
    const Measured before = measure(trpo, before_mean, before_std);
    trpo.update(st);
    const Measured after = measure(trpo, before_mean, before_std);
    EXPECT_GT(st.step_size, 0.0) << "iteration " << i << ": no step accepted";
    EXPECT_GT(after.surrogate, before.surrogate) << "iteration " << i;
    EXPECT_GT(after.kl, 0.0);
    EXPECT_LE(after.kl, 1.5 * s.cfg.max_kl + 1e-6) << "iteration " << i;
    EXPECT_NEAR(st.approx_kl, after.kl, 1e-4 * s.cfg.max_kl + 1e-7);
    // Under the quadratic model the full step lands on the region's edge: the accepted
    // fraction f gives KL near f^2 max_kl, not a step that barely moved.
    EXPECT_GT(after.kl, 0.2 * st.step_size * st.step_size * s.cfg.max_kl) << "iteration " << i;
  }
}

TEST(Trpo, ABatchWithoutAdvantageLeavesThePolicyUnchanged) {
  at::set_num_threads(1);
  ShortWalker s;
  VectorEnv envs(s.make, s.cfg.num_envs, 1);
  TRPO trpo(s.cfg, s.spec, envs, 5);
  IterationStats st;
  trpo.collect_rollout(st);
  auto& adv = const_cast<RolloutBuffer&>(trpo.buffer()).advantages;
  std::fill(adv.begin(), adv.end(), 0.0f);
  std::vector<torch::Tensor> before;
  for (const auto& p : trpo.net()->actor->parameters()) before.push_back(p.detach().clone());
  before.push_back(trpo.net()->log_std.detach().clone());
  auto critic_before = trpo.net()->critic->parameters()[0].detach().clone();
  trpo.update(st);
  auto after = trpo.net()->actor->parameters();
  after.push_back(trpo.net()->log_std);
  for (size_t i = 0; i < before.size(); ++i) EXPECT_TRUE(torch::equal(before[i], after[i])) << "parameter " << i;
  EXPECT_EQ(st.step_size, 0.0);
  EXPECT_FALSE(torch::equal(critic_before, trpo.net()->critic->parameters()[0])) << "the value network still learns";
}

TEST(Trpo, ImprovesReturnOnAShortWalkerHorizon) {
  at::set_num_threads(1);
  ShortWalker s;
  VectorEnv envs(s.make, s.cfg.num_envs, 1);
  TRPO trpo(s.cfg, s.spec, envs, 7);
  auto mean_return = [&] { return summarize(evaluate_policy(trpo.policy(), s.make, 16, 123, 1).returns).mean; };
  const double before = mean_return();
  while (trpo.global_step() < s.cfg.total_steps) trpo.iterate();
  const double after = mean_return();
  EXPECT_GT(after, before + 50.0) << "before " << before << " after " << after;
}

TEST(Trpo, TrainingDoesNotDependOnTheThreadCount) {
  // With two threads the natural step and the value fit run side by side
  // (OnPolicyLearner::run_both).
  at::set_num_threads(1);
  expect_same_on_one_and_two_threads<TRPO>(ShortWalker(), [](const IterationStats& s) { return s.step_size > 0; });
}

class TrpoRuns : public TempDirTest {
 protected:
  TrpoRuns() : TempDirTest("trpo") {}
  std::string recipe(const std::string& name, const std::string& extra = "") {
    const std::string file = path(name + ".yaml");
    std::ofstream(file) << "task: walker_forward\n"
                           "threads: 1\n"
                           "run_dir: " << path(name) << "\n"
                           "checkpoint_every: 1\n"
                           "learner: trpo\n"
                           "env: {max_episode_steps: 50, success_steps: 50}\n"
                           "trpo: {total_steps: 8192, num_envs: 4, steps_per_env: 256" << extra << "}\n"
                           "eval: {episodes: 2}\n";
    return file;
  }
};

TEST_F(TrpoRuns, KilledThreeTimesResumesToTheUnbrokenRunsPolicy) {
  ASSERT_EQ(run_cli("train " + recipe("unbroken")).code, 0);
  const std::string file = recipe("killed"), checkpoint = path("killed/checkpoint.pt");
  for (int kill = 0; kill < 3; ++kill)  // each in the rollout after a new checkpoint
    ASSERT_TRUE(kill_after_next_checkpoint(file, checkpoint)) << "the run ended before kill " << kill;
  ASSERT_EQ(run_cli("train " + file).code, 0);
  auto a = csv(path("killed/metrics.csv")), b = csv(path("unbroken/metrics.csv"));
  ASSERT_EQ(a.size(), 9u);  // header and 8 iterations
  ASSERT_EQ(a[0], b[0]);
  EXPECT_NE(std::find(a[0].begin(), a[0].end(), "step_size"), a[0].end());
  for (size_t r = 1; r < a.size(); ++r)
    for (size_t c = 0; c < a[0].size(); ++c)
      if (a[0][c].find("seconds") == std::string::npos) EXPECT_EQ(a[r][c], b[r][c]) << a[0][c] << " row " << r;
  EXPECT_TRUE(read_file(path("killed/policy.pt")) == read_file(path("unbroken/policy.pt")));
}

TEST_F(TrpoRuns, ACheckpointResumesOnlyItsOwnLearnerAndSeedsAnother) {
  at::set_num_threads(1);
  ShortWalker s;
  VectorEnv e1(s.make, s.cfg.num_envs, 1), e2(s.make, s.cfg.num_envs, 1);
  TRPO trpo(s.cfg, s.spec, e1, 9);
  trpo.iterate();
  trpo.save(path("trpo.pt"));
  PpoConfig ppo_cfg;
  ppo_cfg.num_envs = s.cfg.num_envs;
  PPO ppo(ppo_cfg, s.spec, e2, 9);
  try {  // resuming: the optimiser's state would not fit
    ppo.load(path("trpo.pt"));
    ADD_FAILURE() << "a PPO run resumed a TRPO checkpoint";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("learner 'trpo'"), std::string::npos) << e.what();
  }
  // Continuing (init_from): networks, normalisers and counters, a fresh optimiser.
  ppo.load(path("trpo.pt"), {}, /*resume_episodes=*/false);
  EXPECT_EQ(ppo.iteration(), 1);
  std::vector<float> obs(26 * 2, 0.2f), a(12), b(12);
  trpo.policy().act(obs.data(), 2, a.data());
  ppo.policy().act(obs.data(), 2, b.data());
  EXPECT_EQ(a, b);
}

TEST_F(TrpoRuns, BadSettingsAreRefusedInOneLine) {
  auto one_line = [](const CliRun& r, const std::string& needle) {
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_EQ(r.output.rfind("error: ", 0), 0u) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos) << r.output;
  };
  const std::string file = recipe("bad");
  one_line(run_cli("train " + file + " --check --set learner=a2c"), "key 'learner'");
  one_line(run_cli("train " + file + " --check --set trpo.max_kl=0"), "key 'trpo.max_kl'");
  one_line(run_cli("train " + file + " --check --set trpo.max_kl=-0.01"), "key 'trpo.max_kl'");
  one_line(run_cli("train " + file + " --check --set learner=ppo"), "key 'trpo': applies to learner: trpo");
  one_line(run_cli("train " + file + " --check --set trpo.vf_minibatch=5000"), "key 'trpo.vf_minibatch'");
  EXPECT_EQ(run_cli("train " + file + " --check").code, 0);
}

}  // namespace segue
