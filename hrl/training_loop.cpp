#include "hrl/training_loop.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/progress.h"
#include "core/run_dir.h"

namespace segue {

int signal_of(const std::atomic<int>* stop) { return stop ? stop->load() : 0; }

int agreed_stop(const Distributed& group, const std::atomic<int>* stop) {
  return group.any(signal_of(stop) != 0) ? std::max(signal_of(stop), 1) : 0;
}

int run_training_loop(const TrainingLoop& loop, int64_t start_iteration, int64_t start_step,
                      const std::function<IterationStats(std::vector<double>& row)>& iterate,
                      const std::function<void()>& save) {
  const Distributed& group = *loop.group;
  std::optional<MetricsCsv> csv;
  std::optional<Progress> progress;
  if (group.leader()) {
    csv.emplace(loop.csv_path, loop.columns, start_iteration);
    progress.emplace(loop.label, loop.total_steps, start_step);
  }
  double recent_return = NAN, recent_success = NAN;
  std::vector<double> row;
  for (int64_t step = start_step; step < loop.total_steps;) {
    row.clear();
    const IterationStats it = iterate(row);
    step = it.global_step;
    if (it.episodes > 0) recent_return = it.episode_return, recent_success = it.success_rate;
    if (csv) csv->write(row);
    const bool last = step >= loop.total_steps;
    const int stop = agreed_stop(group, loop.stop);
    if (last || stop || it.iteration % loop.checkpoint_every == 0) save();
    if (progress) progress->update(step, recent_return, recent_success);
    if (stop && !last) return stop;
  }
  return 0;
}

}  // namespace segue
