// A curriculum is one recipe: `stages:` run in order by one `segue train`, each stage
// continuing the last, each in its own directory, the rows of all in one metrics.csv.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <sstream>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "core/run_dir.h"
#include "tests/cli_run.h"
#include "tests/csv.h"
#include "tests/temp_dir.h"

namespace segue {
namespace {

int run_segue(const std::string& args) { return run_cli(args).code; }

// Starts `segue train FILE` in the background.
// Every column but the timings.
void expect_same_rows(const std::vector<std::vector<std::string>>& a, const std::vector<std::vector<std::string>>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t r = 0; r < a.size(); ++r) {
    ASSERT_EQ(a[r].size(), b[r].size()) << "row " << r;
    for (size_t c = 0; c < a[r].size(); ++c) {
      const std::string& name = a[0][c];
      if (name == "rollout_seconds" || name == "update_seconds" || name == "wall_seconds" || name == "comm_seconds")
        continue;
      EXPECT_EQ(a[r][c], b[r][c]) << "row " << r << " column " << name;
    }
  }
}

class Stages : public TempDirTest {
 protected:
  Stages() : TempDirTest("stages") {}
  // Two PPO iterations of 1024 steps per stage on a 50-step walk.
  // `head`: top-level keys of the file (e.g. where its first stage starts from).
  std::string recipe(const std::string& second, const std::string& run = "run", const std::string& head = "") {
    const std::string file = path(run + ".yaml");
    std::ofstream(file) << head << "task: walker_forward\n"
                           "threads: 1\n"
                           "run_dir: " << path(run) << "\n"
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
  expect_same_rows(csv(path("run/2-second/metrics.csv")), second_rows);
}

TEST_F(Stages, ARunStoppedInTheSecondStageResumesToTheUnbrokenRunsRows) {
  // Stage two is 12 iterations, checkpointed after each; the run is stopped (SIGTERM)
  // as soon as stage two's first checkpoint exists, then rerun to the end.
  const std::string longer = ", ppo: {total_steps: 12288}";
  ASSERT_EQ(run_segue("train " + recipe(longer, "unbroken")), 0);
  const std::string file = recipe(longer, "stopped");
  pid_t pid = start_train(file);
  int status = 0;
  if (wait_until(pid, [&] { return std::filesystem::exists(path("stopped/2-second/checkpoint.pt")); }, &status)) {
    kill(pid, SIGTERM);
    waitpid(pid, &status, 0);
  }
  const bool stopped_in_stage_two = WIFEXITED(status) && WEXITSTATUS(status) == 128 + SIGTERM;
  EXPECT_TRUE(stopped_in_stage_two) << "status " << status << " (finished before the signal?)";
  if (stopped_in_stage_two) EXPECT_FALSE(std::filesystem::exists(path("stopped/2-second/eval.json")));
  ASSERT_EQ(run_segue("train " + file), 0);
  expect_same_rows(csv(path("stopped/metrics.csv")), csv(path("unbroken/metrics.csv")));
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

TEST_F(Stages, ACurriculumFromAnExportedPolicyContinuesItsOwnCheckpointLater) {
  // The file's init_policy is where the first stage starts; the second continues the
  // first's checkpoint, and no longer also names that policy (which would be refused).
  const std::string head = "init_policy: assets/policies/walker/walker_forward.pt\n";
  ASSERT_EQ(run_segue("train " + recipe("", "run", head)), 0);
  const std::string first = read_file(path("run/1-first/recipe.yaml"));
  EXPECT_NE(first.find("init_policy: assets/policies/walker/walker_forward.pt"), std::string::npos) << first;
  const std::string second = read_file(path("run/2-second/recipe.yaml"));
  EXPECT_NE(second.find("init_from: " + path("run/1-first/checkpoint.pt")), std::string::npos) << second;
  EXPECT_EQ(second.find("walker_forward.pt"), std::string::npos) << second;
  auto rows = csv(path("run/metrics.csv"));
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[3][1], "3");  // the checkpoint's counters go on
}

TEST_F(Stages, AStageMayTrainWithAnotherLearner) {
  // The file's `ppo:` settings are its PPO stages'; a TRPO stage reads its own section only.
  ASSERT_EQ(run_segue("train " + recipe(", continue: policy, learner: trpo, trpo: {total_steps: 2048, num_envs: 4, "
                                        "steps_per_env: 256, vf_minibatch: 256}")),
            0);
  const std::string second = read_file(path("run/2-second/recipe.yaml"));
  EXPECT_NE(second.find("learner: trpo"), std::string::npos) << second;
  EXPECT_EQ(second.find("ppo:"), std::string::npos) << second;
  auto rows = csv(path("run/metrics.csv"));
  ASSERT_EQ(rows.size(), 5u);
  const auto& header = rows[0];
  const size_t step_size = std::find(header.begin(), header.end(), "step_size") - header.begin();
  ASSERT_LT(step_size, header.size()) << "no TRPO column in the stages' metrics";
  // A row's trailing empty cells may be left out.
  auto cell = [&](size_t r) { return step_size < rows[r].size() ? rows[r][step_size] : std::string(); };
  EXPECT_EQ(cell(2), "");  // the PPO stage's rows leave it empty
  EXPECT_NE(cell(4), "");
}

}  // namespace segue
