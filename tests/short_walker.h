#pragma once
// The learners' tests' task: walker_forward cut to 100-step episodes (a success is staying
// up through them), a 26 -> 6 network, and one learner's settings for the tests to set.
#include <gtest/gtest.h>

#include <functional>
#include <memory>

#include "algorithms/actor_critic.h"
#include "algorithms/learner.h"
#include "core/recipe.h"
#include "core/vector_env.h"
#include "environments/registry.h"

namespace segue {

template <class Config>
struct ShortWalkerTask {
  Recipe recipe = Recipe::parse("{env: {max_episode_steps: 100, success_steps: 100}}", "test");
  std::function<std::unique_ptr<Env>()> make = task_factory("walker_forward", recipe.root().sub("env"));
  Config cfg;
  ActorCriticSpec spec;
  ShortWalkerTask() {
    spec.obs_dim = 26;
    spec.act_dim = 6;
  }
};

// Trains two `Learner`s from the same seed on `task`, one on one thread and one on two,
// for three iterations: every statistic and every parameter must be bit-identical (the
// threads step environments and run the update's two networks side by side, never
// changing what is computed). `took_a_step` guards against a test that shows nothing.
template <class Learner, class Task>
void expect_same_on_one_and_two_threads(const Task& task, const std::function<bool(const IterationStats&)>& took_a_step) {
  VectorEnv e1(task.make, task.cfg.num_envs, 1), e2(task.make, task.cfg.num_envs, 2);
  Learner a(task.cfg, task.spec, e1, 21), b(task.cfg, task.spec, e2, 21);
  for (int i = 0; i < 3; ++i) {
    const IterationStats sa = a.iterate(), sb = b.iterate();
    EXPECT_EQ(sa.episode_return, sb.episode_return) << "iteration " << i;
    EXPECT_EQ(sa.policy_loss, sb.policy_loss) << "iteration " << i;
    EXPECT_EQ(sa.value_loss, sb.value_loss) << "iteration " << i;
    EXPECT_TRUE(took_a_step(sa)) << "iteration " << i << ": the update did not move the policy, so this shows nothing";
  }
  auto pa = a.net()->parameters(), pb = b.net()->parameters();
  for (size_t i = 0; i < pa.size(); ++i) EXPECT_TRUE(torch::equal(pa[i], pb[i])) << "parameter " << i;
}

}  // namespace segue
