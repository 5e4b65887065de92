// kill -9 at moments defined by the run's own progress: a tiny PPO run killed twenty times
// (before its first checkpoint, between a metrics row and its checkpoint, while a
// checkpoint is being written, in the rollout after one) and rerun each time ends with the
// unbroken run's policy.pt, byte for byte, and its rows. Every kill waits on the run
// directory, never on the clock, so all twenty land on a machine of any speed.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/rng.h"
#include "core/run_dir.h"
#include "tests/cli_run.h"
#include "tests/temp_dir.h"

namespace segue {
namespace {

class KillSoak : public TempDirTest {
 protected:
  KillSoak() : TempDirTest("kill_soak") {}
  std::string recipe(const std::string& name) {
    const std::string file = path(name + ".yaml");
    std::ofstream(file) << "task: walker_forward\n"
                           "threads: 1\n"
                           "run_dir: " << path(name) << "\n"
                           "checkpoint_every: 1\n"
                           "env: {max_episode_steps: 50, success_steps: 50}\n"
                           "ppo: {total_steps: 46080, num_envs: 4, steps_per_env: 128, minibatch_size: 256, epochs: 2}\n"
                           "eval: {episodes: 2}\n";
    return file;
  }
};

// Every metrics row without its timing columns.
std::vector<std::string> rows(const std::string& file) {
  std::ifstream in(file);
  std::vector<std::string> header, out;
  std::string line;
  std::getline(in, line);
  std::stringstream hs(line);
  for (std::string c; std::getline(hs, c, ',');) header.push_back(c);
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::string kept;
    size_t k = 0;
    for (std::string c; std::getline(ls, c, ','); ++k)
      if (k < header.size() && header[k].find("seconds") == std::string::npos) kept += c + ",";
    out.push_back(kept);
  }
  return out;
}

size_t row_count(const std::string& file) {
  std::ifstream in(file);
  size_t n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n > 0 ? n - 1 : 0;
}

TEST_F(KillSoak, TwentyKillsAtRandomPointsOfProgressResumeToABitIdenticalPolicy) {
  const std::string unbroken = recipe("unbroken"), killed = recipe("killed");
  ASSERT_EQ(run_cli("train " + unbroken).code, 0);
  const std::string metrics = path("killed") + "/metrics.csv", checkpoint = path("killed") + "/checkpoint.pt";
  Rng rng(20261202);
  // The run has 90 iterations; a kill lets it advance at most three rows, so twenty kills
  // land before it can finish, however fast or slow the machine.
  for (int kill = 0; kill < 20; ++kill) {
    const size_t rows_before = row_count(metrics);
    const ino_t checkpoint_before = inode(checkpoint);
    const int moment = rng.integer(0, 3), ahead = rng.integer(1, 2);
    const pid_t pid = start_train(killed);
    const size_t target = rows_before + ahead;
    std::function<bool()> reached = [] { return true; };  // 0: at start-up, before any checkpoint of this life
    if (moment == 1)  // just after a metrics row, before (or while) its checkpoint is written
      reached = [&] { return row_count(metrics) >= target; };
    else if (moment == 2)  // while a checkpoint's temporary file exists (or, missed, one row on)
      reached = [&] {
        return (row_count(metrics) >= rows_before + 1 && std::filesystem::exists(checkpoint + ".tmp")) ||
               row_count(metrics) >= target + 1;
      };
    else if (moment == 3)  // in the rollout after a new checkpoint
      reached = [&] { return inode(checkpoint) != checkpoint_before && inode(checkpoint) != 0; };
    int status = 0;
    ASSERT_TRUE(wait_until(pid, reached, &status))
        << "kill " << kill << " (moment " << moment << "): the run ended by itself, status " << status;
    ASSERT_EQ(::kill(pid, SIGKILL), 0);
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "kill " << kill << ": status " << status;
    ASSERT_FALSE(std::filesystem::exists(path("killed") + "/eval.json")) << "the run finished before kill " << kill;
  }
  ASSERT_EQ(run_cli("train " + killed).code, 0);
  EXPECT_EQ(rows(metrics), rows(path("unbroken") + "/metrics.csv"));
  EXPECT_EQ(rows(metrics).size(), 46080u / 512);
  EXPECT_TRUE(read_file(path("killed") + "/policy.pt") == read_file(path("unbroken") + "/policy.pt"))
      << "policy.pt differs from the unbroken run's";
}

}  // namespace
}  // namespace segue
