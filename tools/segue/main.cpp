// segue: train, evaluate, export and benchmark skills from YAML recipes.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include <torch/torch.h>

#include "core/distributed.h"
#include "core/error.h"
#include "tools/segue/cli.h"

namespace {

const char* kUsage =
    "usage: segue COMMAND [ARGS]\n\n"
    "Segue composes pretrained skills with transition policies (Byun & Perrault, ICLR 2022).\n\n"
    "commands:\n"
    "  train RECIPE       train a skill with PPO from a YAML recipe (resumes an interrupted run)\n"
    "  run RECIPE         the whole method on a composite task: collect, transition policies,\n"
    "                     switch Q-networks, evaluation (resumes an interrupted run)\n"
    "  eval [POLICY]      evaluate a policy on a task, or a method on a composite task\n"
    "  report TASK        evaluate methods over seeds; write experiments/results/TASK.{md,json}\n"
    "  diagnose TASK      where a method loses its episodes: hand-over rates, episode ends\n"
    "  export CKPT OUT    write a checkpoint's policy as TorchScript\n"
    "  render POLICY      render one episode of a policy to a video, headless\n"
    "  plot RUN_DIR       draw a run's learning curves (PNG)\n"
    "  keys               print every recipe key with its type, range and default (docs/recipes.md)\n"
    "  bench              measure physics, rollout and PPO throughput\n\n"
    "Run 'segue COMMAND --help' for a command's flags.\n";

}  // namespace

namespace {

int dispatch(const std::string& cmd, int argc, char** argv) {
  if (cmd == "train") return segue::cli::train_main(argc, argv);
  if (cmd == "run") return segue::cli::run_main(argc, argv);
  if (cmd == "eval") return segue::cli::eval_main(argc, argv);
  if (cmd == "export") return segue::cli::export_main(argc, argv);
  if (cmd == "render") return segue::cli::render_main(argc, argv);
  if (cmd == "bench") return segue::cli::bench_main(argc, argv);
  if (cmd == "report") return segue::cli::report_main(argc, argv);
  if (cmd == "diagnose") return segue::cli::diagnose_main(argc, argv);
  if (cmd == "plot") return segue::cli::plot_main(argc, argv);
  if (cmd == "keys") return segue::cli::keys_main(argc, argv);
  throw segue::Error("unknown command '" + cmd +
                     "' (commands: train, run, eval, report, diagnose, export, render, plot, keys, bench; see segue --help)");
}

// Takes `--nproc N` out of the command line; 0 if absent.
int take_nproc(std::vector<std::string>& args) {
  int nproc = 0;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] != "--nproc") continue;
    if (i + 1 >= args.size()) throw segue::Error("flag --nproc needs a value (the number of ranks)");
    char* end = nullptr;
    const long n = std::strtol(args[i + 1].c_str(), &end, 10);
    if (*end || n < 1 || n > 256)
      throw segue::Error("--nproc must be an integer in [1, 256], got '" + args[i + 1] + "'");
    nproc = int(n);
    args.erase(args.begin() + long(i), args.begin() + long(i) + 2);
    --i;
  }
  return nproc;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
      !std::strcmp(argv[1], "help")) {
    std::fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  const std::string cmd = argv[1];
  std::string who;  // "rank R: " before an error, when there are several ranks
  try {
    // `segue train|run ... --nproc N` starts N local ranks of itself; a rank finds RANK and
    // WORLD_SIZE in its environment (torchrun's conventions) and joins the others.
    std::vector<std::string> args(argv, argv + argc);
    const int nproc = take_nproc(args);
    const bool parallel = cmd == "train" || cmd == "run";
    if (nproc > 0 && !parallel)
      throw segue::Error("--nproc is for 'segue train' and 'segue run'; 'segue " + cmd + "' runs on one process");
    if (nproc > 1) return segue::launch_local_ranks(nproc, args);
    if (parallel) {
      segue::Distributed::init_from_environment();
      const auto& world = segue::Distributed::world();
      if (!world.single()) {
        who = "rank " + std::to_string(world.rank()) + ": ";
        if (!world.leader()) spdlog::set_level(spdlog::level::warn);  // rank 0 speaks for all
      }
    }
    std::vector<char*> rest;
    for (auto& a : args) rest.push_back(a.data());
    return dispatch(cmd, int(rest.size()) - 2, rest.data() + 2);
  } catch (const segue::Error& e) {
    std::fprintf(stderr, "error: %s%s\n", who.c_str(), e.what());
  } catch (const c10::Error& e) {
    std::string what = e.what_without_backtrace();
    std::fprintf(stderr, "error: %s%s\n", who.c_str(), what.substr(0, what.find('\n')).c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s%s\n", who.c_str(), e.what());
  }
  return 1;
}
