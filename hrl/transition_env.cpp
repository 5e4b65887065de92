#include "hrl/transition_env.h"

#include <algorithm>

namespace segue {

TransitionEnv::TransitionEnv(std::unique_ptr<Env> task, StartStates starts, Transition transition, int obs_begin,
                             int obs_end)
    : task_(std::move(task)), starts_(std::move(starts)), transition_(std::move(transition)), begin_(obs_begin),
      end_(obs_end) {
  if (starts_.size() == 0) throw Error("transition environment: S_a is empty");
  spec_ = task_->spec();
  spec_.name = task_->spec().name + " (transition)";
  spec_.obs_dim = end_ - begin_;
  full_.resize(task_->spec().obs_dim);
  features_.resize(task_->spec().feature_names.size());
}

void TransitionEnv::slice(float* obs) const { std::copy(full_.begin() + begin_, full_.begin() + end_, obs); }

void TransitionEnv::reset(uint64_t seed, float* obs) {
  rng_.seed(seed);
  reset(obs);
}

void TransitionEnv::reset(float* obs) {
  int i = rng_.integer(0, starts_.size() - 1);
  starts_.state(i, state_);
  task_->restore_state(state_, full_.data());
  steps_ = 0;
  slice(obs);
}

StepResult TransitionEnv::step(const float* action, float* obs) {
  StepResult r = task_->step(action, full_.data());
  slice(obs);
  task_->features(features_.data());
  ++steps_;
  const bool left = !MetaController::holds(transition_.when, features_.data());
  if (!r.terminated && (left || transition_.capped(steps_))) r.truncated = true;  // Transition::running
  // A transition episode succeeds when it reaches the interval's end on its feet (not
  // when max_steps cut it short).
  r.info.success = left && !r.terminated;
  r.info.success_count = r.info.success;
  return r;
}

bool TransitionEnv::save_episode(std::vector<double>& state, std::string& rng) const {
  if (!task_->save_episode(state, rng)) return false;
  state.push_back(double(steps_));
  rng += "|" + rng_.state();  // one line per environment (VectorEnv::save_episodes)
  return true;
}

void TransitionEnv::restore_episode(const std::vector<double>& state, const std::string& rng, float* obs) {
  const size_t bar = rng.rfind('|');
  if (state.empty() || bar == std::string::npos) throw Error(spec_.name + ": a saved episode of another kind");
  task_->restore_episode(std::vector<double>(state.begin(), state.end() - 1), rng.substr(0, bar), full_.data());
  steps_ = int(state.back());
  rng_.set_state(rng.substr(bar + 1));
  slice(obs);
}

void TransitionEnv::restore_state(const std::vector<double>& state, float* obs) {
  task_->restore_state(state, full_.data());
  steps_ = 0;
  slice(obs);
}

}  // namespace segue
