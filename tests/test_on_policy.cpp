// OnPolicyLearner::init_actor (algorithms/on_policy.h): a trainer's actor starts as a given
// policy and acts exactly as it does, pi_ab as pi_b, or a policy that sees a prefix of the
// trainer's observation; one that sees more than the task gives is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "algorithms/ppo.h"
#include "core/assets.h"
#include "core/vector_env.h"
#include "environments/registry.h"
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

}  // namespace segue
