// Run directories: atomic writes, resume rules, metrics rows cut back to the checkpoint.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "core/error.h"
#include "core/run_dir.h"
#include "tests/temp_dir.h"

namespace segue {

class RunDirTest : public TempDirTest {
 protected:
  RunDirTest() : TempDirTest("rundir") {}
};

TEST_F(RunDirTest, AtomicWriteReplacesAndLeavesNoTemporary) {
  std::string path = this->path("f.txt");
  write_file_atomic(path, "one");
  write_file_atomic(path, "two");
  EXPECT_EQ(read_file(path), "two");
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
}

TEST_F(RunDirTest, ResumesWithAnotherThreadCountButNotAnotherRecipe) {
  const std::string recipe = "task: walker_forward\nthreads: 0\nppo:\n  lr: 0.0003\n";
  std::filesystem::remove_all(dir_);  // RunDir creates it
  RunDir first(dir_.string(), recipe);
  EXPECT_NO_THROW(RunDir(dir_.string(), "task: walker_forward\nthreads: 1\nppo:\n  lr: 0.0003\n"));
  try {
    RunDir(dir_.string(), "task: walker_forward\nthreads: 0\nppo:\n  lr: 0.001\n");
    FAIL() << "a different learning rate was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("different recipe"), std::string::npos);
  }
}

TEST_F(RunDirTest, ResumesWhenTheCodeGainedAKeyTheRecipeLeavesAtItsDefault) {
  // The run started before ppo.min_log_std existed. Resuming with it at its default is
  // the same run, and the stored recipe gains the key; set explicitly, it is refused.
  const std::string old_recipe = "task: walker_jump\nppo:\n  lr: 0.0003\n  hidden: [32, 32]\n";
  const std::string now = "task: walker_jump\nppo:\n  lr: 0.0003\n  hidden: [32, 32]\n  min_log_std: -20\n";
  std::filesystem::remove_all(dir_);
  RunDir first(dir_.string(), old_recipe);
  auto refused = [&](const std::string& resolved, const std::set<std::string>& defaulted) {
    try {
      RunDir(dir_.string(), resolved, defaulted);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(refused(now, {}), path("recipe.yaml") +
            ": this run directory was started with a different recipe (key 'ppo.min_log_std': absent there, -20 now); "
            "choose another run_dir or remove the directory");
  EXPECT_NE(refused("task: walker_jump\nppo:\n  lr: 0.0003\n  hidden: [32, 64]\n", {}).find("key 'ppo.hidden.1': 32 there, 64 now"),
            std::string::npos);
  EXPECT_NE(refused("task: walker_jump\nppo:\n  lr: 0.0003\n", {}).find("key 'ppo.hidden.0': 32 there, absent now"),
            std::string::npos);
  EXPECT_EQ(read_file(path("recipe.yaml")), old_recipe);
  EXPECT_EQ(refused(now, {"ppo.min_log_std", "ppo.lr"}), "");
  EXPECT_EQ(read_file(path("recipe.yaml")), now);
  EXPECT_EQ(refused(now, {}), "");  // the rewritten recipe holds the key now
}

TEST_F(RunDirTest, ResumesWhenTheCodeDroppedASettingTheRunLeftNeutral) {
  // ppo.noise_repeat is no longer a setting; at 1 it changed nothing, so a run that had
  // it at 1 resumes (its stored recipe loses the key), while one at 4 is refused by name.
  const std::string now = "task: walker_jump\nppo:\n  lr: 0.0003\n";
  std::filesystem::remove_all(dir_);
  RunDir(dir_.string(), "task: walker_jump\nppo:\n  lr: 0.0003\n  noise_repeat: 1\nenv:\n  ghost_curbs: false\n");
  EXPECT_NO_THROW(RunDir(dir_.string(), now));
  EXPECT_EQ(read_file(path("recipe.yaml")), now);
  std::filesystem::remove_all(dir_);
  RunDir(dir_.string(), "task: walker_jump\nppo:\n  lr: 0.0003\n  noise_repeat: 4\n");
  try {
    RunDir(dir_.string(), now);
    FAIL() << "a run with noise held for 4 steps was resumed without it";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), path("recipe.yaml") +
                                         ": this run directory was started with key 'ppo.noise_repeat': 4, a setting "
                                         "Segue no longer has (only runs at 1 resume); choose another run_dir or "
                                         "remove the directory");
  }
  // A key Segue never had is a different recipe, as before.
  std::filesystem::remove_all(dir_);
  RunDir(dir_.string(), "task: walker_jump\nppo:\n  lr: 0.0003\n  other: 1\n");
  EXPECT_THROW(RunDir(dir_.string(), now), Error);
}

TEST_F(RunDirTest, MetricsKeepOnlyRowsUpToTheCheckpoint) {
  std::string path = this->path("metrics.csv");
  {
    MetricsCsv csv(path, {"iteration", "x"}, 0);
    for (int i = 1; i <= 5; ++i) csv.write({double(i), 10.0 * i});
  }
  {
    MetricsCsv resumed(path, {"iteration", "x"}, 3);  // the checkpoint was at iteration 3
    resumed.write({4, 41});
  }
  EXPECT_EQ(read_file(path), "iteration,x\n1,10\n2,20\n3,30\n4,41\n");
}

}  // namespace segue
