// segue eval POLICY --task NAME: success and return of a policy over seeded episodes.
#include <cstdio>

#include "algorithms/evaluate.h"
#include "core/thread_pool.h"
#include "environments/registry.h"
#include "tools/segue/cli.h"

namespace segue::cli {
namespace {

const Command kEval{
    "eval",
    "POLICY --task NAME [--episodes N] [--seed S] [--json]",
    "Runs the deterministic policy (a checkpoint.pt or an exported .pt) for N episodes;\n"
    "episode i starts from a seed derived from (S, i). Prints mean +- std of return,\n"
    "success rate and success count.",
    {"POLICY"},
    {{"task", "NAME", "task to run (e.g. walker_forward)"},
     {"episodes", "N", "number of episodes (default 50)"},
     {"seed", "S", "evaluation seed (default 0)"},
     {"json", "", "print one JSON object instead of text"},
     {"set", "key=value", "override a task setting, e.g. --set env.push_prob=0 (repeatable)", true},
     {"threads", "N", "threads stepping environments (default 0 = all cores)"}}};

}  // namespace

int eval_main(int argc, char** argv) {
  Args args(kEval, argc, argv);
  if (args.help()) {
    std::fputs(help_text(kEval).c_str(), stdout);
    return 0;
  }
  if (!args.has("task")) throw Error("segue eval: --task NAME is required (see segue eval --help)");
  const std::string path = args.positional(0), task = args.get("task", "");
  const int episodes = args.get_int("episodes", 50);
  if (episodes <= 0) throw Error("segue eval: --episodes must be positive");
  const int seed = args.get_int("seed", 0);
  Recipe settings = Recipe::parse("{}", "--set", args.all("set"));
  auto make = task_factory(task, settings.root().sub("env"));
  settings.reject_unknown();
  Policy policy = Policy::load(path);
  policy.check_fits(make()->spec(), path);
  set_torch_threads(1);
  EvalResult r = evaluate_policy(policy, make, episodes, uint64_t(seed), resolve_threads(args.get_int("threads", 0)));

  Summary ret = summarize(r.returns), count = summarize(r.success_counts);
  double success = summarize(std::vector<double>(r.successes.begin(), r.successes.end())).mean;
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
    std::printf("%s on %s, %d episodes, seed %d\n", path.c_str(), task.c_str(), episodes, seed);
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
