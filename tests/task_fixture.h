#pragma once
// Builds a task with `env` settings given as YAML, e.g. make_task("walker_jump", "{curb_noise: 0}").
#include <memory>
#include <string>

#include "core/mujoco_env.h"
#include "environments/registry.h"

namespace segue {

inline std::unique_ptr<Env> make_task(const std::string& task, const std::string& env = "{}") {
  Recipe recipe = Recipe::parse("{env: " + env + "}", "test");
  return task_factory(task, recipe.root().sub("env"))();
}

// Whether a random push (an external force on any body) acts during the current step.
inline bool pushed(const MujocoEnv& m) {
  for (int i = 0; i < 6 * m.model()->nbody; ++i)
    if (m.data()->xfrc_applied[i] != 0) return true;
  return false;
}

}  // namespace segue
