// segue report TASK: the paper's table row by row, measured. For each method, 50 episodes
// (recipe eval.episodes) for each evaluation seed; mean +- std of the success count over
// all of them, with per-seed means. Writes experiments/results/TASK.md and TASK.json.
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/run_dir.h"
#include "core/thread_pool.h"
#include "hrl/composite_recipe.h"
#include "hrl/results_table.h"
#include "tools/segue/cli.h"

namespace segue::cli {
namespace {

const Command kReport{
    "report",
    "TASK [--methods a,b] [--recipe FILE] [--set key=value ...] [--out DIR]",
    "Evaluates methods of the paper on a composite task over the recipe's evaluation seeds\n"
    "and episodes, and writes DIR/TASK.md (a table in the paper's layout) and DIR/TASK.json\n"
    "(method -> mean, std, per_seed_means, per_seed_stds, episodes, seeds), and DIR/TASK.png,\n"
    "a bar chart of the methods beside the paper's.",
    {"TASK"},
    {{"methods", "a,b", "methods to run (default: every method whose artefacts exist)"},
     {"recipe", "FILE", "composite recipe (default experiments/TASK.yaml)"},
     {"set", "key=value", "override a recipe key, e.g. --set eval.handover_point=random (repeatable)", true},
     {"out", "DIR", "output folder (default experiments/results in the source tree)"},
     {"threads", "N", "threads stepping environments (default 0 = all cores)"}}};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string p; std::getline(ss, p, ',');)
    if (!p.empty()) out.push_back(p);
  return out;
}

}  // namespace

int report_main(int argc, char** argv) {
  Args args(kReport, argc, argv);
  if (args.help()) return print_help(kReport);
  const std::string task = args.positional(0);
  if (!args.has("recipe")) require_known_task(task);  // with --recipe, TASK only names the files
  CompositeRecipe r = CompositeRecipe::load(args.get("recipe", CompositeRecipe::default_file(task)), args.all("set"));
  const int threads = resolve_threads(args.get_int("threads", 0, Range::closed(0, kMaxThreads)));
  set_torch_threads(1);
  std::vector<std::string> wanted = args.has("methods") ? split(args.get("methods", "")) : method_names();
  std::vector<std::pair<std::string, std::string>> skipped;  // method, why
  auto methods = available_methods(r, wanted, /*skip_missing=*/!args.has("methods"), skipped);
  std::vector<MethodResult> results = measure_methods(r, methods, threads);
  std::string out = args.get("out", std::string(SEGUE_SOURCE_DIR) + "/experiments/results");
  std::string command = "segue report " + task;  // as the table records it
  for (const std::string& set : args.all("set")) command += " --set " + set;
  write_results(r, results, skipped, command, out);
  std::printf("wrote %s/%s.md and .json\n", out.c_str(), task.c_str());
  // The bar chart beside the paper's; a missing matplotlib costs the picture, not the table.
  if (run_plot_tool("methods '" + out + "/" + task + ".json'") != 0)
    std::fprintf(stderr, "segue report: no chart drawn (tools/plot.py needs python3-matplotlib)\n");
  return 0;
}

}  // namespace segue::cli
