#pragma once
// Skill training, what `segue train RECIPE` runs: a learner (PPO, TRPO or SAC, the recipe's
// `learner:`) on one task, or a curriculum (`stages:`, each stage a partial recipe laid over
// the rest of the file). Every run keeps a run directory (recipe.yaml, metrics.csv,
// checkpoint.pt, policy.pt, eval.json) that survives interruption: the same recipe run again
// resumes from the last checkpoint, and a finished run is only evaluated again.
#include <atomic>
#include <string>

#include "core/recipe.h"

namespace segue {

// Reads and checks the whole recipe, every stage of it, and trains nothing: a bad key is a
// segue::Error naming the file and key. Returns the number of stages (0: none).
size_t check_skill_recipe(const Recipe& recipe, const std::string& default_run_dir);

// Trains it. A signal sets `stop` (to its number): the run checkpoints and returns 128 + it.
// Returns 0 when done. With several ranks (Distributed::world()) PPO and TRPO are
// data-parallel and rank 0 keeps the run directory.
int train_skill_recipe(const Recipe& recipe, const std::string& default_run_dir, const std::atomic<int>* stop);

}  // namespace segue
