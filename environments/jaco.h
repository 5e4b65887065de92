#pragma once
// The Kinova Jaco arm (assets/jaco/) and what every arm task shares: the observation, the
// hand position, the in-hand / in-air tests, the control cost, the randomised start and the
// catch throw. Facts and reference values from docs/reference/jaco.md; every number can be
// changed from a recipe's `env:` section.
#include <array>

#include "core/mujoco_env.h"
#include "core/recipe.h"

namespace segue {

using Vec3 = std::array<double, 3>;
double distance(const Vec3& a, const Vec3& b);

struct JacoConfig {
  int max_episode_steps = 200;
  double init_noise = 0.01;    // arm qpos, qvel + U(init_noise) at the start
  int init_random_steps = 10;  // then this many uniformly random actions, not counted
  // Control cost (docs/reference/jaco.md#control-cost): ctrl_cost sum a^2 + qvel_cost
  // mean|qvel| + qacc_cost mean|qacc|, the means over all 15 DoF, the object's included.
  double ctrl_cost = 1e-4;
  double qvel_cost = 1e-8;
  double qacc_cost = 1e-8;

  static JacoConfig read(const Section& env, JacoConfig defaults);
};

// Reads a 3-vector key (e.g. `hold_target: [0.5, 0.2, 0.2]`), refusing other lengths.
Vec3 read_vec3(const Section& env, const std::string& key, const Vec3& fallback);

class JacoEnv : public MujocoEnv {
 public:
  static constexpr int kArmDof = 9;     // j1..j6, three fingers
  static constexpr int kArmJoints = 6;  // j1..j6: hinges without limits
  // with_rotation: observe the object's quaternion and angular velocity (pick and catch:
  // 49 numbers); without (toss and hit: 39).
  JacoEnv(const std::string& name, const JacoConfig& config, const std::string& model_file,
          bool with_rotation);

  // The reference's hand position: the mean of the palm's and three fingers' geom centres.
  Vec3 hand_pos() const;
  Vec3 object_pos() const;
  Vec3 object_velocity() const;  // world frame
  double object_z() const { return data_->qpos[object_qpos_ + 2]; }
  double hand_object_distance() const { return distance(hand_pos(), object_pos()); }
  bool in_hand(double threshold) const { return hand_object_distance() < threshold; }
  bool in_air(double threshold) const { return object_z() > threshold; }

  // Puts the object at `pos`, its quaternion (1, 0, 0, 0) + U(quat_noise) per component
  // (not renormalised, as the reference), its six velocities U(vel_noise).
  void place_object(const Vec3& pos, double quat_noise, double vel_noise);
  // The catch throw: `force` newtons on the object along the unit vector to the base's
  // centre + aim, held for one control step while the arm takes a random action.
  void throw_object(double force, const Vec3& aim);
  // Moves a static geom of this environment's model copy (the hit's target).
  void move_geom(const char* name, const Vec3& pos);
  // Holds the object where it is, at rest (Repetitive catching pins the next box).
  void pin_object(const Vec3& pos);
  // Turns each of j1..j6 by whole turns to the angle in [-pi, pi]: the same pose (these
  // hinges have no limits, springs or position servos), with the raw angles of a fresh
  // start. The arm's skills turn the wrist a turn or two per pick or catch, so without this
  // every cycle of a repetitive task starts them from angles they never saw.
  void unwind_arm();

  // Features (what transition intervals and expert windows are written in): steps (since
  // the episode start), object_z; a task appends its own after these kArmFeatures.
  static constexpr int kArmFeatures = 2;
  void features(double* out) const override;

 protected:
  void reset_task() final;
  StepResult evaluate(const float* action) final;
  void observe(float* obs) const override;

  // Places the object for a new episode; the arm already has its start noise.
  virtual void place_task_object() = 0;
  // Called after placement and before the random steps: the task's bookkeeping.
  virtual void begin_task() = 0;
  // Called after the random steps (the catch throws its box here).
  virtual void after_random_steps() {}
  // Scores the step that just ran (positions are current: evaluate() refreshed them).
  virtual StepResult score(const float* action) = 0;

  // The shared control cost (a negative reward).
  double control_cost(const float* action) const;
  void random_steps(int n);

  JacoConfig cfg_;
  bool with_rotation_;
  int object_body_, object_qpos_, object_dof_;
  int base_geom_;
  std::array<int, 4> hand_geoms_;
  std::vector<float> random_action_;
};

// A task's bookkeeping as structs of doubles, so snapshots can copy them whole.
template <class State>
constexpr size_t state_size() {
  static_assert(sizeof(State) % sizeof(double) == 0, "task state must be doubles only");
  return sizeof(State) / sizeof(double);
}
template <class... State>
void append_state(std::vector<double>& out, const State&... s) {
  (out.insert(out.end(), reinterpret_cast<const double*>(&s), reinterpret_cast<const double*>(&s) + state_size<State>()),
   ...);
}
template <class... State>
void read_state(const double* in, size_t n, const std::string& task, State&... s) {
  const size_t want = (state_size<State>() + ...);
  if (n != want)
    throw Error(task + ": a saved state with " + std::to_string(n) + " task numbers, expected " + std::to_string(want));
  ((std::copy(in, in + state_size<State>(), reinterpret_cast<double*>(&s)), in += state_size<State>()), ...);
}

}  // namespace segue
