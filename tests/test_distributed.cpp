// Data-parallel PPO on c10d Gloo, on loopback: two ranks with half the environments each
// train what one process with all of them trains; a killed rank resumes; bad launches are
// refused in one line.
#include <gtest/gtest.h>
#include <torch/torch.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "core/distributed.h"
#include "core/run_dir.h"
#include "hrl/collection.h"
#include "tests/cli_run.h"
#include "tests/csv.h"
#include "tests/temp_dir.h"
#include "tests/tiny_patrol.h"

namespace segue {
namespace {

bool timing(const std::string& column) { return column.find("seconds") != std::string::npos; }

// Every tensor of two checkpoints, to `tol`: networks, normalisers, episodes in flight
// and, under "optimizer", Adam's moments; the recipe text and the counters (which hold
// wall time) aside. Returns how many tensors were compared.
bool close(const torch::Tensor& a, const torch::Tensor& b, double tol) {
  if (a.sizes() != b.sizes()) return false;
  if (!a.is_floating_point()) return torch::equal(a, b);
  return torch::allclose(a.to(torch::kFloat64), b.to(torch::kFloat64), tol, tol);
}

// LibTorch keys Adam's per-parameter state by the parameter's address, which differs
// between processes: each state of one file must match a state of the other.
bool same_state(torch::serialize::InputArchive& a, torch::serialize::InputArchive& b, double tol) {
  for (const char* k : {"exp_avg", "exp_avg_sq"}) {
    torch::Tensor ta, tb;
    if (!a.try_read(k, ta) || !b.try_read(k, tb) || !close(ta, tb, tol)) return false;
  }
  return true;
}

int expect_close_archives(torch::serialize::InputArchive& a, torch::serialize::InputArchive& b,
                          const std::string& where, double tol) {
  int compared = 0;
  for (const std::string& key : a.keys()) {
    if (key == "meta_note" || key == "meta_counters") continue;
    torch::Tensor ta, tb;
    torch::serialize::InputArchive sa, sb;
    if (a.try_read(key, ta)) {
      EXPECT_TRUE(b.try_read(key, tb)) << where << key;
      EXPECT_TRUE(close(ta, tb, tol)) << where << key << " differs";
      ++compared;
    } else if (key.rfind("0x", 0) == 0 && a.try_read(key, sa)) {
      bool matched = false;
      for (const std::string& other : b.keys())
        if (b.try_read(other, sb) && same_state(sa, sb, tol)) matched = true;
      EXPECT_TRUE(matched) << where << key << ": no Adam state of the other file matches";
      compared += 2;
    } else if (a.try_read(key, sa)) {
      EXPECT_TRUE(b.try_read(key, sb)) << where << key;
      compared += expect_close_archives(sa, sb, where + key + "/", tol);
    }
  }
  return compared;
}

int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

class DataParallel : public TempDirTest {
 protected:
  DataParallel() : TempDirTest("distributed") {}
  // A 50-step walk, 4 environments; minibatches of half a rollout, so that every
  // minibatch mixes both ranks' rows.
  std::string recipe(const std::string& name, int iterations, int epochs = 2, int steps_per_env = 64,
                     int minibatches = 2) {
    const std::string file = path(name + ".yaml");
    std::ofstream(file) << "task: walker_forward\n"
                           "threads: 1\n"
                           "run_dir: " << path(name) << "\n"
                           "checkpoint_every: 1\n"
                           "env: {max_episode_steps: 50, success_steps: 50}\n"
                           "ppo: {total_steps: " << iterations * 4 * steps_per_env
                        << ", num_envs: 4, steps_per_env: " << steps_per_env
                        << ", minibatch_size: " << 4 * steps_per_env / minibatches << ", epochs: " << epochs << "}\n"
                           "eval: {episodes: 1}\n";
    return file;
  }
  // Runs `segue ARGS`, expecting success; returns what it printed.
  std::string segue_ok(const std::string& args) {
    CliRun r = run_cli(args);
    EXPECT_EQ(r.code, 0) << r.output;
    return r.output;
  }
  std::string train(const std::string& file, const std::string& flags = "") {
    return segue_ok("train " + file + " " + flags);
  }
};

// TRPO on two ranks: rank 0 takes the step and fits the value network on the gathered
// rollout. After one iteration the checkpoints agree to float tolerance; over three, the
// normalisers' moments merged over ranks round differently, conjugate gradient amplifies
// that, and the walker's chaotic episodes drift apart a little, so the metrics are
// compared to 5e-3.
TEST_F(DataParallel, TwoRanksTakeTheTrpoStepOneProcessTakes) {
  for (int iterations : {1, 3}) {
    auto trpo = [&](const std::string& name) {
      const std::string file = path(name + ".yaml");
      std::ofstream(file) << "task: walker_forward\nthreads: 1\nrun_dir: " << path(name)
                          << "\ncheckpoint_every: 1\nlearner: trpo\n"
                             "env: {max_episode_steps: 50, success_steps: 50}\n"
                             "trpo: {total_steps: " << 256 * iterations
                          << ", num_envs: 4, steps_per_env: 64, vf_minibatch: 128, vf_epochs: 2}\n"
                             "eval: {episodes: 1}\n";
      return file;
    };
    const std::string one = "trpo_one" + std::to_string(iterations), two = "trpo_two" + std::to_string(iterations);
    train(trpo(one));
    const std::string out = train(trpo(two), "--nproc 2");
    EXPECT_NE(out.find("on 2 ranks"), std::string::npos) << out;
    if (iterations == 1) {
      torch::serialize::InputArchive a, b;
      a.load_from(path(one) + "/checkpoint.pt");
      b.load_from(path(two) + "/checkpoint.pt");
      EXPECT_GT(expect_close_archives(a, b, "checkpoint.pt: ", 2e-5), 20);
    }
    auto m1 = csv(path(one) + "/metrics.csv"), m2 = csv(path(two) + "/metrics.csv");
    ASSERT_EQ(m1.size(), size_t(iterations + 1));
    ASSERT_EQ(m1.size(), m2.size());
    const double tol = iterations == 1 ? 1e-5 : 5e-3;
    for (size_t r = 1; r < m1.size(); ++r)
      for (size_t c = 0; c < m1[0].size(); ++c)
        if (!timing(m1[0][c]))
          EXPECT_NEAR(std::stod(m1[r][c]), std::stod(m2[r][c]), tol * (1 + std::abs(std::stod(m1[r][c]))))
              << iterations << " iterations, row " << r << " column " << m1[0][c];
  }
}

TEST_F(DataParallel, TwoRanksTrainWhatOneProcessTrains) {
  // One iteration of one minibatch: Adam's first moments are 0.1 x the (clipped) gradient,
  // so equal optimiser states after it are equal gradients. Then three iterations.
  for (int iterations : {1, 3}) {
    const std::string one = "one" + std::to_string(iterations), two = "two" + std::to_string(iterations);
    const int epochs = iterations == 1 ? 1 : 2, minibatches = iterations == 1 ? 1 : 2;
    const std::string r1 = recipe(one, iterations, epochs, 64, minibatches);
    const std::string r2 = recipe(two, iterations, epochs, 64, minibatches);
    train(r1);
    const std::string out = train(r2, "--nproc 2");
    EXPECT_NE(out.find("on 2 ranks"), std::string::npos) << out;
    torch::serialize::InputArchive a, b;
    a.load_from(path(one) + "/checkpoint.pt");
    b.load_from(path(two) + "/checkpoint.pt");
    EXPECT_GT(expect_close_archives(a, b, "checkpoint.pt: ", 2e-5), 40);  // networks, normalisers, episodes in flight, optimiser moments
    auto m1 = csv(path(one) + "/metrics.csv"), m2 = csv(path(two) + "/metrics.csv");
    ASSERT_EQ(m1.size(), size_t(iterations + 1));
    ASSERT_EQ(m1.size(), m2.size());
    for (size_t r = 1; r < m1.size(); ++r)
      for (size_t c = 0; c < m1[0].size(); ++c)
        if (!timing(m1[0][c]))
          EXPECT_NEAR(std::stod(m1[r][c]), std::stod(m2[r][c]), 1e-5 * (1 + std::abs(std::stod(m1[r][c]))))
              << "row " << r << " column " << m1[0][c];
  }
}

// `segue train FILE --nproc 2` in the background, its stderr into `log`. Returns the
// launcher's pid once RUN_DIR/metrics.csv has `rows` iterations, or -1 (the launcher reaped,
// its exit status in *status) if it ended before that.
pid_t start_two_ranks(const std::string& file, const std::string& run_dir, size_t rows, const std::string& log,
                      const char* timeout_s = nullptr, int* status = nullptr) {
  const pid_t launcher = fork();
  if (launcher == 0) {
    freopen(log.c_str(), "w", stderr);
    freopen("/dev/null", "w", stdout);
    if (timeout_s) setenv("SEGUE_DIST_TIMEOUT", timeout_s, 1);
    execl(SEGUE_BINARY, SEGUE_BINARY, "train", file.c_str(), "--nproc", "2", static_cast<char*>(nullptr));
    _exit(127);
  }
  int st = 0;
  const bool reached = wait_until(launcher, [&] { return csv(run_dir + "/metrics.csv").size() >= rows + 1; }, &st);
  if (status) *status = st;
  return reached ? launcher : -1;
}

// The children of a process (the launcher's ranks), in start order.
std::vector<pid_t> children(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/task/" + std::to_string(pid) + "/children");
  std::vector<pid_t> out;
  for (pid_t c; in >> c;) out.push_back(c);
  return out;
}

TEST_F(DataParallel, AKilledRankStopsTheOthersAndTheRerunResumesToTheUnbrokenRun) {
  const int iterations = 24;
  train(recipe("unbroken", iterations, 2, 128), "--nproc 2");
  const std::string file = recipe("killed", iterations, 2, 128);
  // Rank 1 dies (SIGKILL: no checkpoint of its own) once a few iterations are in.
  int started = 0;
  const pid_t launcher = start_two_ranks(file, path("killed"), 3, path("killed.log"), nullptr, &started);
  ASSERT_GT(launcher, 0) << "segue train --nproc 2 ended before iteration 3, status " << started << "\n"
                         << read_file(path("killed.log"));
  const std::vector<pid_t> ranks = children(launcher);
  ASSERT_EQ(ranks.size(), 2u);
  ::kill(ranks[1], SIGKILL);
  int status = 0;
  ::waitpid(launcher, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_NE(WEXITSTATUS(status), 0);
  const size_t rows_then = csv(path("killed") + "/metrics.csv").size() - 1;
  ASSERT_LT(rows_then, size_t(iterations)) << "the run ended before rank 1 was killed";
  EXPECT_FALSE(std::filesystem::exists(path("killed") + "/eval.json"));

  const std::string out = train(file, "--nproc 2");
  EXPECT_NE(out.find("resuming"), std::string::npos) << out;
  // The same rows (timings aside) and the same policy as the run nobody killed.
  auto a = csv(path("unbroken") + "/metrics.csv"), b = csv(path("killed") + "/metrics.csv");
  ASSERT_EQ(a.size(), size_t(iterations + 1));
  ASSERT_EQ(a.size(), b.size());
  for (size_t r = 0; r < a.size(); ++r)
    for (size_t c = 0; c < a[0].size(); ++c)
      if (!timing(a[0][c])) EXPECT_EQ(a[r][c], b[r][c]) << "row " << r << " column " << a[0][c];
  torch::serialize::InputArchive ca, cb;
  ca.load_from(path("unbroken") + "/checkpoint.pt");
  cb.load_from(path("killed") + "/checkpoint.pt");
  EXPECT_GT(expect_close_archives(ca, cb, "checkpoint.pt: ", 0.0), 40);
}

TEST_F(DataParallel, BadLaunchesAreRefusedInOneLine) {
  const std::string file = recipe("bad", 1);
  struct Case {
    std::string command, expect;
  };
  // A port that is taken: rank 0 cannot serve the rendezvous there.
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof addr;
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  ASSERT_EQ(::listen(fd, 1), 0);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  const std::string taken = std::to_string(ntohs(addr.sin_port));
  const std::string port = std::to_string(free_port());
  // run_cli puts the binary first: "--help >/dev/null;" lets a case start with its own environment.
  const std::string bin = SEGUE_BINARY;
  auto own = [](const std::string& shell) { return "--help >/dev/null; { " + shell + "; }"; };
  const std::vector<Case> cases{
      {"train " + file + " --nproc 0", "--nproc must be an integer in [1, 256], got '0'"},
      {"train " + file + " --nproc", "flag --nproc needs a value"},
      {"eval " + file + " --nproc 2", "--nproc is for 'segue train' and 'segue run'"},
      {own("MASTER_PORT=" + taken + " " + bin + " train " + file + " --nproc 2"),
       "MASTER_PORT " + taken + " (in use? pick another MASTER_PORT)"},
      {own("RANK=1 " + bin + " train " + file), "RANK is set but WORLD_SIZE is not"},
      {own("WORLD_SIZE=2 RANK=5 " + bin + " train " + file),
       "RANK must be an integer in [0, 1], got '5'"},
      // Rank 1 started with another learning rate than rank 0: both refuse, naming the key.
      {own("export WORLD_SIZE=2 MASTER_PORT=" + port + "; RANK=0 " + bin + " train " + file + " & RANK=1 " + bin +
           " train " + file + " --set ppo.lr=1e-4; wait $!"),
       "rank 1 was started with another recipe than rank 0 (key 'ppo.lr': "},
  };
  for (const Case& c : cases) {
    CliRun r = run_cli(c.command);
    EXPECT_NE(r.code, 0) << c.command;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.command << "\n" << r.output;
    EXPECT_EQ(r.output.find("terminate called"), std::string::npos) << r.output;
  }
  EXPECT_FALSE(std::filesystem::exists(path("bad") + "/eval.json"));  // nothing trained
  ::close(fd);
}

// segue run on two ranks: collection split and joined, pi_ab and Lee's policy
// data-parallel, the switch's attempts split, and every rank's attempts in the replay
// buffer.
TEST_F(DataParallel, TheMethodRunsOnTwoRanks) {
  const std::string file = path("tiny_patrol.yaml");
  std::ofstream(file) << kTinyPatrol << "lee: {enabled: true}\nrun_dir: " << path("patrol") << "\n";
  segue_ok("run " + file + " --nproc 2");
  const std::string t = path("patrol") + "/forward-balance/";
  EXPECT_EQ(load_start_states(t + "start_states.pt").size(), 12);       // collect.start_states, both ranks' halves
  EXPECT_EQ(load_demonstrations(t + "demonstrations.pt").size(), 400);  // collect.demonstrations
  for (const auto& entry : std::filesystem::directory_iterator(t))
    EXPECT_EQ(entry.path().string().find(".part"), std::string::npos) << entry.path();
  EXPECT_EQ(csv(t + "transition.csv").size(), 1u + 2048 / 512);
  EXPECT_EQ(csv(t + "lee.csv").size(), 1u + 2048 / 512);
  for (const char* f : {"policy.pt", "q.pt", "lee.pt"}) EXPECT_TRUE(std::filesystem::exists(t + f)) << f;
  EXPECT_TRUE(std::filesystem::exists(path("patrol") + "/patrol.json"));
  const auto sw = csv(t + "switch.csv");
  ASSERT_GE(sw.size(), 2u);
  auto column = [&](const std::string& name) {
    const size_t c = size_t(std::find(sw[0].begin(), sw[0].end(), name) - sw[0].begin());
    return std::stod(sw.back().at(c));
  };
  EXPECT_EQ(column("attempts"), 24);
  // Rank 1's transitions are in rank 0's buffer: rank 0's own are only part of it.
  EXPECT_GT(column("rank0_rows"), 0);
  EXPECT_GT(column("replay_rows"), column("rank0_rows"));
  EXPECT_GE(column("replay_rows"), 24);  // at least one transition per attempt
}

// A rank that hangs (stopped, not dead: its connections stay open) makes rank 0's next
// collective give up after SEGUE_DIST_TIMEOUT, and the launcher stops the rest. A short
// timeout can also fire before the hang, when a loaded machine keeps one rank from its
// collective that long: then the run is started again with four times the timeout, so the
// test holds on a machine of any speed.
TEST_F(DataParallel, AHungRankStopsTheOthersWithinTheTimeout) {
  const std::string file = recipe("hung", 400);
  const std::string log = path("hung.log");
  pid_t launcher = -1;
  std::string timeout;
  for (int seconds = 2; launcher < 0 && seconds <= 512; seconds *= 4) {
    std::filesystem::remove_all(path("hung"));
    timeout = std::to_string(seconds);
    int status = 0;
    launcher = start_two_ranks(file, path("hung"), 2, log, timeout.c_str(), &status);
    if (launcher < 0) {
      const std::string text = read_file(log);
      ASSERT_NE(text.find("lost the other ranks in"), std::string::npos)
          << "segue train --nproc 2 ended before iteration 2, status " << status << "\n" << text;
    }
  }
  ASSERT_GT(launcher, 0);
  const std::vector<pid_t> ranks = children(launcher);
  ASSERT_EQ(ranks.size(), 2u);
  ::kill(ranks[1], SIGSTOP);
  // No clock here: the log's line says the timeout fired (a hang would never write it, and
  // ctest's own timeout ends the test).
  int status = 0;
  ::waitpid(launcher, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0);
  const std::string text = read_file(log);
  EXPECT_NE(text.find("error: rank 0: lost the other ranks in"), std::string::npos) << text;
  EXPECT_NE(text.find("SEGUE_DIST_TIMEOUT=" + timeout + " s"), std::string::npos) << text;
  EXPECT_NE(text.find("the other ranks were stopped"), std::string::npos) << text;
}

}  // namespace
}  // namespace segue

namespace segue {
namespace {

// Two "hosts": network namespaces joined by a veth pair, each with its own address, rank 0
// serving the store on host A's. Needs root and `ip netns`; where the machine refuses,
// the tests say so and skip (the local-rank tests above still run).
class TwoHosts : public DataParallel {
 protected:
  void SetUp() override {
    DataParallel::SetUp();
    const std::string id = std::to_string(::getpid() % 100000);
    ns_a_ = "segue_a" + id, ns_b_ = "segue_b" + id, veth_a_ = "sga" + id, veth_b_ = "sgb" + id;
    const std::string setup = "ip netns add " + ns_a_ + " && ip netns add " + ns_b_ + " && ip link add " + veth_a_ +
                              " type veth peer name " + veth_b_ + " && ip link set " + veth_a_ + " netns " + ns_a_ +
                              " && ip link set " + veth_b_ + " netns " + ns_b_ + " && ip -n " + ns_a_ +
                              " addr add 10.231.7.1/24 dev " + veth_a_ + " && ip -n " + ns_b_ +
                              " addr add 10.231.7.2/24 dev " + veth_b_ + " && ip -n " + ns_a_ + " link set " +
                              veth_a_ + " up && ip -n " + ns_b_ + " link set " + veth_b_ + " up && ip -n " + ns_a_ +
                              " link set lo up && ip -n " + ns_b_ + " link set lo up";
    ready_ = std::system((setup + " >/dev/null 2>&1").c_str()) == 0;
    if (!ready_) GTEST_SKIP() << "this machine does not allow network namespaces (ip netns add: needs root)";
  }
  void TearDown() override {
    std::system(("ip netns del " + ns_a_ + " >/dev/null 2>&1; ip netns del " + ns_b_ + " >/dev/null 2>&1").c_str());
    DataParallel::TearDown();
  }
  // Rank `rank` of 2 on its host, `segue train FILE`, all it prints into `log`.
  pid_t start_rank(int rank, const std::string& file, const std::string& log) {
    const pid_t pid = fork();
    if (pid == 0) {
      freopen(log.c_str(), "w", stdout);
      dup2(fileno(stdout), fileno(stderr));
      const std::string ns = rank == 0 ? ns_a_ : ns_b_, ifname = rank == 0 ? veth_a_ : veth_b_;
      const std::string r = "RANK=" + std::to_string(rank), gloo = "GLOO_SOCKET_IFNAME=" + ifname;
      // `ip netns exec` runs the command in the same process: the pid is segue's.
      execlp("ip", "ip", "netns", "exec", ns.c_str(), "env", r.c_str(), "WORLD_SIZE=2", "MASTER_ADDR=10.231.7.1",
             "MASTER_PORT=29531", gloo.c_str(), "SEGUE_DIST_TIMEOUT=10", SEGUE_BINARY, "train", file.c_str(),
             static_cast<char*>(nullptr));
      _exit(127);
    }
    return pid;
  }
  int wait_exit(pid_t pid) {
    int status = 0;
    ::waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  void expect_same_metrics(const std::string& a, const std::string& b, double tol) {
    auto m1 = csv(a), m2 = csv(b);
    ASSERT_EQ(m1.size(), m2.size());
    for (size_t r = 1; r < m1.size(); ++r)
      for (size_t c = 0; c < m1[0].size(); ++c)
        if (!timing(m1[0][c]))
          EXPECT_NEAR(std::stod(m1[r][c]), std::stod(m2[r][c]), tol * (1 + std::abs(std::stod(m1[r][c]))))
              << "row " << r << " column " << m1[0][c];
  }
  bool ready_ = false;
  std::string ns_a_, ns_b_, veth_a_, veth_b_;
};

TEST_F(TwoHosts, TrainWhatOneProcessTrains) {
  train(recipe("one", 3));
  const std::string file = recipe("hosts", 3);
  const pid_t a = start_rank(0, file, path("a.log")), b = start_rank(1, file, path("b.log"));
  EXPECT_EQ(wait_exit(a), 0) << read_file(path("a.log"));
  EXPECT_EQ(wait_exit(b), 0) << read_file(path("b.log"));
  torch::serialize::InputArchive x, y;
  x.load_from(path("one") + "/checkpoint.pt");
  y.load_from(path("hosts") + "/checkpoint.pt");
  EXPECT_GT(expect_close_archives(x, y, "checkpoint.pt: ", 2e-5), 40);
  expect_same_metrics(path("one") + "/metrics.csv", path("hosts") + "/metrics.csv", 1e-5);
}

TEST_F(TwoHosts, AKilledHostStopsTheOtherInOneLineAndTheRerunResumes) {
  train(recipe("one", 6));
  const std::string file = recipe("killed", 6);
  const pid_t a = start_rank(0, file, path("a.log")), b = start_rank(1, file, path("b.log"));
  int status = 0;
  ASSERT_TRUE(wait_until(a, [&] { return csv(path("killed") + "/metrics.csv").size() >= 3; }, &status))
      << "rank 0 ended before its second iteration: " << read_file(path("a.log"));
  ::kill(b, SIGKILL);
  wait_exit(b);
  EXPECT_NE(wait_exit(a), 0);
  const std::string log = read_file(path("a.log"));
  EXPECT_NE(log.find("error: "), std::string::npos) << log;
  EXPECT_NE(log.find("lost the other ranks"), std::string::npos) << log;
  // Both hosts rerun the same command: the run resumes from its last checkpoint.
  const pid_t a2 = start_rank(0, file, path("a2.log")), b2 = start_rank(1, file, path("b2.log"));
  EXPECT_EQ(wait_exit(a2), 0) << read_file(path("a2.log"));
  EXPECT_EQ(wait_exit(b2), 0) << read_file(path("b2.log"));
  EXPECT_NE(read_file(path("a2.log")).find("resuming"), std::string::npos) << read_file(path("a2.log"));
  expect_same_metrics(path("one") + "/metrics.csv", path("killed") + "/metrics.csv", 1e-4);
}

}  // namespace
}  // namespace segue
