#pragma once
// Data parallelism over LibTorch's c10d: the ranks meet at a TCPStore served by rank 0
// (MASTER_ADDR:MASTER_PORT, torchrun's conventions) and exchange tensors through
// ProcessGroupGloo. A process started without RANK/WORLD_SIZE is a world of one, where
// every collective below returns its input: the single-process code path is the
// distributed one with nothing to exchange.
//
// Every collective must be called by every rank in the same order (as in MPI). A rank
// that stops or hangs makes the others' next collective throw segue::Error after
// SEGUE_DIST_TIMEOUT seconds at the latest (default 300).
#include <torch/torch.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace segue {

// The contiguous block of `total` items (environments, attempts) a rank owns.
struct Shard {
  int first = 0, count = 0;
};

class Distributed {
 public:
  // The process-wide group, like torch.distributed's default group: a world of one
  // until init_from_environment() finds RANK and WORLD_SIZE.
  static Distributed& world();
  // A world of one, whatever world() is (work only rank 0 does, e.g. a final evaluation).
  static const Distributed& alone();
  // Reads RANK, WORLD_SIZE, MASTER_ADDR (default 127.0.0.1), MASTER_PORT (default 29500)
  // and SEGUE_DIST_TIMEOUT, and joins the group. Throws segue::Error with one line on an
  // incomplete or malformed environment, a port already in use, or ranks that never come.
  static void init_from_environment();

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool single() const { return size_ == 1; }
  bool leader() const { return rank_ == 0; }  // writes the run directory

  // This rank's share of `total` items, the first ranks taking one more when it does not
  // divide; every rank gets at least one (throws otherwise).
  Shard shard(int total, const std::string& what) const;

  // In place, over every rank: the sum, the minimum, the maximum (double or float rows).
  void sum(torch::Tensor& t) const;
  void sum(double* x, size_t n) const;
  void min(torch::Tensor& t) const;
  bool any(bool flag) const;  // true if any rank's flag is
  // Rank 0's bytes, on every rank.
  std::string broadcast(const std::string& bytes) const;
  // Every rank's bytes, in rank order, on every rank.
  std::vector<std::string> gather(const std::string& bytes) const;
  void barrier() const;
  // Sums every parameter's gradient over the ranks (a parameter without one counts as
  // zero), with `extra` riding along in the same exchange; returns the sum of `extra`.
  double sum_gradients(const std::vector<torch::Tensor>& params, double extra = 0.0) const;
  // Work rank 0 does alone (a stage whose output only it writes): the others wait at
  // leader_done() until rank 0 reaches it, without SEGUE_DIST_TIMEOUT (but a rank 0 that
  // dies still ends the wait). Every rank calls it, in the same order.
  void leader_done(const std::string& what) const;

  // Wall time spent inside collectives since the start (benchmarks report it).
  double comm_seconds() const { return comm_seconds_; }

 private:
  Distributed() = default;
  void run(const char* op, const std::function<void()>& body) const;

  int rank_ = 0, size_ = 1;
  double timeout_s_ = 300;
  struct Group;  // the TCPStore and the ProcessGroupGloo (distributed.cpp)
  std::shared_ptr<Group> group_;
  mutable double comm_seconds_ = 0;
};

// segue COMMAND ... --nproc N: starts N copies of the command on this host as ranks
// 0..N-1 (RANK, WORLD_SIZE, MASTER_ADDR, MASTER_PORT set; a free port unless MASTER_PORT
// is), or with NNODES and NODE_RANK as ranks NODE_RANK * N + 0..N-1 of NNODES * N;
// forwards Ctrl-C and SIGTERM, and when a rank fails stops the others and returns its
// exit status. `argv` is the command line without --nproc.
int launch_local_ranks(int nproc, const std::vector<std::string>& argv);

}  // namespace segue
