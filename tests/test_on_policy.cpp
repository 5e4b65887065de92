// OnPolicyLearner (algorithms/on_policy.h). init_actor: a trainer's actor starts as a
// given policy and acts exactly as it does, pi_ab as pi_b, or a policy that sees a prefix
// of the trainer's observation; one that sees more than the task gives is refused.
// policy_lag 1: the rollout collected beside an update is the policy's before that update;
// a run saved between that rollout and its update resumes to the unbroken run; the number
// of stepping threads changes nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "algorithms/ppo.h"
#include "algorithms/trpo.h"
#include "core/assets.h"
#include "core/vector_env.h"
#include "environments/registry.h"
#include "tests/short_walker.h"
#include "tests/temp_dir.h"
#include "tests/transition_fixture.h"

namespace segue {

TEST_F(TransitionTraining, PiAbStartsAsPiB) {
  CompositeRecipe r = tiny();
  const Policy& balance = r.skills[2].policy;
  VectorEnv envs(task_factory("walker_balance", Recipe::parse("{}", "b").root()), 2, 1);
  ActorCriticSpec net;
  net.obs_dim = balance.obs_dim(), net.act_dim = balance.act_dim();
  net.vf_hidden = {64, 64};
  PPO ppo(PpoConfig(), net, envs, 1);
  ppo.init_actor(balance);
  auto obs = random_obs(16, net.obs_dim, 5);
  std::vector<float> want(16 * 6), got(16 * 6);
  balance.act(obs.data(), 16, want.data());
  ppo.policy().act(obs.data(), 16, got.data());
  for (size_t i = 0; i < want.size(); ++i) ASSERT_NEAR(got[i], want[i], 1e-4) << i;
}

// A jump run may start as the shipped walk (recipe key init_policy): the walk sees the
// first 26 inputs, and the obstacle pair starts at zero weight and unscaled.
TEST_F(TransitionTraining, ActorStartsAsAPolicyOnAPrefixOfItsObservation) {
  Policy walk = Policy::load(repo_path("assets/policies/walker/walker_forward.pt"));
  VectorEnv envs(task_factory("walker_jump", Recipe::parse("{}", "j").root()), 2, 1);
  ActorCriticSpec net;
  net.obs_dim = envs.spec().obs_dim, net.act_dim = envs.spec().act_dim;
  ASSERT_EQ(net.obs_dim, walk.obs_dim() + 2);
  PPO ppo(PpoConfig(), net, envs, 1);
  ppo.init_actor(walk);
  auto obs = random_obs(16, net.obs_dim, 9);
  std::vector<float> prefix(16 * walk.obs_dim());
  for (int i = 0; i < 16; ++i)
    std::copy_n(&obs[i * net.obs_dim], walk.obs_dim(), &prefix[i * walk.obs_dim()]);
  std::vector<float> want(16 * 6), got(16 * 6);
  walk.act(prefix.data(), 16, want.data());
  ppo.policy().act(obs.data(), 16, got.data());
  for (size_t i = 0; i < want.size(); ++i) ASSERT_NEAR(got[i], want[i], 1e-4) << i;
  EXPECT_FLOAT_EQ(ppo.policy().obs_mean()[net.obs_dim - 1], 0.0f);
  EXPECT_NEAR(ppo.policy().obs_inv_std()[net.obs_dim - 1], 1.0f, 1e-6);
  // A policy that sees more than the task gives cannot start it.
  VectorEnv walks(task_factory("walker_forward", Recipe::parse("{}", "w").root()), 2, 1);
  ActorCriticSpec small = net;
  small.obs_dim = walks.spec().obs_dim;
  PPO narrow(PpoConfig(), small, walks, 1);
  EXPECT_THROW(narrow.init_actor(ppo.policy()), Error);
}

namespace {

// A short walker horizon, the next rollout collected beside each update.
template <class Config>
struct LaggedWalker : ShortWalkerTask<Config> {
  LaggedWalker() {
    this->cfg.num_envs = 8;
    this->cfg.steps_per_env = 128;
    this->cfg.total_steps = 5 * 1024;
    this->cfg.policy_lag = 1;
  }
};

std::vector<torch::Tensor> copy_of(const std::vector<torch::Tensor>& params) {
  std::vector<torch::Tensor> out;
  for (const auto& p : params) out.push_back(p.detach().clone());
  return out;
}

// log pi(a|s) of the rollout in `learner`'s buffer under the parameters `theta`, at the
// network inputs stored with it.
torch::Tensor rollout_log_probs(OnPolicyLearner& learner, const std::vector<torch::Tensor>& theta) {
  const RolloutBuffer& b = learner.buffer();
  const int64_t M = int64_t(b.T) * b.N;
  auto params = learner.net()->parameters();
  const auto now = copy_of(params);
  torch::NoGradGuard no_grad;
  for (size_t i = 0; i < params.size(); ++i) params[i].copy_(theta[i]);
  auto obs = torch::from_blob(const_cast<float*>(b.obs.data()), {M, b.in_dim});
  auto act = torch::from_blob(const_cast<float*>(b.actions.data()), {M, b.act_dim});
  auto logp = learner.net()->log_prob(learner.net()->mean(obs), act).clone();
  for (size_t i = 0; i < params.size(); ++i) params[i].copy_(now[i]);
  return logp;
}

}  // namespace

TEST(PolicyLag, TheRolloutBesideAnUpdateIsThePolicysBeforeIt) {
  at::set_num_threads(1);
  LaggedWalker<PpoConfig> s;
  VectorEnv envs(s.make, s.cfg.num_envs, 1);
  PPO ppo(s.cfg, s.spec, envs, 3);
  for (int i = 0; i < 3; ++i) {
    const auto before = copy_of(ppo.net()->parameters());
    ppo.iterate();  // updates on the rollout collected before, collects the next one beside
    auto stored = torch::from_blob(const_cast<float*>(ppo.buffer().log_probs.data()),
                                   {int64_t(ppo.buffer().log_probs.size())});
    EXPECT_TRUE(torch::allclose(rollout_log_probs(ppo, before), stored, 1e-4, 1e-4)) << "iteration " << i;
    EXPECT_FALSE(torch::allclose(rollout_log_probs(ppo, ppo.net()->parameters()), stored, 1e-4, 1e-4))
        << "iteration " << i << ": the update did not move the policy, so this test shows nothing";
  }
}

TEST(PolicyLag, TrainingDoesNotDependOnTheThreadCount) {
  at::set_num_threads(1);
  expect_same_on_one_and_two_threads<TRPO>(LaggedWalker<TrpoConfig>(),
                                           [](const IterationStats& s) { return s.step_size > 0; });
}

class PolicyLagCheckpoints : public TempDirTest {
 protected:
  PolicyLagCheckpoints() : TempDirTest("policy_lag") {}
};

// Saved after two iterations, the checkpoint holds the third rollout, collected but not
// yet used: the resumed run trains on it and goes on as the unbroken one, to its end (the
// last iteration collects nothing beside its update).
TEST_F(PolicyLagCheckpoints, ResumesBetweenARolloutAndItsUpdate) {
  at::set_num_threads(1);
  LaggedWalker<PpoConfig> s;
  const std::string ckpt = path("checkpoint.pt");
  VectorEnv e1(s.make, s.cfg.num_envs, 1), e2(s.make, s.cfg.num_envs, 1);
  PPO a(s.cfg, s.spec, e1, 5), b(s.cfg, s.spec, e2, 5);
  a.iterate();
  a.iterate();
  a.save(ckpt);
  b.load(ckpt);
  EXPECT_EQ(b.buffer().log_probs, a.buffer().log_probs);
  EXPECT_EQ(b.buffer().advantages, a.buffer().advantages);
  int iterations = 2;
  while (a.global_step() < s.cfg.total_steps) {
    IterationStats sa = a.iterate(), sb = b.iterate();
    ++iterations;
    EXPECT_EQ(sa.episodes, sb.episodes) << "iteration " << iterations;
    if (sa.episodes > 0) EXPECT_EQ(sa.episode_return, sb.episode_return) << "iteration " << iterations;
    EXPECT_EQ(sa.policy_loss, sb.policy_loss) << "iteration " << iterations;
    // Only the last iteration, which collects nothing, ends no episode.
    EXPECT_EQ(sa.episodes == 0, a.global_step() == s.cfg.total_steps) << "iteration " << iterations;
  }
  EXPECT_EQ(iterations, 5);
  EXPECT_EQ(b.global_step(), a.global_step());
  auto pa = a.net()->parameters(), pb = b.net()->parameters();
  for (size_t i = 0; i < pa.size(); ++i) EXPECT_TRUE(torch::equal(pa[i], pb[i])) << "parameter " << i;
  // The same checkpoint continued by a synchronous run (another recipe: init_from) carries
  // no rollout over: its first iteration collects one with the loaded policy.
  s.cfg.policy_lag = 0;
  VectorEnv e3(s.make, s.cfg.num_envs, 1);
  PPO c(s.cfg, s.spec, e3, 5);
  c.load(ckpt, {}, /*resume_episodes=*/false);
  c.iterate();
  EXPECT_EQ(c.global_step(), 3 * 1024);
}

}  // namespace segue
