#pragma once
// Task names (docs/reference/tasks.md#task-names) to environment constructors. A task's
// parameters come from the recipe's `env:` section; every key has the reference default.
#include <memory>
#include <string>
#include <vector>

#include "core/env.h"
#include "core/recipe.h"

namespace segue {

// Reads the task's settings from `env` (so unknown keys can be refused afterwards) and
// returns a factory for independent copies. Throws segue::Error for an unknown task.
std::function<std::unique_ptr<Env>()> task_factory(const std::string& task, const Section& env);
// task_factory for a recipe: errors name the recipe's key ('task', 'env.*'), and one copy
// is built, so that settings the model cannot hold (more curbs than it has) are refused
// before any work; its spec goes to `spec`.
std::function<std::unique_ptr<Env>()> read_task(const Section& root, const std::string& task, EnvSpec& spec);
// The task with every setting at its reference value.
std::function<std::unique_ptr<Env>()> reference_task_factory(const std::string& task);
std::vector<std::string> task_names();

}  // namespace segue
