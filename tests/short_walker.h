#pragma once
// The learners' tests' task: walker_forward cut to 100-step episodes (a success is staying
// up through them), a 26 -> 6 network, and one learner's settings for the tests to set.
#include <functional>
#include <memory>

#include "algorithms/actor_critic.h"
#include "core/recipe.h"
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

}  // namespace segue
