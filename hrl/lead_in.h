#pragma once
// A skill's training episodes may begin where another skill hands over to it. The
// lead-in skill (the walk, for the jump) acts from the task's start until it has passed
// through the `when` interval; the episode then goes on from one of the states it was in
// inside the interval, drawn uniformly. Those are the states a skill meets in a composite
// task when the skill before it hands over directly (Without TP, or With TP + Q switching
// early), and training on its own task alone never shows them. A skill recipe asks for it
// with
//
//   lead_in: {policy: assets/policies/walker/walker_forward.pt, when: {curb_ahead: [3, 4]},
//             share: 0.5}
//
// `when` ranges over the training task's features (as a composite recipe's intervals);
// `share` is the fraction of episodes that begin so, the rest begin at the task's start.
// The skill's evaluation keeps the task's own start.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "algorithms/policy.h"
#include "core/recipe.h"
#include "core/rng.h"
#include "hrl/meta_controller.h"

namespace segue {

struct LeadIn {
  std::string policy_path;
  Policy policy;  // deterministic, on the first policy.obs_dim() numbers of the observation
  std::vector<Condition> when;
  double share = 1.0;
  // Reads the `lead_in:` section against the task it will run in; errors name the key.
  static LeadIn read(const Section& s, const EnvSpec& task);
};

class LeadInEnv : public Env {
 public:
  LeadInEnv(std::unique_ptr<Env> task, LeadIn lead_in);
  const EnvSpec& spec() const override { return task_->spec(); }
  void reset(uint64_t seed, float* obs) override;
  void reset(float* obs) override;
  StepResult step(const float* action, float* obs) override { return task_->step(action, obs); }
  void features(double* out) const override { task_->features(out); }
  void save_state(std::vector<double>& out) const override { task_->save_state(out); }
  void restore_state(const std::vector<double>& state, float* obs) override { task_->restore_state(state, obs); }
  // The lead-in's steps before the current episode's first state (0: the task's start).
  int lead_in_steps() const { return lead_in_steps_; }

  // A lead-in whose episodes end before its interval is retried on a fresh start this
  // many times, then refused (it never reaches where it should hand over).
  static constexpr int kAttempts = 100;

 private:
  void begin(float* obs);
  bool run_lead_in(float* obs);  // false: it fell, or the episode ended, before the interval
  std::unique_ptr<Env> task_;
  LeadIn lead_in_;
  Rng rng_;
  int lead_in_steps_ = 0;
  std::vector<float> action_;
  std::vector<double> features_;
  std::vector<std::vector<double>> inside_;  // states passed through inside the interval
  std::vector<int> inside_steps_;
};

// make_env's environments wrapped in the lead-in (each with its own copy of the policy).
std::function<std::unique_ptr<Env>()> with_lead_in(std::function<std::unique_ptr<Env>()> make_env, LeadIn lead_in);

}  // namespace segue
