#pragma once
// Builds a task with `env` settings given as YAML, e.g. make_task("walker_jump", "{curb_noise: 0}").
#include <memory>
#include <string>

#include "environments/registry.h"

namespace segue {

inline std::unique_ptr<Env> make_task(const std::string& task, const std::string& env = "{}") {
  Recipe recipe = Recipe::parse("{env: " + env + "}", "test");
  return task_factory(task, recipe.root().sub("env"))();
}

}  // namespace segue
