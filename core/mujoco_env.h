#pragma once
// The MuJoCo environment base: loads an MJCF model from assets/, applies an action for
// frame_skip physics steps, and snapshots/restores the full simulator state. A task is
// a small subclass: how an episode starts, what it observes, how a step is scored.
#include <mujoco/mujoco.h>

#include <string>
#include <vector>

#include "core/env.h"
#include "core/rng.h"

namespace segue {

// Routes MuJoCo's errors into segue::Error and its warnings to stderr (once per process;
// every MujocoEnv calls it).
void install_mujoco_handlers();

class MujocoEnv : public Env {
 public:
  MujocoEnv(const std::string& model_file, int frame_skip);
  ~MujocoEnv() override;
  MujocoEnv(const MujocoEnv&) = delete;
  MujocoEnv& operator=(const MujocoEnv&) = delete;

  const EnvSpec& spec() const override { return spec_; }
  void reset(uint64_t seed, float* obs) override;
  void reset(float* obs) override;
  StepResult step(const float* action, float* obs) override;
  void save_state(std::vector<double>& out) const override;
  void restore_state(const std::vector<double>& state, float* obs) override;
  bool save_episode(std::vector<double>& state, std::string& rng) const override;
  void restore_episode(const std::vector<double>& state, const std::string& rng, float* obs) override;

  const mjModel* model() const { return model_; }
  const mjData* data() const { return data_; }
  mjData* mutable_data() { return data_; }
  int frame_skip() const { return frame_skip_; }
  int episode_step() const { return t_; }
  double control_dt() const { return model_->opt.timestep * frame_skip_; }
  // mj_step calls since construction, resets included (for throughput accounting).
  int64_t physics_steps() const { return physics_steps_; }
  // Recomputes derived quantities (positions, contacts) after the state was edited by hand,
  // e.g. by a test that places the walker somewhere. Refreshes the observation.
  void forward(float* obs);

 protected:
  // Sets the initial physics state; data_ was just reset to the model's reference pose.
  virtual void reset_task() = 0;
  // Called once per control step before the physics runs (pushes, scripted events).
  virtual void before_physics() {}
  // Scores the step that just ran. `action` is the clipped action that was applied.
  virtual StepResult evaluate(const float* action) = 0;
  virtual void observe(float* obs) const = 0;
  // Task state beyond mjData (obstacle layout, counters), appended to snapshots.
  virtual void save_task_state(std::vector<double>& out) const {}
  virtual void restore_task_state(const double* in, size_t n) {}

  // Runs the physics for one control step with the given (already clipped) controls.
  void simulate(const float* ctrl);
  int body_id(const char* name) const;
  int joint_qpos(const char* name) const;

  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
  EnvSpec spec_;
  Rng rng_;
  int frame_skip_;
  int t_ = 0;
  int64_t physics_steps_ = 0;
  std::vector<float> clipped_;  // scratch for the clipped action
};

}  // namespace segue
