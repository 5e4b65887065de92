#include "tools/segue/cli.h"

#include <csignal>

#include <torch/torch.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/distributed.h"
#include "core/run_dir.h"
#include "core/thread_pool.h"
#include "environments/registry.h"

namespace segue::cli {

Args::Args(const Command& cmd, int argc, char** argv) : cmd_(cmd) {
  for (int i = 0; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      help_ = true;
      return;
    }
    if (a.rfind("--", 0) == 0) {
      std::string name = a.substr(2), value;
      bool inline_value = false;
      if (auto eq = name.find('='); eq != std::string::npos) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
        inline_value = true;
      }
      const Flag* flag = nullptr;
      for (const auto& f : cmd.flags)
        if (f.name == name) flag = &f;
      if (!flag) throw Error("segue " + cmd.name + ": unknown flag --" + name + " (see segue " + cmd.name + " --help)");
      if (!flag->value.empty() && !inline_value) {
        if (i + 1 >= argc) throw Error("segue " + cmd.name + ": --" + name + " needs a value " + flag->value);
        value = argv[++i];
      }
      if (!flag->repeatable && values_.count(name))
        throw Error("segue " + cmd.name + ": --" + name + " given twice");
      values_.emplace(name, value);
    } else {
      positionals_.push_back(a);
    }
  }
  if (positionals_.size() < cmd.positionals.size() ||
      positionals_.size() > cmd.positionals.size() + cmd.optional_positionals)
    throw Error("segue " + cmd.name + ": expected " + cmd.usage + " (see segue " + cmd.name + " --help)");
}

std::string Args::get(const std::string& flag, const std::string& fallback) const {
  auto it = values_.find(flag);
  return it == values_.end() ? fallback : it->second;
}

int Args::get_int(const std::string& flag, int fallback, const Range& range) const {
  auto it = values_.find(flag);
  if (it == values_.end()) return fallback;
  int v = 0;
  try {
    size_t used;
    v = std::stoi(it->second, &used);
    if (used != it->second.size()) throw Error("");
  } catch (const std::exception&) {
    throw Error("segue " + cmd_.name + ": --" + flag + " expects an integer, got '" + it->second + "'");
  }
  if (!range.contains(v))
    throw Error("segue " + cmd_.name + ": --" + flag + " must be " + range.text() + ", got " + it->second);
  return v;
}

std::vector<std::string> Args::all(const std::string& flag) const {
  std::vector<std::string> out;
  auto range = values_.equal_range(flag);
  for (auto it = range.first; it != range.second; ++it) out.push_back(it->second);
  return out;
}

std::string help_text(const Command& cmd) {
  std::ostringstream o;
  o << "usage: segue " << cmd.name << (cmd.usage.empty() ? "" : " " + cmd.usage) << "\n\n" << cmd.summary << "\n";
  o << "\nflags:\n";
  for (const auto& f : cmd.flags) {
    std::string left = "--" + f.name + (f.value.empty() ? "" : " " + f.value);
    o << "  " << left << std::string(left.size() < 22 ? 22 - left.size() : 1, ' ') << f.help << "\n";
  }
  o << "  --help                show this help\n";
  return o.str();
}

int print_help(const Command& cmd) {
  std::fputs(help_text(cmd).c_str(), stdout);
  return 0;
}

namespace {
std::atomic<int> g_stop{0};
extern "C" void segue_on_stop_signal(int sig) {
  g_stop = sig;
  std::signal(sig, SIG_DFL);  // a second signal stops at once
}
}  // namespace

const std::atomic<int>& install_stop_signals() {
  std::signal(SIGINT, segue_on_stop_signal);
  std::signal(SIGTERM, segue_on_stop_signal);
  return g_stop;
}

void uninstall_stop_signals() {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

std::vector<std::string> close_names(const std::string& name, const std::vector<std::string>& known) {
  // The nearest by edit distance, if near enough; else the names holding it (or held by it).
  std::vector<std::string> out;
  const size_t limit = std::max<size_t>(2, name.size() / 4);
  size_t best = limit + 1;
  for (const auto& k : known) {
    const size_t d = edit_distance(name, k);
    if (d > limit) continue;
    if (d < best) best = d, out.clear();
    if (d == best) out.push_back(k);
  }
  if (out.empty() && name.size() >= 3)
    for (const auto& k : known)
      if (k.find(name) != std::string::npos || name.find(k) != std::string::npos) out.push_back(k);
  if (out.size() > 3) out.resize(3);
  return out;
}

void require_known_task(const std::string& task) {
  const std::vector<std::string> known = task_names();
  if (std::find(known.begin(), known.end(), task) != known.end()) return;
  std::string hint, all;
  const std::vector<std::string> near = close_names(task, known);
  for (size_t i = 0; i < near.size(); ++i)
    hint += (i == 0 ? "; did you mean '" : i + 1 == near.size() ? " or '" : ", '") + near[i] + "'";
  if (!hint.empty()) hint += "?";
  for (const auto& n : known) all += (all.empty() ? "" : ", ") + n;
  throw Error("unknown task '" + task + "'" + hint + " (tasks: " + all + ")");
}

CompositeRecipe method_recipe(const std::string& command, const Args& args, const std::string& task,
                              const std::vector<std::string>& sets) {
  const std::string file = args.get("recipe", CompositeRecipe::default_file(task));
  if (!args.has("recipe") && !std::filesystem::exists(file))
    throw Error("segue " + command + ": task '" + task + "' has no composite recipe (experiments/" + task +
                ".yaml); --method is for composite tasks (or give --recipe FILE)");
  CompositeRecipe r = CompositeRecipe::load(file, sets);
  if (r.task != task) throw Error(r.file + ": key 'task' is '" + r.task + "', not '" + task + "'");
  return r;
}

}  // namespace segue::cli
