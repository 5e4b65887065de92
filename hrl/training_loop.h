#pragma once
// The loop every training stage runs, a skill's (segue train) and the method's pi_ab and
// Lee et al.'s policy (segue run) alike: iterations until the step budget is spent, a
// metrics row each, a checkpoint every few iterations, at the last and when stopped, and a
// progress line. Every rank of a data-parallel run stops at the same iteration.
#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "algorithms/learner.h"
#include "core/distributed.h"

namespace segue {

// The signal number that asked the run to stop, or 0.
int signal_of(const std::atomic<int>* stop);
// Whether to stop, agreed by every rank (a collective): the signal number if any rank saw
// one (1 where this rank did not), else 0.
int agreed_stop(const Distributed& group, const std::atomic<int>* stop);

struct TrainingLoop {
  std::string label;  // of the progress line
  int64_t total_steps = 0;
  int checkpoint_every = 10;  // iterations
  std::string csv_path;       // metrics.csv: `columns`, a row per iteration (rank 0)
  std::vector<std::string> columns;
  const Distributed* group = &Distributed::alone();
  const std::atomic<int>* stop = nullptr;  // set by a signal: checkpoint and return
};

// From (start_iteration, start_step), a resumed run's or 0: iterate() takes one iteration
// and fills its metrics row, save() writes the checkpoint. Rows past start_iteration in an
// existing metrics.csv (written after the checkpoint resumed from) are dropped first, so a
// kill loses or doubles no row. Returns 0 once total_steps are done, else agreed_stop's
// signal number.
int run_training_loop(const TrainingLoop& loop, int64_t start_iteration, int64_t start_step,
                      const std::function<IterationStats(std::vector<double>& row)>& iterate,
                      const std::function<void()>& save);

}  // namespace segue
