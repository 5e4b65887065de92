#pragma once
// The paper's results table, measured: for each method, `episodes` evaluation episodes
// for each evaluation seed of the recipe; mean +- std of the success count over all of
// them, with per-seed means. Written as TASK.md (the paper's layout) and TASK.json
// (method -> mean, std, per_seed_means, per_seed_stds, episodes, seeds).
#include <string>
#include <utility>
#include <vector>

#include "hrl/composite_recipe.h"

namespace segue {

struct MethodResult {
  std::string method;
  Summary pooled;
  std::vector<double> seed_means, seed_stds;
};

// Controllers for the wanted methods. With skip_missing, a method whose artefacts are
// missing is left out and listed in `skipped` with the reason (source-tree paths made
// relative); otherwise its error propagates.
std::vector<std::pair<std::string, ControllerFactory>> available_methods(
    const CompositeRecipe& recipe, const std::vector<std::string>& wanted, bool skip_missing,
    std::vector<std::pair<std::string, std::string>>& skipped);
// Evaluates each method, printing its row as it finishes.
std::vector<MethodResult> measure_methods(const CompositeRecipe& recipe,
                                          const std::vector<std::pair<std::string, ControllerFactory>>& methods,
                                          int threads);
// Writes DIR/TASK.md and DIR/TASK.json. `unmeasured` rows (method, why) are listed as such;
// `command` is how the table was produced.
void write_results(const CompositeRecipe& recipe, const std::vector<MethodResult>& results,
                   const std::vector<std::pair<std::string, std::string>>& unmeasured, const std::string& command,
                   const std::string& dir);
// "Without TP", "With TP + Q", ... as the paper's rows.
const char* method_row_name(const std::string& method);

}  // namespace segue
