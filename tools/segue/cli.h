#pragma once
// Command-line plumbing shared by the segue commands: flag parsing with per-command
// help, and the one-line error convention.
#include <atomic>
#include <map>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/recipe.h"
#include "core/thread_pool.h"
#include "hrl/composite_recipe.h"

namespace segue::cli {

struct Flag {
  std::string name;   // without dashes
  std::string value;  // placeholder shown in help; empty for a boolean switch
  std::string help;
  bool repeatable = false;
};

struct Command {
  std::string name, usage, summary;
  std::vector<std::string> positionals;  // names, all required
  std::vector<Flag> flags;
  size_t optional_positionals = 0;       // how many more positionals may follow
};

class Args {
 public:
  // Throws segue::Error on an unknown flag or a missing value/positional.
  Args(const Command& cmd, int argc, char** argv);
  bool help() const { return help_; }
  const std::string& positional(size_t i) const { return positionals_.at(i); }
  size_t positional_count() const { return positionals_.size(); }
  bool has(const std::string& flag) const { return values_.count(flag) > 0; }
  std::string get(const std::string& flag, const std::string& fallback) const;
  // An integer flag, refused unless in `range`.
  int get_int(const std::string& flag, int fallback, const Range& range) const;
  std::vector<std::string> all(const std::string& flag) const;

 private:
  const Command& cmd_;
  bool help_ = false;
  std::vector<std::string> positionals_;
  std::multimap<std::string, std::string> values_;
};

std::string help_text(const Command& cmd);
// Prints the command's help to stdout; returns exit code 0.
int print_help(const Command& cmd);

// Commands: each returns the process exit code.
int train_main(int argc, char** argv);
int run_main(int argc, char** argv);
int eval_main(int argc, char** argv);
int export_main(int argc, char** argv);
int bench_main(int argc, char** argv);
int report_main(int argc, char** argv);
int diagnose_main(int argc, char** argv);
int render_main(int argc, char** argv);
int plot_main(int argc, char** argv);
int keys_main(int argc, char** argv);
// Runs tools/plot.py (matplotlib) with `args`; its exit status (127: no python3).
int run_plot_tool(const std::string& args);

// Ctrl-C and SIGTERM set the returned flag (the signal number), which a long command polls
// to checkpoint and stop; a second signal stops at once. uninstall_stop_signals() restores
// the default handlers.
const std::atomic<int>& install_stop_signals();
void uninstall_stop_signals();

// The names in `known` a typo of `name` may have meant, at most three: those nearest by
// edit distance where that is small, else those that contain it ("walker").
std::vector<std::string> close_names(const std::string& name, const std::vector<std::string>& known);
// Refuses a task name the registry does not know, in one line: "unknown task 'hurdel';
// did you mean 'hurdle'? (tasks: ...)".
void require_known_task(const std::string& task);

// The composite recipe a command's --method runs on `task`: --recipe FILE, else the shipped
// experiments/TASK.yaml, with `sets` laid over it. Refused in one line (naming `command`)
// where the task has no such recipe or the file is another task's.
CompositeRecipe method_recipe(const std::string& command, const Args& args, const std::string& task,
                              const std::vector<std::string>& sets);

}  // namespace segue::cli
