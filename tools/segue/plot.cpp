// segue plot RUN_DIR: a run's learning curves as PNG, drawn by tools/plot.py (matplotlib;
// Python draws pictures only, never trains).
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "core/error.h"
#include "tools/segue/cli.h"

namespace segue::cli {
namespace {

const Command kPlot{
    "plot",
    "RUN_DIR [--out FILE.png]",
    "Draws a run's learning curves: for a skill run the episode return, success rate and\n"
    "policy entropy against environment steps (one colour per stage of a curriculum); for a\n"
    "composite run each transition policy's AIRL training (interval completed, D's loss and\n"
    "accuracies). Uses Debian's python3-matplotlib through tools/plot.py.",
    {"RUN_DIR"},
    {{"out", "FILE.png", "picture to write (default RUN_DIR/curves.png)"}}};

std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace

int run_plot_tool(const std::string& args) {
  const std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string cmd = python + " " + quoted(std::string(SEGUE_SOURCE_DIR) + "/tools/plot.py") + " " + args;
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}

int plot_main(int argc, char** argv) {
  Args args(kPlot, argc, argv);
  if (args.help()) return print_help(kPlot);
  const std::string dir = args.positional(0);
  if (!std::filesystem::is_directory(dir)) throw Error(dir + ": no such run directory");
  std::string extra = args.has("out") ? " --out " + quoted(args.get("out", "")) : "";
  return run_plot_tool("curves " + quoted(dir) + extra) == 0 ? 0 : 1;
}

}  // namespace segue::cli
