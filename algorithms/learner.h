#pragma once
// What `segue train` needs of any learner: iterate, report, checkpoint, export. PPO and
// TRPO (algorithms/on_policy.h) and SAC (algorithms/sac.h) implement it.
#include <cmath>
#include <string>
#include <vector>

#include "algorithms/policy.h"

namespace segue {

// One iteration's report: the episodes that ended in it, in the task's own units, and
// the learner's update diagnostics (each learner fills its own, update_columns() says which).
struct IterationStats {
  int64_t iteration = 0, global_step = 0;
  int episodes = 0;                 // episodes finished during the iteration
  double episode_return = NAN, episode_length = NAN, success_rate = NAN, success_count = NAN;
  double policy_loss = 0, value_loss = 0, entropy = 0, approx_kl = 0;
  double clip_fraction = 0;         // PPO: rows whose ratio was clipped
  double step_size = 0;             // TRPO: the accepted fraction of the natural step (0: none)
  double alpha = 0, q_mean = 0;     // SAC: the entropy temperature, the mean Q of the batch
  double rollout_seconds = 0, update_seconds = 0;
  double comm_seconds = 0;          // of those, inside collectives with the other ranks
};

class Learner {
 public:
  virtual ~Learner() = default;
  virtual const std::string& name() const = 0;  // "ppo", "trpo" or "sac"
  virtual IterationStats iterate() = 0;
  // The metrics.csv columns the learner's update fills, and their values.
  virtual std::vector<std::string> update_columns() const = 0;
  virtual std::vector<double> update_values(const IterationStats& s) const = 0;
  // The deterministic policy (mean action), as exported.
  virtual Policy policy() const = 0;
  virtual int64_t iteration() const = 0;
  virtual int64_t global_step() const = 0;
  virtual double wall_seconds() const = 0;  // training time, across resumes
  // A checkpoint holds everything an exact resume needs. load() with `resume` puts a run
  // back as it was; without, it continues another run's networks (init_from).
  virtual void save(const std::string& path, const std::string& note) const = 0;
  virtual void load_checkpoint(const std::string& path, bool resume) = 0;
};

}  // namespace segue
