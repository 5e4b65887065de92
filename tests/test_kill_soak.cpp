// kill -9 at random moments: a tiny PPO run killed twenty times (before its first
// checkpoint, mid-rollout, mid-write, between a metrics row and its checkpoint) and rerun
// each time ends with the unbroken run's policy.pt, byte for byte, and its rows.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

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

TEST_F(KillSoak, TwentyRandomKillsResumeToABitIdenticalPolicy) {
  const std::string unbroken = recipe("unbroken"), killed = recipe("killed");
  ASSERT_EQ(run_cli("train " + unbroken).code, 0);
  Rng rng(20261202);
  int kills = 0;
  for (int attempt = 0; attempt < 60 && kills < 20; ++attempt) {
    const pid_t pid = fork();
    if (pid == 0) {
      freopen("/dev/null", "w", stdout);
      freopen("/dev/null", "w", stderr);
      execl(SEGUE_BINARY, SEGUE_BINARY, "train", killed.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    // Startup takes about half a second; the whole run a few.
    std::this_thread::sleep_for(std::chrono::microseconds(int64_t(rng.uniform(0.3, 1.3) * 1e6)));
    const bool alive = ::kill(pid, SIGKILL) == 0;
    int status = 0;
    ::waitpid(pid, &status, 0);
    if (alive && WIFSIGNALED(status)) ++kills;
    if (std::filesystem::exists(path("killed") + "/eval.json")) break;  // finished before the kill
  }
  EXPECT_EQ(kills, 20);
  ASSERT_EQ(run_cli("train " + killed).code, 0);
  EXPECT_EQ(rows(path("killed") + "/metrics.csv"), rows(path("unbroken") + "/metrics.csv"));
  EXPECT_EQ(rows(path("killed") + "/metrics.csv").size(), 46080u / 512);
  EXPECT_TRUE(read_file(path("killed") + "/policy.pt") == read_file(path("unbroken") + "/policy.pt"))
      << "policy.pt differs from the unbroken run's";
}

}  // namespace
}  // namespace segue
