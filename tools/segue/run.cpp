// segue run RECIPE: the whole method on a composite task (hrl/pipeline.h), stage by stage.
#include <spdlog/spdlog.h>

#include <cstdio>

#include "core/distributed.h"
#include "hrl/pipeline.h"
#include "core/run_dir.h"
#include "core/thread_pool.h"
#include "tools/segue/cli.h"

namespace segue::cli {
namespace {


const Command kRun{
    "run",
    "RECIPE [--set key=value ...] [--publish DIR]",
    "Runs the paper's method on a composite task from its recipe: for every transition,\n"
    "collects S_a and T_b, trains the transition policy (AIRL) and the switch Q-network\n"
    "(double DQN), then evaluates every method and writes the results table into the run\n"
    "directory (recipe key run_dir, default runs/TASK). A stage whose outputs exist is\n"
    "skipped: rerunning the same command after an interruption resumes it.",
    {"RECIPE"},
    {{"set", "key=value", "override a recipe key (repeatable), e.g. --set switch.attempts=500", true},
     {"threads", "N", "threads stepping environments (overrides the recipe; 0 = all cores)"},
     {"publish", "DIR", "also write TASK.md and TASK.json to DIR (e.g. experiments/results)"},
     {"nproc", "N", "N local ranks: data-parallel pi_ab and Lee, split collection (docs/distributed.md)"},
     {"check", "", "read and check the recipe, then stop"}}};

}  // namespace

int run_main(int argc, char** argv) {
  Args args(kRun, argc, argv);
  if (args.help()) return print_help(kRun);
  auto sets = args.all("set");
  if (args.has("threads")) sets.push_back("threads=" + args.get("threads", "0"));
  {
    const Recipe probe = Recipe::load(args.positional(0), sets);
    if (!probe.root().has("skills") && !probe.root().has("transitions"))
      throw Error(args.positional(0) + ": a skill recipe (it has no 'skills:'); train it with 'segue train " +
                  args.positional(0) + "'");
  }
  CompositeRecipe recipe = CompositeRecipe::load(args.positional(0), sets);
  if (args.has("check")) return std::printf("%s: ok\n", args.positional(0).c_str()) < 0;
  require_same_recipe(recipe.resolved, args.positional(0));
  set_torch_threads(1);  // as in training: results do not depend on the thread count
  PipelineOptions o;
  o.group = &Distributed::world();
  o.threads = resolve_threads(recipe.pipeline.threads);
  o.stop = &install_stop_signals();
  o.publish_dir = args.get("publish", "");
  o.command = "segue run " + args.positional(0);
  int stop = run_pipeline(recipe, o);
  return stop ? 128 + stop : 0;
}

}  // namespace segue::cli
