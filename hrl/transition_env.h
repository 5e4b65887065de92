#pragma once
// The environment a transition policy pi_ab trains in (Algorithm 1, lines 8-9): each
// episode starts from a state sampled from S_a and runs while the transition interval
// holds (Transition::running). Leaving the interval ends the episode as a time limit
// (truncated: pi_b takes over from there); the task ending (a fall) ends it for real.
// pi_ab sees pi_b's slice of the task observation, the space its discriminator compares
// with T_b.
#include <memory>

#include "core/rng.h"
#include "hrl/collection.h"
#include "hrl/meta_controller.h"

namespace segue {

class TransitionEnv : public Env {
 public:
  TransitionEnv(std::unique_ptr<Env> task, StartStates starts, Transition transition, int obs_begin, int obs_end);
  const EnvSpec& spec() const override { return spec_; }
  void reset(uint64_t seed, float* obs) override;
  void reset(float* obs) override;
  StepResult step(const float* action, float* obs) override;
  void features(double* out) const override { task_->features(out); }
  void save_state(std::vector<double>& out) const override { task_->save_state(out); }
  void restore_state(const std::vector<double>& state, float* obs) override;
  // The task's episode, then this wrapper's step count and start-drawing stream: a
  // resumed transition stage goes on with the episodes in flight.
  bool save_episode(std::vector<double>& state, std::string& rng) const override;
  void restore_episode(const std::vector<double>& state, const std::string& rng, float* obs) override;
  Env& task() { return *task_; }
  // The task's whole observation after the last reset or step (pi_ab sees a slice of it).
  const std::vector<float>& task_obs() const { return full_; }

 private:
  void slice(float* obs) const;
  std::unique_ptr<Env> task_;
  StartStates starts_;
  Transition transition_;
  int begin_, end_, steps_ = 0;
  EnvSpec spec_;
  Rng rng_;
  std::vector<float> full_;
  std::vector<double> features_, state_;
};

}  // namespace segue
