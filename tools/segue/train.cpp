// segue train RECIPE: the command line of skill training (hrl/skill_training.h). Ctrl-C or
// SIGTERM checkpoints and stops; a second one stops at once.
#include <atomic>
#include <cstdio>
#include <filesystem>

#include "core/recipe.h"
#include "hrl/skill_training.h"
#include "tools/segue/cli.h"

namespace segue::cli {
namespace {

const Command kTrain{
    "train",
    "RECIPE [--set key=value ...]",
    "Trains a skill with the recipe's learner (PPO, TRPO or SAC). Writes the run directory\n"
    "(recipe.yaml, metrics.csv, checkpoint.pt, policy.pt, eval.json). Rerunning the same\n"
    "command after an interruption resumes from the last checkpoint; a finished run is\n"
    "only re-evaluated. A composite recipe (with skills:) is for 'segue run'.",
    {"RECIPE"},
    {{"set", "key=value", "override a recipe key (repeatable), e.g. --set ppo.lr=1e-4", true},
     {"threads", "N", "threads for environments and LibTorch (overrides the recipe; 0 = all)"},
     {"nproc", "N", "data-parallel PPO or TRPO on N local ranks (c10d Gloo; see docs/distributed.md)"},
     {"check", "", "read and check the recipe (every stage), then stop"}}};

}  // namespace

int train_main(int argc, char** argv) {
  Args args(kTrain, argc, argv);
  if (args.help()) return print_help(kTrain);
  const std::string recipe_path = args.positional(0);
  auto sets = args.all("set");
  if (args.has("threads")) sets.push_back("threads=" + args.get("threads", "0"));
  Recipe recipe = Recipe::load(recipe_path, sets);
  for (const char* composite_key : {"skills", "transitions"})
    if (recipe.root().has(composite_key))
      throw Error(recipe_path + ": a composite recipe (it has '" + composite_key + ":'); train it with 'segue run " +
                  recipe_path + "'");
  const std::string default_run_dir = "runs/" + std::filesystem::path(recipe_path).stem().string();
  if (args.has("check")) {
    const size_t stages = check_skill_recipe(recipe, default_run_dir);
    if (stages == 0) return std::printf("%s: ok\n", recipe_path.c_str()) < 0;
    return std::printf("%s: ok (%zu stages)\n", recipe_path.c_str(), stages) < 0;
  }
  const std::atomic<int>& stop = install_stop_signals();
  const int rc = train_skill_recipe(recipe, default_run_dir, &stop);
  uninstall_stop_signals();
  return rc;
}

}  // namespace segue::cli
