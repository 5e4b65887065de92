// segue: train, evaluate, export and benchmark skills from YAML recipes.
#include <cstdio>
#include <cstring>
#include <string>

#include <torch/torch.h>

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
    "  export CKPT OUT    write a checkpoint's policy as TorchScript\n"
    "  render POLICY      render one episode of a policy to a video, headless\n"
    "  plot RUN_DIR       draw a run's learning curves (PNG)\n"
    "  keys               print every recipe key with its default (docs/recipes.md)\n"
    "  bench              measure physics, rollout and PPO throughput\n\n"
    "Run 'segue COMMAND --help' for a command's flags.\n";

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
      !std::strcmp(argv[1], "help")) {
    std::fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  std::string cmd = argv[1];
  try {
    if (cmd == "train") return segue::cli::train_main(argc - 2, argv + 2);
    if (cmd == "run") return segue::cli::run_main(argc - 2, argv + 2);
    if (cmd == "eval") return segue::cli::eval_main(argc - 2, argv + 2);
    if (cmd == "export") return segue::cli::export_main(argc - 2, argv + 2);
    if (cmd == "render") return segue::cli::render_main(argc - 2, argv + 2);
    if (cmd == "bench") return segue::cli::bench_main(argc - 2, argv + 2);
    if (cmd == "report") return segue::cli::report_main(argc - 2, argv + 2);
    if (cmd == "plot") return segue::cli::plot_main(argc - 2, argv + 2);
    if (cmd == "keys") return segue::cli::keys_main(argc - 2, argv + 2);
    std::fprintf(stderr, "segue: unknown command '%s'\n\n%s", cmd.c_str(), kUsage);
    return 2;
  } catch (const segue::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
  } catch (const c10::Error& e) {
    std::string what = e.what_without_backtrace();
    std::fprintf(stderr, "error: %s\n", what.substr(0, what.find('\n')).c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
  }
  return 1;
}
