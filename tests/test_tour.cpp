// The README's five-minute tour, as a newcomer types it, with small budgets: every command
// succeeds, what it writes lands under runs/tour/ of the folder it runs in, and the source
// tree is left as it was (the tour must not rewrite a tracked file).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "core/run_dir.h"
#include "tests/cli_run.h"
#include "tests/temp_dir.h"

namespace segue {
namespace {

namespace fs = std::filesystem;

struct ShellRun {
  int code;
  std::string output;
};

ShellRun shell(const std::string& command) {
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  std::string out;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int status = pclose(p);
  return {WEXITSTATUS(status), out};
}

// The tour's command lines: the ```sh block after "## A five-minute tour".
std::vector<std::string> tour_commands() {
  const std::string readme = read_file(std::string(SEGUE_SOURCE_DIR) + "/README.md");
  const size_t tour = readme.find("## A five-minute tour");
  const size_t begin = readme.find("```sh\n", tour), end = readme.find("```", begin + 6);
  std::vector<std::string> out;
  if (tour == std::string::npos || begin == std::string::npos || end == std::string::npos) return out;
  std::istringstream lines(readme.substr(begin + 6, end - begin - 6));
  for (std::string line; std::getline(lines, line);)
    if (!line.empty()) out.push_back(line);
  return out;
}

// The same command with budgets a test can afford: fewer episodes and steps.
std::string small(std::string c) {
  c = std::regex_replace(c, std::regex("--episodes [0-9]+"), "--episodes 2");
  c = std::regex_replace(c, std::regex("--steps [0-9]+"), "--steps 30");
  c = std::regex_replace(c, std::regex("ppo\\.total_steps=[0-9]+"), "ppo.total_steps=4096 --set eval.episodes=2");
  if (c.find("segue report") != std::string::npos) c += " --set eval.episodes=2 --set 'eval.seeds=[0]'";
  return c;
}

class Tour : public TempDirTest {
 protected:
  Tour() : TempDirTest("tour") {}
};

TEST_F(Tour, EveryReadmeTourCommandRunsAndWritesOnlyUnderRunsTour) {
  const std::vector<std::string> commands = tour_commands();
  ASSERT_GE(commands.size(), 6u) << "README.md: no tour block found";
  // The folder a newcomer works in: the checkout's inputs, and this build as build/.
  for (const char* input : {"assets", "experiments", "tools"})
    fs::create_directory_symlink(fs::path(SEGUE_SOURCE_DIR) / input, dir_ / input);
  fs::create_directory_symlink(fs::path(SEGUE_BINARY).parent_path(), dir_ / "build");
  const std::string status = "git -C " + std::string(SEGUE_SOURCE_DIR) + " status --porcelain --untracked-files=no";
  const ShellRun before = shell(status);
  for (const std::string& c : commands) {
    SCOPED_TRACE(c);
    const ShellRun r = shell("cd " + dir_.string() + " && " + small(c));
    EXPECT_EQ(r.code, 0) << r.output.substr(r.output.size() > 3000 ? r.output.size() - 3000 : 0);
  }
  // Nothing beside the inputs but runs/tour/, which holds what the tour says it writes.
  for (const auto& entry : fs::directory_iterator(dir_)) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(name == "runs" || name == "assets" || name == "experiments" || name == "tools" || name == "build")
        << "the tour wrote " << name << " outside runs/";
  }
  for (const auto& entry : fs::directory_iterator(dir_ / "runs"))
    EXPECT_EQ(entry.path().filename(), "tour") << "the tour wrote " << entry.path() << " outside runs/tour/";
  for (const char* file : {"results/hurdle.md", "results/hurdle.json", "hurdle.mp4", "hurdle_control.csv",
                           "checkpoint.pt", "metrics.csv", "curves.png", "tour.pt"})
    EXPECT_TRUE(fs::exists(dir_ / "runs" / "tour" / file) ||
                (std::string(file) == "hurdle.mp4" && fs::exists(dir_ / "runs" / "tour" / "hurdle_frames")))
        << "runs/tour/" << file;
  EXPECT_EQ(shell(status).output, before.output) << "the tour changed the source tree";
}

}  // namespace
}  // namespace segue
