// segue diagnose TASK: where a composite task's method loses its episodes (hrl/diagnosis.h).
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "core/run_dir.h"
#include "hrl/diagnosis.h"
#include "tools/segue/cli.h"

namespace segue::cli {
namespace {

const Command kDiagnose{
    "diagnose",
    "TASK [--method M] [--starts N] [--episodes N] [--json] [--plot FILE.png]",
    "Explains a composite task's results. Per transition, from N states of S_a collected\n"
    "With TP (as segue run collects them), the share of hand-overs after which pi_b achieves its subtask: at the\n"
    "interval's start (Without TP), at its end (With TP), where q_ab switches (With TP + Q),\n"
    "at the best fixed point of several along pi_ab's path (a switch blind to the state) and\n"
    "per state at the best of them, in hindsight. Each skill alone from its own start: N episodes of its own task\n"
    "(skills.NAME.task, by default its policy file's name), push-free. Then the method's evaluation episodes (the recipe's eval seeds, as segue report\n"
    "runs them), grouped by who was in control when each ended, at which success count, and\n"
    "how (success, terminated, time limit). Uses the recipe's (by default the shipped) artefacts.",
    {"TASK"},
    {{"method", "M", "method whose episodes are grouped (default tp+q)"},
     {"recipe", "FILE", "composite recipe (default experiments/TASK.yaml)"},
     {"starts", "N", "S_a states per transition, and episodes of each skill alone (default 100)"},
     {"points", "N", "hand-over points spread along pi_ab's path, >= 2 (default 10)"},
     {"episodes", "N", "evaluation episodes per seed (default: the recipe's eval.episodes)"},
     {"seed", "S", "seed of S_a's collection (default 0)"},
     {"json", "", "print one JSON object instead of the tables"},
     {"plot", "FILE.png", "also draw the hand-over rates and episode ends (FILE.json beside it)"},
     {"set", "key=value", "override a recipe key, e.g. --set env.max_episode_steps=500 (repeatable)", true},
     {"threads", "N", "threads stepping environments (default 0 = all cores)"}}};

}  // namespace

int diagnose_main(int argc, char** argv) {
  Args args(kDiagnose, argc, argv);
  if (args.help()) return print_help(kDiagnose);
  const std::string task = args.positional(0);
  require_known_task(task);
  const CompositeRecipe recipe = method_recipe("diagnose", args, task, args.all("set"));
  const std::string method = args.get("method", "tp+q");
  const auto& names = method_names();
  if (std::find(names.begin(), names.end(), method) == names.end())
    throw Error("segue diagnose: unknown --method '" + method + "' (methods: single, without-tp, tp, lee, tp+q)");
  const int starts = args.get_int("starts", 100, Range::positive());
  const int points = args.get_int("points", 10, Range::closed(2, 1000));
  const int episodes = args.get_int("episodes", recipe.eval_episodes, Range::positive());
  const int seed = args.get_int("seed", 0, Range::non_negative());
  const int threads = resolve_threads(args.get_int("threads", 0, Range::closed(0, kMaxThreads)));
  set_torch_threads(1);
  const Diagnosis d = diagnose(recipe, method, starts, points, episodes, uint64_t(seed), threads);
  const std::string json = diagnosis_json(d) + "\n";
  std::printf("%s", args.has("json") ? json.c_str() : diagnosis_text(d).c_str());
  if (!args.has("plot")) return 0;
  const std::filesystem::path png = args.get("plot", "");
  std::filesystem::path data = png;
  data.replace_extension(".json");
  write_file_atomic(data.string(), json);
  return run_plot_tool("diagnose '" + data.string() + "' --out '" + png.string() + "'") == 0 ? 0 : 1;
}

}  // namespace segue::cli
