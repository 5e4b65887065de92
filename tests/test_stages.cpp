// A curriculum is one recipe: `stages:` run in order by one `segue train`, each stage
// continuing the last, each in its own directory, the rows of all in one metrics.csv.
#include <gtest/gtest.h>

#include <array>
#include <fstream>
#include <sstream>

#include "core/run_dir.h"
#include "tests/temp_dir.h"

namespace segue {
namespace {

int run_segue(const std::string& args) {
  std::string cmd = std::string(SEGUE_BINARY) + " " + args + " > /dev/null 2>&1";
  return WEXITSTATUS(std::system(cmd.c_str()));
}

std::vector<std::vector<std::string>> csv(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> row;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) row.push_back(cell);
    rows.push_back(row);
  }
  return rows;
}

class Stages : public TempDirTest {
 protected:
  Stages() : TempDirTest("stages") {}
  // Two PPO iterations of 1024 steps per stage on a 50-step walk.
  std::string recipe(const std::string& second) {
    const std::string file = path("curriculum.yaml");
    std::ofstream(file) << "task: walker_forward\n"
                           "threads: 1\n"
                           "run_dir: " << path("run") << "\n"
                           "checkpoint_every: 1\n"
                           "env: {max_episode_steps: 50, success_steps: 50}\n"
                           "ppo: {total_steps: 2048, num_envs: 4, steps_per_env: 256, minibatch_size: 256, epochs: 2}\n"
                           "eval: {episodes: 2}\n"
                           "stages:\n"
                           "  - {name: first, ppo: {lr: 1.0e-3}}\n"
                        << "  - {name: second" << second << "}\n";
    return file;
  }
};

}  // namespace

TEST_F(Stages, TwoStagesRunInOrderAndTheSecondContinuesTheFirst) {
  ASSERT_EQ(run_segue("train " + recipe(", env: {target_speed: 1.0}")), 0);
  auto rows = csv(path("run/metrics.csv"));
  ASSERT_EQ(rows.size(), 5u);  // header, two rows per stage
  EXPECT_EQ(rows[0][0], "stage");
  EXPECT_EQ(rows[0][1], "iteration");
  EXPECT_EQ(rows[1][0], "first");
  EXPECT_EQ(rows[3][0], "second");
  // The second stage continues the first's checkpoint: iterations and steps go on.
  EXPECT_EQ(rows[3][1], "3");
  EXPECT_EQ(rows[4][2], "4096");
  const std::string second = read_file(path("run/2-second/recipe.yaml"));
  EXPECT_NE(second.find("init_from: " + path("run/1-first/checkpoint.pt")), std::string::npos) << second;
  EXPECT_NE(second.find("target_speed: 1"), std::string::npos);  // its own key over the file's
  EXPECT_EQ(second.find("lr: 0.001"), std::string::npos);        // the first's lr is the first's
  EXPECT_TRUE(std::filesystem::exists(path("run/policy.pt")));
  EXPECT_TRUE(std::filesystem::exists(path("run/eval.json")));

  // Rerunning skips finished stages; a stage whose directory is gone runs again, and
  // (from the same checkpoint and seed) writes the same rows.
  auto first_rows = csv(path("run/1-first/metrics.csv"));
  auto second_rows = csv(path("run/2-second/metrics.csv"));
  std::filesystem::remove_all(path("run/2-second"));
  ASSERT_EQ(run_segue("train " + recipe(", env: {target_speed: 1.0}")), 0);
  EXPECT_EQ(csv(path("run/1-first/metrics.csv")), first_rows);
  auto again = csv(path("run/2-second/metrics.csv"));
  ASSERT_EQ(again.size(), second_rows.size());
  for (size_t r = 0; r < again.size(); ++r)
    for (size_t c = 0; c + 1 < again[r].size(); ++c)  // all but wall_seconds
      if (again[0][c] != "rollout_seconds" && again[0][c] != "update_seconds")
        EXPECT_EQ(again[r][c], second_rows[r][c]) << "row " << r << " column " << again[0][c];
}

TEST_F(Stages, ContinuingFromThePolicyStartsFreshCounters) {
  ASSERT_EQ(run_segue("train " + recipe(", continue: policy")), 0);
  auto rows = csv(path("run/metrics.csv"));
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[3][1], "1");     // a new run: iteration 1
  EXPECT_EQ(rows[4][2], "2048");  // its own two iterations
  const std::string second = read_file(path("run/2-second/recipe.yaml"));
  EXPECT_NE(second.find("init_policy: " + path("run/1-first/policy.pt")), std::string::npos) << second;
}

}  // namespace segue
