#ifndef USE_C10D_GLOO  // LibTorch's CMake config defines it; ProcessGroupGloo.hpp needs it
#define USE_C10D_GLOO
#endif
#include "core/distributed.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <torch/csrc/distributed/c10d/ProcessGroupGloo.hpp>
#include <torch/csrc/distributed/c10d/TCPStore.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/error.h"

namespace segue {

struct Distributed::Group {
  c10::intrusive_ptr<c10d::TCPStore> store;
  c10::intrusive_ptr<c10d::ProcessGroupGloo> gloo;
};

namespace {

std::string first_line(const std::string& s) { return s.substr(0, s.find('\n')); }

std::string env_or(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? v : fallback;
}

int env_int(const char* name, long lo, long hi) {
  const std::string text = env_or(name, "");
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end || v < lo || v > hi)
    throw Error("environment variable " + std::string(name) + " must be an integer in [" + std::to_string(lo) +
                ", " + std::to_string(hi) + "], got '" + text + "'");
  return int(v);
}

void wait_for(const c10::intrusive_ptr<c10d::Work>& work) {
  if (!work->wait()) std::rethrow_exception(work->exception());
}

}  // namespace

Distributed& Distributed::world() {
  static Distributed d;
  return d;
}

const Distributed& Distributed::alone() {
  static Distributed d;
  return d;
}

void Distributed::init_from_environment() {
  const bool has_rank = std::getenv("RANK"), has_world = std::getenv("WORLD_SIZE");
  if (!has_rank && !has_world) return;
  if (has_rank != has_world)
    throw Error(std::string(has_rank ? "RANK" : "WORLD_SIZE") + " is set but " + (has_rank ? "WORLD_SIZE" : "RANK") +
                " is not: set RANK, WORLD_SIZE, MASTER_ADDR and MASTER_PORT together (or use --nproc N)");
  Distributed& d = world();
  if (d.group_) throw Error("the process group is already joined");
  const int size = env_int("WORLD_SIZE", 1, 4096);
  const int rank = env_int("RANK", 0, size - 1);
  if (size == 1) return;
  const std::string addr = env_or("MASTER_ADDR", "127.0.0.1");
  const int port = std::getenv("MASTER_PORT") ? env_int("MASTER_PORT", 1, 65535) : 29500;
  const double timeout_s = std::getenv("SEGUE_DIST_TIMEOUT") ? env_int("SEGUE_DIST_TIMEOUT", 1, 86400) : 300;
  const auto timeout = std::chrono::milliseconds(int64_t(timeout_s * 1000));
  auto group = std::make_shared<Group>();
  try {
    c10d::TCPStoreOptions opts;
    opts.port = uint16_t(port);
    opts.isServer = rank == 0;
    opts.numWorkers = size;
    opts.waitWorkers = true;
    opts.timeout = timeout;
    group->store = c10::make_intrusive<c10d::TCPStore>(addr, opts);
  } catch (const std::exception& e) {
    if (rank == 0)
      throw Error("rank 0 could not serve the rendezvous on MASTER_PORT " + std::to_string(port) +
                  " (in use? pick another MASTER_PORT): " + first_line(e.what()));
    throw Error("rank " + std::to_string(rank) + " could not reach rank 0 at MASTER_ADDR " + addr + ":" +
                std::to_string(port) + " within " + std::to_string(int(timeout_s)) + " s: " + first_line(e.what()));
  }
  try {
    auto options = c10d::ProcessGroupGloo::Options::create(timeout);
    // The address the other ranks reach this one at: loopback for a single host,
    // GLOO_SOCKET_IFNAME's interface if set (as in PyTorch), else the host name's address.
    const std::string ifname = env_or("GLOO_SOCKET_IFNAME", "");
    options->devices.push_back(
        addr == "127.0.0.1" || addr == "localhost" ? c10d::ProcessGroupGloo::createDeviceForHostname("127.0.0.1")
        : !ifname.empty()                          ? c10d::ProcessGroupGloo::createDeviceForInterface(ifname)
                                                   : c10d::ProcessGroupGloo::createDefaultDevice());
    group->gloo = c10::make_intrusive<c10d::ProcessGroupGloo>(group->store, rank, size, options);
  } catch (const std::exception& e) {
    throw Error("rank " + std::to_string(rank) + " could not join the Gloo group of " + std::to_string(size) +
                ": " + first_line(e.what()));
  }
  d.rank_ = rank;
  d.size_ = size;
  d.timeout_s_ = timeout_s;
  d.group_ = group;
}

Shard Distributed::shard(int total, const std::string& what) const {
  if (total < size_)
    throw Error(what + ": " + std::to_string(total) + " cannot be shared by " + std::to_string(size_) +
                " ranks (each needs at least one)");
  const int base = total / size_, extra = total % size_;
  return {rank_ * base + std::min(rank_, extra), base + (rank_ < extra ? 1 : 0)};
}

void Distributed::run(const char* op, const std::function<void()>& body) const {
  const auto t0 = std::chrono::steady_clock::now();
  try {
    body();
  } catch (const std::exception& e) {
    throw Error(std::string("lost the other ranks in ") + op +
                " (one stopped, or hung past SEGUE_DIST_TIMEOUT=" + std::to_string(int(timeout_s_)) +
                " s): " + first_line(e.what()) + "; rerun the same command to resume from the last checkpoint");
  }
  comm_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void Distributed::sum(torch::Tensor& t) const {
  if (single()) return;
  run("all-reduce", [&] {
    std::vector<torch::Tensor> ts{t};
    wait_for(group_->gloo->allreduce(ts, c10d::AllreduceOptions{}));
  });
}

void Distributed::sum(double* x, size_t n) const {
  if (single() || n == 0) return;
  auto t = torch::from_blob(x, {int64_t(n)}, torch::kFloat64);
  sum(t);
}

void Distributed::min(torch::Tensor& t) const {
  if (single()) return;
  run("all-reduce", [&] {
    std::vector<torch::Tensor> ts{t};
    c10d::AllreduceOptions opts;
    opts.reduceOp = c10d::ReduceOp::MIN;
    wait_for(group_->gloo->allreduce(ts, opts));
  });
}

bool Distributed::any(bool flag) const {
  double x = flag ? 1.0 : 0.0;
  sum(&x, 1);
  return x > 0;
}

std::string Distributed::broadcast(const std::string& bytes) const {
  if (single()) return bytes;
  auto size = torch::tensor({int64_t(bytes.size())}, torch::kLong);
  std::string out;
  run("broadcast", [&] {
    std::vector<torch::Tensor> s{size};
    wait_for(group_->gloo->broadcast(s, c10d::BroadcastOptions{}));
    out.resize(size_t(size.item<int64_t>()));
    if (rank_ == 0) out = bytes;
    if (out.empty()) return;
    std::vector<torch::Tensor> b{torch::from_blob(out.data(), {int64_t(out.size())}, torch::kUInt8)};
    wait_for(group_->gloo->broadcast(b, c10d::BroadcastOptions{}));
  });
  return out;
}

std::vector<std::string> Distributed::gather(const std::string& bytes) const {
  if (single()) return {bytes};
  std::vector<std::string> out(size_);
  run("all-gather", [&] {
    // The sizes first, then every rank's bytes padded to the longest.
    std::vector<torch::Tensor> in{torch::tensor({int64_t(bytes.size())}, torch::kLong)};
    std::vector<std::vector<torch::Tensor>> sizes(1);
    for (int r = 0; r < size_; ++r) sizes[0].push_back(torch::empty({1}, torch::kLong));
    wait_for(group_->gloo->allgather(sizes, in));
    int64_t longest = 1;
    for (const auto& s : sizes[0]) longest = std::max(longest, s.item<int64_t>());
    auto padded = torch::zeros({longest}, torch::kUInt8);
    std::memcpy(padded.data_ptr(), bytes.data(), bytes.size());
    std::vector<torch::Tensor> mine{padded};
    std::vector<std::vector<torch::Tensor>> all(1);
    for (int r = 0; r < size_; ++r) all[0].push_back(torch::empty({longest}, torch::kUInt8));
    wait_for(group_->gloo->allgather(all, mine));
    for (int r = 0; r < size_; ++r)
      out[r].assign(static_cast<const char*>(all[0][r].data_ptr()), size_t(sizes[0][r].item<int64_t>()));
  });
  return out;
}

void Distributed::barrier() const {
  if (single()) return;
  run("barrier", [&] { wait_for(group_->gloo->barrier(c10d::BarrierOptions{})); });
}

double Distributed::sum_gradients(const std::vector<torch::Tensor>& params, double extra) const {
  if (single()) return extra;
  std::vector<torch::Tensor> parts;
  for (const auto& p : params) parts.push_back(p.grad().defined() ? p.grad().reshape(-1) : torch::zeros({p.numel()}));
  parts.push_back(torch::tensor({float(extra)}));
  auto flat = torch::cat(parts);
  sum(flat);
  int64_t k = 0;
  for (auto p : params) {
    auto g = flat.slice(0, k, k + p.numel()).view(p.sizes());
    if (p.grad().defined()) p.mutable_grad().copy_(g);
    else p.mutable_grad() = g.clone();
    k += p.numel();
  }
  return flat[k].item<double>();
}

void Distributed::leader_done(const std::string& what) const {
  if (single()) return;
  static int calls = 0;
  const std::string key = "segue/leader_done/" + std::to_string(calls++);
  run(what.c_str(), [&] {
    if (leader()) group_->store->set(key, std::vector<uint8_t>{1});
    else group_->store->wait({key}, std::chrono::hours(24 * 365));
  });
}

// ---- the local launcher --------------------------------------------------------------

namespace {

std::vector<pid_t> g_children;
volatile sig_atomic_t g_forwarded = 0;

void forward_signal(int sig) {
  g_forwarded = sig;
  for (pid_t p : g_children) ::kill(p, sig);
}

int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  if (fd < 0 || ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0)
    throw Error("--nproc: could not find a free port on 127.0.0.1 for the rendezvous (set MASTER_PORT)");
  const int port = ntohs(a.sin_port);
  ::close(fd);
  return port;
}

std::string describe(int status) {
  if (WIFSIGNALED(status)) return "was killed by signal " + std::to_string(WTERMSIG(status));
  return "exited with status " + std::to_string(WEXITSTATUS(status));
}

}  // namespace

int launch_local_ranks(int nproc, const std::vector<std::string>& argv) {
  if (nproc < 1 || nproc > 256) throw Error("--nproc must be in [1, 256], got " + std::to_string(nproc));
  if (std::getenv("RANK") || std::getenv("WORLD_SIZE"))
    throw Error("--nproc starts its own ranks: unset RANK and WORLD_SIZE, or drop --nproc");
  // With NNODES and NODE_RANK (torchrun's multi-node form), this host's ranks are
  // NODE_RANK * nproc + 0..nproc-1 of NNODES * nproc, meeting at MASTER_ADDR:MASTER_PORT.
  const int nodes = std::getenv("NNODES") ? env_int("NNODES", 1, 4096) : 1;
  const int node = nodes > 1 ? env_int("NODE_RANK", 0, nodes - 1) : 0;
  if (nodes > 1 && (!std::getenv("MASTER_ADDR") || !std::getenv("MASTER_PORT")))
    throw Error("NNODES is " + std::to_string(nodes) + ": set MASTER_ADDR and MASTER_PORT to rank 0's host and port");
  const std::string port = std::getenv("MASTER_PORT") ? std::to_string(env_int("MASTER_PORT", 1, 65535))
                                                      : std::to_string(free_port());
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  std::fflush(nullptr);
  for (int r = 0; r < nproc; ++r) {
    const pid_t pid = ::fork();
    if (pid < 0) throw Error("--nproc: fork failed: " + std::string(std::strerror(errno)));
    if (pid == 0) {
      // Its own process group, so a terminal's Ctrl-C reaches the launcher only (which
      // forwards it once); and a launcher that dies takes its ranks with it.
      ::setpgid(0, 0);
      ::prctl(PR_SET_PDEATHSIG, SIGTERM);
      ::setenv("RANK", std::to_string(node * nproc + r).c_str(), 1);
      ::setenv("WORLD_SIZE", std::to_string(nodes * nproc).c_str(), 1);
      ::setenv("LOCAL_RANK", std::to_string(r).c_str(), 1);
      ::setenv("LOCAL_WORLD_SIZE", std::to_string(nproc).c_str(), 1);
      ::setenv("MASTER_ADDR", env_or("MASTER_ADDR", "127.0.0.1").c_str(), 1);
      ::setenv("MASTER_PORT", port.c_str(), 1);
      ::setenv("GLOG_minloglevel", "3", 0);  // c10d's own log lines: our errors say it in one line
      ::execv("/proc/self/exe", args.data());
      std::fprintf(stderr, "error: --nproc: could not start rank %d: %s\n", r, std::strerror(errno));
      ::_exit(127);
    }
    g_children.push_back(pid);
  }
  ::signal(SIGINT, forward_signal);
  ::signal(SIGTERM, forward_signal);
  int result = 0;
  size_t running = g_children.size();
  while (running > 0) {
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, 0);
    if (pid < 0) {
      if (errno == EINTR) continue;
      break;
    }
    --running;
    const bool failed = !(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    if (!failed || result != 0) continue;
    result = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    if (g_forwarded) continue;  // stopping on request: every rank checkpoints and exits
    size_t rank = 0;
    while (rank < g_children.size() && g_children[rank] != pid) ++rank;
    for (pid_t p : g_children)
      if (p != pid) ::kill(p, SIGKILL);
    std::fprintf(stderr, "error: rank %zu %s; the other ranks were stopped\n", rank, describe(status).c_str());
  }
  ::signal(SIGINT, SIG_DFL);
  ::signal(SIGTERM, SIG_DFL);
  g_children.clear();
  return result;
}

}  // namespace segue
