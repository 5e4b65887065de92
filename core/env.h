#pragma once
// The environment API. Like EnvPool's env spec: each task declares its shapes up front,
// and step() writes into caller-owned buffers so a rollout allocates nothing per step.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace segue {

struct EnvSpec {
  std::string name;
  int obs_dim = 0;
  int act_dim = 0;
  std::vector<float> act_low, act_high;   // action bounds in the environment's units
  int max_episode_steps = 1000;           // truncation horizon
  std::vector<std::string> metric_names;  // per-step task metrics reported in StepInfo
  // Named quantities of the task state that a meta-controller reads to pick a skill and
  // to detect transition intervals (e.g. "curb_ahead": metres to the next curb).
  std::vector<std::string> feature_names;
};

constexpr int kMaxMetrics = 4;

struct StepInfo {
  bool success = false;  // the task's success rule fired (stays true once fired)
  int success_count = 0; // successes so far this episode (composite tasks count several)
  std::array<double, kMaxMetrics> metrics{};  // values for EnvSpec::metric_names
};

struct StepResult {
  double reward = 0.0;
  bool terminated = false;  // a true end (fall, contact): no bootstrapping past it
  bool truncated = false;   // the time limit: the value of the next state still counts
  StepInfo info;
  bool done() const { return terminated || truncated; }
};

class Env {
 public:
  virtual ~Env() = default;
  virtual const EnvSpec& spec() const = 0;
  // Starts an episode with a fresh random stream drawn from `seed`.
  virtual void reset(uint64_t seed, float* obs) = 0;
  // Starts an episode continuing the environment's own random stream.
  virtual void reset(float* obs) = 0;
  virtual StepResult step(const float* action, float* obs) = 0;
  // Current values of spec().feature_names, in order.
  virtual void features(double* out) const {}

  // Exact snapshot of everything the next step depends on (physics, task layout, step
  // counter), flattened to doubles so it can be stored in files. Restoring a snapshot
  // and stepping reproduces the original run bit for bit; the transition method starts
  // its episodes from such snapshots of pi_a.
  virtual void save_state(std::vector<double>& out) const = 0;
  virtual void restore_state(const std::vector<double>& state, float* obs) = 0;

  // The episode in flight, for a resume that loses nothing: the snapshot above and the
  // environment's random stream. False where an environment cannot say (a wrapper that
  // holds a controller); a resumed run then starts a fresh episode there.
  virtual bool save_episode(std::vector<double>& state, std::string& rng) const { return false; }
  virtual void restore_episode(const std::vector<double>& state, const std::string& rng, float* obs) {}
};

}  // namespace segue
