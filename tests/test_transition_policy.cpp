// Algorithm 1's trainer (hrl/transition_policy.h): pi_ab's network takes pi_b's periodic
// input features when it starts as pi_b, and the generator's rewards are Eq. 3 of its own
// discriminator (with the absorbing term at a fall), which learns to tell pi_b's steps
// from pi_ab's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/vector_env.h"
#include "environments/registry.h"
#include "hrl/collection.h"
#include "hrl/transition_env.h"
#include "hrl/transition_policy.h"
#include "tests/transition_fixture.h"

namespace segue {

// pi_b with periodic input features (a jump that reads the curb's phase): pi_ab's network
// takes them when it starts as pi_b, and then acts exactly as pi_b; not otherwise.
TEST_F(TransitionTraining, TransitionNetworkTakesNextSkillsFeatures) {
  VectorEnv envs(task_factory("walker_jump", Recipe::parse("{}", "j").root()), 2, 1);
  ActorCriticSpec featured;
  featured.obs_dim = envs.spec().obs_dim, featured.act_dim = envs.spec().act_dim;
  featured.features = ObsFeatures{{26}, {1.9, 3.8}};
  PPO jump_trainer(PpoConfig(), featured, envs, 3);
  jump_trainer.iterate();
  const Policy jump = jump_trainer.policy();

  TransitionPolicyConfig tp;
  ActorCriticSpec net = tp.network(envs.spec(), jump);
  EXPECT_EQ(net.obs_dim, 28);
  EXPECT_TRUE(net.features == featured.features);
  PPO pi_ab(tp.ppo, net, envs, 4);
  pi_ab.init_actor(jump);
  auto obs = random_obs(8, 28, 5);
  std::vector<float> want(8 * 6), got(8 * 6);
  jump.act(obs.data(), 8, want.data());
  pi_ab.policy().act(obs.data(), 8, got.data());
  for (size_t i = 0; i < want.size(); ++i) ASSERT_NEAR(got[i], want[i], 1e-5) << i;

  tp.init_from_next = false;
  EXPECT_TRUE(tp.network(envs.spec(), jump).features.empty());
}

TEST_F(TransitionTraining, GeneratorRewardsAreEq3OfTheDiscriminator) {
  for (const std::string mode : {"airl", "airl_absorbing"}) {
    CompositeRecipe r = tiny({"transition.reward=" + mode, "transition.discriminator.steps=16"});
    const TransitionPolicyConfig& cfg = r.pipeline.transition;
    const Transition& tr = r.meta.transitions()[0];
    const Skill& b = r.skills[tr.to];
    StartStates starts = collect_start_states(r, 0, 6, 1);
    VectorEnv envs([&] { return std::make_unique<TransitionEnv>(r.make_env(), starts, tr, b.obs_begin, b.obs_end); },
                   cfg.ppo.num_envs, 1);
    TransitionPolicyTrainer trainer(cfg, envs, collect_demonstrations(r, 0, 300, 2), b.policy, 7);
    std::vector<double> losses;
    for (int i = 0; i < 6; ++i) losses.push_back(trainer.iterate().disc_loss);
    // The discriminator learns to tell pi_b's steps from pi_ab's (log 2 at chance).
    EXPECT_LT(losses.back(), losses.front()) << mode;
    EXPECT_LT(losses.back(), std::log(2.0)) << mode;

    // Recompute the last rollout's rewards independently of the hook.
    const RolloutBuffer& buf = trainer.ppo().buffer();
    const int64_t M = int64_t(buf.T) * buf.N, D = buf.obs_dim, A = buf.act_dim;
    auto obs = torch::from_blob(const_cast<float*>(buf.raw_obs.data()), {M, D});
    auto next = torch::from_blob(const_cast<float*>(buf.next_raw_obs.data()), {M, D});
    auto act = torch::from_blob(const_cast<float*>(buf.actions.data()), {M, A}).clamp(-1.0, 1.0);
    auto logp = torch::from_blob(const_cast<float*>(buf.log_probs.data()), {M});
    std::vector<float> done(M, 0.0f);
    std::vector<bool> truncated(M, false);
    for (int k : buf.truncated_index) truncated[k] = true;
    int falls = 0;
    for (int64_t k = 0; k < M; ++k) done[k] = buf.dones[k] && !truncated[k], falls += done[k] > 0;
    auto reward = trainer.discriminator()->reward(obs, act, next, torch::from_blob(done.data(), {M}), logp);
    // Eq. 3 is the logit of D: log D - log(1 - D) with D = exp f / (exp f + pi).
    auto f = trainer.discriminator()->f(obs, act, next, torch::from_blob(done.data(), {M})).detach();
    auto d = torch::exp(f) / (torch::exp(f) + torch::exp(logp));
    EXPECT_TRUE(torch::allclose(reward, torch::log(d) - torch::log(1 - d), 1e-3, 1e-3)) << mode;
    double worst = reward.min().item<double>(), gamma = cfg.ppo.gamma;
    for (int64_t k = 0; k < M; ++k) {
      double want = reward[k].item<double>();
      if (mode == "airl_absorbing" && done[k]) want += gamma * std::min(worst, 0.0) / (1 - gamma);
      ASSERT_NEAR(buf.raw_rewards[k], want, 1e-3 * std::max(1.0, std::abs(want))) << mode << " row " << k;
    }
    if (mode == "airl_absorbing") EXPECT_GT(falls, 0) << "the check of the absorbing term saw no fall";
  }
}

}  // namespace segue
