#pragma once
// The fixture of the transition method's training tests (test_transition_policy.cpp,
// test_switch_training.cpp, test_pipeline.cpp, ...): a scratch folder, the tiny Patrol
// recipe (tiny_patrol.h) loaded with --set overrides and its run_dir inside the folder,
// and random observations. The suite TransitionTraining spans those files, and GoogleTest
// asks every TEST_F of a suite to use one fixture class: so it is declared here, not in an
// anonymous namespace.
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "core/rng.h"
#include "hrl/composite_recipe.h"
#include "hrl/switch_training.h"
#include "tests/temp_dir.h"
#include "tests/tiny_patrol.h"

namespace segue {

class TransitionTraining : public TempDirTest {
 protected:
  TransitionTraining() : TempDirTest("transition_training") {}
  CompositeRecipe tiny(std::vector<std::string> sets = {}) {
    std::string file = path("tiny_patrol.yaml");
    std::ofstream(file) << kTinyPatrol;
    sets.push_back("run_dir=" + path("run"));
    return CompositeRecipe::load(file, sets);
  }
};

// Switch training on transition t of a recipe, from `starts`, with no other transition
// policy trained (hrl/switch_training.h).
inline SwitchTrainer switch_trainer(const CompositeRecipe& r, int t, StartStates starts, Policy pi_ab, uint64_t seed) {
  const SwitchConfig& c = r.pipeline.switching;
  return SwitchTrainer(c, SwitchInterval(r.make_env, r.skills, r.meta, t, std::move(starts), std::move(pi_ab), {},
                                         c.lookahead, c.max_subtask_steps),
                       seed);
}

inline std::vector<float> random_obs(int n, int d, uint64_t seed) {
  Rng rng(seed);
  std::vector<float> v(size_t(n) * d);
  for (auto& x : v) x = float(2.0 * rng.normal());
  return v;
}

}  // namespace segue
