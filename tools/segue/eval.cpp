// segue eval: success and return over seeded episodes, for one policy on a task or for a
// method (single, without-tp, ...) on a composite task.
#include <cstdio>
#include <filesystem>

#include "core/thread_pool.h"
#include "environments/registry.h"
#include "hrl/composite_recipe.h"
#include "core/run_dir.h"
#include "tools/segue/cli.h"

namespace segue::cli {
namespace {

const Command kEval{
    "eval",
    "[POLICY] --task NAME [--method M] [--episodes N] [--seed S] [--json]",
    "Runs deterministic policies for N episodes; episode i starts from a seed derived\n"
    "from (S, i). With POLICY (a checkpoint.pt or an exported .pt) and no --method, runs\n"
    "that policy on the task. With --method, runs a method of the paper on a composite\n"
    "task with the recipe's (by default the shipped) policies: single, without-tp, tp,\n"
    "lee, tp+q. Prints mean +- std of return, success rate and success count.",
    {},
    {{"task", "NAME", "task to run (e.g. walker_forward, hurdle)"},
     {"method", "M", "composite-task method (single, without-tp, tp, lee, tp+q)"},
     {"recipe", "FILE", "composite recipe (default experiments/TASK.yaml)"},
     {"episodes", "N", "number of episodes (default 50)"},
     {"seed", "S", "evaluation seed (default 0)"},
     {"json", "", "print one JSON object instead of text"},
     {"set", "key=value", "override a recipe/task key, e.g. --set env.push_prob=0 (repeatable)", true},
     {"threads", "N", "threads stepping environments (default 0 = all cores)"}},
    1};

}  // namespace

int eval_main(int argc, char** argv) {
  Args args(kEval, argc, argv);
  if (args.help()) return print_help(kEval);
  if (!args.has("task")) throw Error("segue eval: --task NAME is required (see segue eval --help)");
  const std::string task = args.get("task", "");
  require_known_task(task);
  const int episodes = args.get_int("episodes", 50, Range::positive());
  const int seed = args.get_int("seed", 0, Range::non_negative());
  const int threads = resolve_threads(args.get_int("threads", 0, Range::closed(0, kMaxThreads)));
  set_torch_threads(1);
  const std::string method = args.get("method", "");
  std::string label;
  EnvFactory make;
  ControllerFactory controllers;
  CompositeRecipe composite;
  if (!method.empty()) {
    std::vector<std::string> sets = args.all("set");
    if (args.positional_count() == 1) {
      if (method != "single") throw Error("segue eval: a POLICY argument only goes with --method single");
      sets.push_back("methods.single.policy=" + args.positional(0));
    }
    composite = method_recipe("eval", args, task, sets);
    make = composite.make_env;
    controllers = method_controllers(composite, method);
    label = method;
  } else {
    if (args.positional_count() != 1) throw Error("segue eval: give a POLICY, or --method for a composite task");
    const std::string path = args.positional(0);
    Recipe settings = Recipe::parse("{}", "--set", args.all("set"));
    make = task_factory(task, settings.root().sub("env"));
    settings.reject_unknown();
    Policy policy = Policy::load(path);
    policy.check_fits(make()->spec(), path);
    controllers = [policy] { return std::make_unique<PolicyController>(policy); };
    label = path;
  }
  EvalResult r = evaluate(make, controllers, episodes, uint64_t(seed), threads, "eval " + task);

  Summary ret = summarize(r.returns), count = summarize(r.success_counts);
  double success = r.success_rate();
  if (args.has("json")) {
    std::vector<std::pair<std::string, double>> f{
        {"return_mean", ret.mean},          {"return_std", ret.std},
        {"success_rate", success},          {"success_count_mean", count.mean},
        {"success_count_std", count.std},   {"episodes", double(episodes)},
        {"episode_length_mean", summarize(r.lengths).mean}};
    for (size_t k = 0; k < r.metric_names.size(); ++k)
      f.push_back({r.metric_names[k] + "_mean", summarize(r.metric_means[k]).mean});
    std::printf("%s\n", json_object(f).c_str());
  } else {
    std::printf("%s on %s, %d episodes, seed %d\n", label.c_str(), task.c_str(), episodes, seed);
    std::printf("  return          %.2f +- %.2f\n", ret.mean, ret.std);
    std::printf("  success rate    %.2f\n", success);
    std::printf("  success count   %.2f +- %.2f\n", count.mean, count.std);
    std::printf("  episode length  %.1f\n", summarize(r.lengths).mean);
    for (size_t k = 0; k < r.metric_names.size(); ++k)
      std::printf("  %-15s %.3f (per-step mean)\n", r.metric_names[k].c_str(), summarize(r.metric_means[k]).mean);
  }
  return 0;
}

}  // namespace segue::cli
