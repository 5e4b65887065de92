// The command line's words against the program: docs/usage.md lists exactly the flags each
// command's --help prints, and the mistakes people make most often (a recipe given to the
// wrong command, a mistyped task, an output folder that is not there, a finished run started
// again) are answered in one line that says what is wrong.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/run_dir.h"
#include "tests/cli_run.h"
#include "tests/temp_dir.h"

namespace segue {
namespace {

// The flags a help text lists: its lines "  --name ...".
std::set<std::string> help_flags(const std::string& help) {
  std::set<std::string> out;
  std::istringstream lines(help);
  const std::regex flag(R"(^  --([a-z][a-z0-9-]*)\b)");
  std::smatch m;
  for (std::string line; std::getline(lines, line);)
    if (std::regex_search(line, m, flag)) out.insert(m[1]);
  return out;
}

// The commands `segue --help` lists: the lines "  NAME ..." under "commands:".
std::vector<std::string> commands() {
  const CliRun top = run_cli("--help");
  EXPECT_EQ(top.code, 0) << top.output;
  std::vector<std::string> out;
  std::istringstream lines(top.output);
  bool in_list = false;
  const std::regex entry(R"(^  ([a-z]+) )");
  std::smatch m;
  for (std::string line; std::getline(lines, line);) {
    if (line == "commands:") in_list = true;
    else if (line.empty()) in_list = false;
    else if (in_list && std::regex_search(line, m, entry)) out.push_back(m[1]);
  }
  return out;
}

// docs/usage.md's command sections: the text under each heading "### segue NAME", up to
// the next heading (lines in fenced code blocks are not headings).
std::map<std::string, std::string> usage_sections() {
  std::istringstream lines(read_file(std::string(SEGUE_SOURCE_DIR) + "/docs/usage.md"));
  std::map<std::string, std::string> out;
  std::string current;
  bool fenced = false;
  const std::regex heading(R"(^### segue ([a-z]+)\s*$)");
  std::smatch m;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("```", 0) == 0) fenced = !fenced;
    if (!fenced && line.rfind("#", 0) == 0) {
      current.clear();
      if (std::regex_search(line, m, heading)) {
        current = m[1];
        EXPECT_EQ(out.count(current), 0u) << "docs/usage.md has two sections for segue " << current;
        out[current];
      }
      continue;
    }
    if (!current.empty()) out[current] += line + "\n";
  }
  return out;
}

std::set<std::string> flags_named(const std::string& text) {
  std::set<std::string> out;
  const std::regex flag(R"((^|[^A-Za-z0-9_-])--([a-z][a-z0-9-]*))");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), flag); it != std::sregex_iterator(); ++it)
    out.insert((*it)[2]);
  return out;
}

void expect_one_line_error(const CliRun& r, const std::string& line) {
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(r.output, "error: " + line + "\n");
}

std::string policy_file() { return std::string(SEGUE_SOURCE_DIR) + "/assets/policies/walker/walker_forward.pt"; }

}  // namespace

class CliMessages : public TempDirTest {
 protected:
  CliMessages() : TempDirTest("cli_messages") {}
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(path(name)) << text;
    return path(name);
  }
};

TEST_F(CliMessages, UsageListsEveryFlagOfEveryCommand) {
  const std::vector<std::string> names = commands();
  ASSERT_GE(names.size(), 9u) << "segue --help lists too few commands";
  const std::map<std::string, std::string> sections = usage_sections();
  for (const std::string& cmd : names) {
    const CliRun help = run_cli(cmd + " --help");
    ASSERT_EQ(help.code, 0) << cmd << ": " << help.output;
    ASSERT_EQ(help.output.rfind("usage: segue " + cmd, 0), 0u) << help.output;
    const auto section = sections.find(cmd);
    if (section == sections.end()) {
      ADD_FAILURE() << "docs/usage.md has no section '### segue " << cmd << "'";
      continue;
    }
    const std::set<std::string> takes = help_flags(help.output), named = flags_named(section->second);
    EXPECT_TRUE(takes.count("help")) << help.output;
    for (const std::string& flag : takes)
      if (flag != "help")
        EXPECT_TRUE(named.count(flag)) << "docs/usage.md, section 'segue " << cmd << "', omits --" << flag
                                       << " (segue " << cmd << " --help lists it)";
    for (const std::string& flag : named)
      EXPECT_TRUE(takes.count(flag)) << "docs/usage.md, section 'segue " << cmd << "', names --" << flag
                                     << ", which segue " << cmd << " does not take";
  }
  for (const auto& [cmd, text] : sections)
    EXPECT_NE(std::find(names.begin(), names.end(), cmd), names.end())
        << "docs/usage.md documents 'segue " << cmd << "', which segue --help does not list";
}


// 1. A recipe given to the other command says which command it is for.
TEST_F(CliMessages, ARecipeForTheOtherCommandNamesIt) {
  const std::string composite =
      write("composite.yaml", "task: hurdle\nskills: {walk: {policy: assets/policies/walker/walker_forward.pt}}\n");
  expect_one_line_error(run_cli("train " + composite),
                        composite + ": a composite recipe (it has 'skills:'); train it with 'segue run " + composite + "'");
  const std::string transitions = write("transitions.yaml", "task: hurdle\ntransitions: [{from: walk, to: jump}]\n");
  expect_one_line_error(run_cli("train " + transitions), transitions +
                                                             ": a composite recipe (it has 'transitions:'); train it "
                                                             "with 'segue run " + transitions + "'");
  const std::string skill = write("skill.yaml", "task: walker_forward\nppo: {total_steps: 2048}\n");
  expect_one_line_error(run_cli("run " + skill),
                        skill + ": a skill recipe (it has no 'skills:'); train it with 'segue train " + skill + "'");
  // Each still checks with its own command.
  EXPECT_EQ(run_cli("train " + skill + " --check").code, 0);
}

// 2. A mistyped task names the tasks it may have meant.
TEST_F(CliMessages, AnUnknownTaskNamesTheCloseOnes) {
  const CliRun r = run_cli("eval --task hurdel --method tp+q");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(r.output.rfind("error: unknown task 'hurdel'; did you mean 'hurdle'? (tasks: ", 0), 0u) << r.output;
  EXPECT_NE(r.output.find("walker_forward"), std::string::npos) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  // The same without --method, and for report.
  const CliRun policy = run_cli("eval " + policy_file() + " --task walker_froward");
  EXPECT_EQ(policy.code, 1) << policy.output;
  EXPECT_EQ(policy.output.rfind("error: unknown task 'walker_froward'; did you mean 'walker_forward'?", 0), 0u)
      << policy.output;
  const CliRun report = run_cli("report patrl");
  EXPECT_EQ(report.code, 1) << report.output;
  EXPECT_EQ(report.output.rfind("error: unknown task 'patrl'; did you mean 'patrol'?", 0), 0u) << report.output;
  // A known task without a composite recipe: --method is for composite tasks.
  expect_one_line_error(run_cli("eval --task walker_forward --method tp+q"),
                        "segue eval: task 'walker_forward' has no composite recipe (experiments/walker_forward.yaml); "
                        "--method is for composite tasks (or give --recipe FILE)");
}

// 3. An output that cannot be written says why.
TEST_F(CliMessages, ExportSaysWhyItCannotWrite) {
  const std::string missing = path("nodir") + "/x.pt";
  expect_one_line_error(run_cli("export " + policy_file() + " " + missing),
                        missing + ": cannot write: the folder '" + path("nodir") + "' does not exist");
  const std::string file = write("file", "not a folder\n");
  expect_one_line_error(run_cli("export " + policy_file() + " " + file + "/x.pt"),
                        file + "/x.pt: cannot write: '" + file + "' is not a folder");
  if (::geteuid() != 0) {  // root writes anywhere
    std::filesystem::create_directories(path("locked"));
    std::filesystem::permissions(path("locked"), std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    expect_one_line_error(run_cli("export " + policy_file() + " " + path("locked") + "/x.pt"),
                          path("locked") + "/x.pt: cannot write: permission denied");
    std::filesystem::permissions(path("locked"), std::filesystem::perms::owner_all);
  }
  const CliRun ok = run_cli("export " + policy_file() + " " + path("x.pt"));
  EXPECT_EQ(ok.code, 0) << ok.output;
  EXPECT_TRUE(std::filesystem::exists(path("x.pt")));
}

// 4. Rerunning a finished run says it is finished, trains nothing, and evaluates again.
TEST_F(CliMessages, RerunningAFinishedRunSaysSo) {
  const std::string run_dir = path("run");
  const std::string recipe = write(
      "tiny.yaml", "task: walker_forward\nthreads: 1\nrun_dir: " + run_dir +
                       "\nenv: {max_episode_steps: 50}\n"
                       "ppo: {total_steps: 2048, num_envs: 2, steps_per_env: 512, minibatch_size: 512, epochs: 1}\n"
                       "eval: {episodes: 1}\n");
  const CliRun first = run_cli("train " + recipe);
  ASSERT_EQ(first.code, 0) << first.output;
  EXPECT_EQ(first.output.find("is finished"), std::string::npos) << first.output;
  const std::string metrics = read_file(run_dir + "/metrics.csv");
  std::filesystem::remove(run_dir + "/eval.json");

  const CliRun second = run_cli("train " + recipe);
  ASSERT_EQ(second.code, 0) << second.output;
  EXPECT_NE(second.output.find(run_dir + " is finished (2048 steps); re-evaluating its policy"), std::string::npos)
      << second.output;
  EXPECT_EQ(second.output.find("resuming"), std::string::npos) << second.output;
  EXPECT_EQ(read_file(run_dir + "/metrics.csv"), metrics) << "the finished run trained again";
  EXPECT_TRUE(std::filesystem::exists(run_dir + "/eval.json")) << "the finished run was not evaluated again";
}

}  // namespace segue
