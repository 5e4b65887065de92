#pragma once
// The planar walker (assets/walker/walker.xml) and what every walker task shares: the
// 26-number observation, the reference reward terms, the randomised start and the
// random pushes. Reference values come from docs/reference/walker.md and can be
// changed from a recipe's `env:` section.
#include <cmath>

#include "core/mujoco_env.h"
#include "core/recipe.h"

namespace segue {

struct WalkerConfig {
  int max_episode_steps = 1000;
  int success_steps = 1000;     // surviving this long is a success
  double init_noise = 0.01;     // qpos, qvel + U(init_noise) at the start
  int init_random_steps = 5;    // then this many uniformly random actions
  double push_prob = 0.2;       // chance per control step of a push on a random body
  double push_force = 100.0;    // horizontal push force ~ U(push_force) newtons
  double fall_height = 0.8;     // torso z below this ends the episode
  // Reward terms (docs/reference/walker.md#reward-terms).
  double target_speed = 3.0;    // v' = target - |v - target|
  double height_target = 1.1;   // -|height_target - delta_h|
  double upright_weight = 0.1;  // + upright_weight cos(pitch)
  double alive_bonus = 1.0;
  double foot_cost = 0.01;      // - foot_cost (|foot joint velocities| summed)
  double ctrl_cost = 1e-3;      // - ctrl_cost |a|^2

  // Reads `env`, starting from `defaults` (each task has its own reference values).
  static WalkerConfig read(const Section& env, WalkerConfig defaults);
  static WalkerConfig read(const Section& env) { return read(env, WalkerConfig()); }
};

class WalkerEnv : public MujocoEnv {
 public:
  static constexpr int kBaseObsDim = 26;
  WalkerEnv(const std::string& name, const WalkerConfig& config,
            const std::string& model_file = "walker/walker.xml");

  double torso_x() const { return data_->qpos[qx_]; }
  double torso_z() const { return data_->qpos[qz_]; }
  double pitch() const { return data_->qpos[qpitch_]; }
  // Torso height above the higher foot: the reference's delta_h.
  double delta_h() const;
  // Smallest x of torso and feet: obstacle distances are measured from it.
  double min_x() const;
  // The trailing foot's x: the reference rewards crossing points "with the lowest foot".
  double trailing_foot_x() const;
  // Torso vertical velocity.
  double z_velocity() const { return data_->qvel[qz_]; }
  bool fallen() const { return torso_z() < cfg_.fall_height; }

 protected:
  void reset_task() override;
  void before_physics() override;
  void observe(float* obs) const override;
  // Shared terms: upright + alive - foot - ctrl (velocity and height terms are per task).
  double posture_terms(const float* action) const;
  // v' = target - |v - target| for a velocity measured along the task's direction.
  static double speed_term(double v, double target) { return target - std::abs(v - target); }
  // Forward velocity over the last control step.
  double x_velocity() const { return (torso_x() - x_before_) / control_dt(); }

  WalkerConfig cfg_;
  // Forward-velocity, height and posture terms shared by walk-like rewards:
  //   speed_weight v' + upright + alive - height_weight |h* - dh| - foot - ctrl.
  double walk_reward(double v, const float* action, double speed_weight, double height_weight) const;
  // The result of a step in a "survive success_steps steps" task.
  StepResult survival_step(double reward, bool ended) const;

  double x_before_ = 0.0;
  int qx_, qz_, qpitch_;
  int foot_, foot_left_, torso_;
  int foot_dof_, foot_left_dof_;
};

// Walk forward (direction +1) or backward (-1): survive success_steps steps.
class WalkerWalk : public WalkerEnv {
 public:
  WalkerWalk(const std::string& name, const WalkerConfig& config, double direction);

 protected:
  StepResult evaluate(const float* action) override;

 private:
  double direction_;
};

}  // namespace segue
