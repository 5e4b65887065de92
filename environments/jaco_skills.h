#pragma once
// The arm's four sub-tasks (docs/reference/jaco.md#sub-tasks): pick, catch, toss, hit. Each
// rule is a small struct (its settings, its bookkeeping, one step of scoring) so that the
// composite tasks, which run the same rules in sequence or repeatedly, reuse them unchanged.
// Every rule offers JacoSkill, which runs one alone, the same calls:
//   place(env, rng)               the object for a new episode
//   begin(env)                    fresh bookkeeping, before the random steps
//   after_random_steps(env, rng)  what follows them (the catch's throw)
//   step(env)                     one step's reward, success and failure
//   feature_names(), write_features(out)  the features it adds to the arm's
#include <string>
#include <vector>

#include "environments/jaco.h"

namespace segue {

// What one step of a rule decided, beside the reward it added.
struct RuleStep {
  double reward = 0.0;
  bool success = false;
  bool failed = false;
};

// The calls most rules need nothing for.
struct ArmRule {
  void after_random_steps(JacoEnv&, Rng&) const {}
  static std::vector<std::string> feature_names() { return {}; }
  void write_features(double*) const {}
};

// Pick: lift the box and hold it in the air for hold_steps steps.
struct PickRule : ArmRule {
  struct Config {
    double in_hand = 0.06, in_air = 0.05;
    Vec3 tile{0.5, 0.2, 0.03};   // the box starts at tile + (U(0, tile_size), U(0, tile_size), 0)
    double tile_size = 0.1;
    double quat_noise = 0.01, vel_noise = 0.01;
    double guide_weight = 2.0;   // 2 (previous - current |hand - box|) until picked
    double lift_weight = 100.0;  // 100 (min(lift_cap, z) - best height so far), when positive
    double lift_cap = 0.3;
    double hold_height = 0.3;    // the hold target is (box x, box y, hold_height) at placement
    double hold_weight = 2.0;    // 2 (1 - |target - box|) on each held step
    int hold_steps = 50;
    double time_bonus = 1.0;     // time_bonus (max_steps - t) at success
    static Config read(const Section& env);
  };
  struct State {
    double prev_dist = 0, pick_height = 0, held = 0, picked = 0;
    Vec3 target{0, 0, 0};
  };
  Config cfg;
  State s;

  void place(JacoEnv& env, Rng& rng) const;
  void begin(const JacoEnv& env);
  // t: steps since the pick began; max_steps: its time limit.
  RuleStep step(const JacoEnv& env, int t, int max_steps);
  // Alone, the pick's clock is the episode's.
  RuleStep step(const JacoEnv& env) { return step(env, env.episode_step(), env.spec().max_episode_steps); }
};

// Catch: the box is thrown at the arm; hold it in the air for hold_steps steps (cumulative).
struct CatchRule : ArmRule {
  struct Config {
    double in_hand = 0.06, in_air = 0.05, on_ground = 0.05;
    Vec3 start{0.0, 2.0, 1.5};
    double quat_noise = 0.01;
    double throw_force = 110.0;          // newtons, for one control step
    Vec3 aim{0.4, 0.3, 1.0};             // aim = base centre + aim + (U(0, aim_spread), U(0, aim_spread), 0)
    double aim_spread = 0.1;
    double catch_bonus = 100.0;          // per held step
    double hold_weight = 4.0;            // 4 (1 - |hold_target - box|) per held step
    Vec3 hold_target{0.5, 0.2, 0.2};
    int hold_steps = 50;
    static Config read(const Section& env, const Vec3& hold_target = {0.5, 0.2, 0.2});
  };
  struct State {
    double held = 0;
  };
  Config cfg;
  State s;

  void place(JacoEnv& env, Rng& rng) const;
  // Repetitive catching holds the next box at the start, at rest, until it is thrown.
  void pin_at_start(JacoEnv& env) const { env.pin_object(cfg.start); }
  void throw_box(JacoEnv& env, Rng& rng) const;
  void begin(const JacoEnv&) { s = State(); }
  // The box falls during the random steps, and is then thrown.
  void after_random_steps(JacoEnv& env, Rng& rng) const { throw_box(env, rng); }
  RuleStep step(const JacoEnv& env);
};

// Toss: pick the ball up, throw it from below release_height so it peaks at apex_height,
// and let it come back down within land_tolerance of (land_x, land_y).
struct TossRule : ArmRule {
  struct Config {
    double in_hand = 0.10, in_air = 0.07;
    Vec3 start{0.4, 0.3, 0.04};
    double start_noise = 0.04, vel_noise = 0.005;
    double guide_weight = 100.0;    // 100 (previous - current |hand - ball top|) before the pick
    double lift_weight = 200.0;     // 200 (min(z, release_height) - best height so far)
    double release_height = 0.7;
    double release_bonus = 50.0;
    double stable_weight = 2.0;     // -2 (|x - land_x| + |y - land_y| - stable_slack) while picked
    double stable_slack = 0.5;
    double land_x = 0.4, land_y = 0.3;
    double apex_height = 2.0;
    double apex_weight = 50.0;      // 50 (1 - |apex - z| / apex) where the ball stops rising
    double apex_tolerance = 0.1;
    double apex_bonus = 50.0;
    double land_tolerance = 0.1;
    double success_bonus = 100.0;
    static Config read(const Section& env);
  };
  struct State {
    double prev_dist = 0, pick_height = 0, picked = 0, released = 0, falling = 0, prev_z = 0;
    Vec3 ball_top{0, 0, 0};
  };
  Config cfg;
  State s;
  // Serve judges the toss when the ball comes down to the hit instead
  // (docs/reference/tasks.md#serve): the
  // landing is then not scored.
  bool judge_landing = true;

  void place(JacoEnv& env, Rng& rng) const;
  void begin(const JacoEnv& env);
  RuleStep step(const JacoEnv& env);
  bool released() const { return s.released != 0; }
  bool falling() const { return s.falling != 0; }
};

// Hit: strike the falling ball at hit_height so that it flies to the target on the wall.
struct HitRule : ArmRule {
  struct Config {
    double hit_distance = 0.12, on_ground = 0.07;
    Vec3 start{0.4, 0.3, 2.0};
    double start_noise = 0.1, vel_noise = 0.1;
    double hit_height = 1.0;
    double hit_weight = 100.0;      // 100 (1 - |z - hit_height|) at the first touch
    double hit_tolerance = 0.1;     // a touch further from hit_height ends the episode
    double hit_bonus = 100.0;
    double vx_cost = 1.0;           // -|vx| after the hit
    Vec3 target{0.4, 2.0, 1.2};
    double target_radius = 0.2;
    double target_bonus = 1200.0;   // the reference's 200 + 1000
    double miss_weight = 200.0;     // on the ground after a hit: 200 (2 - closest distance) / 2
    // Not in the reference (0 there): after the hit, approach_weight (previous - current
    // distance to the target) each step, the potential-based shaping of Ng et al. (1999)
    // with the distance as potential, which leaves the best policy unchanged.
    double approach_weight = 0.0;
    static Config read(const Section& env);
  };
  struct State {
    double hit = 0, closest = 1e9, prev_x = 0, prev_to_target = 0;
  };
  Config cfg;
  State s;

  void place(JacoEnv& env, Rng& rng) const;
  // Moves the target geom to where the rule measures it (Serve, which places its own ball).
  void place_target(JacoEnv& env) const { env.move_geom("target", cfg.target); }
  void begin(const JacoEnv& env);
  RuleStep step(const JacoEnv& env);
  bool hit() const { return s.hit != 0; }
  // Feature hit: 1 after the hit, else 0.
  static std::vector<std::string> feature_names() { return {"hit"}; }
  void write_features(double* out) const { out[0] = s.hit; }
};

// A sub-task's step: the control cost and the rule's reward; it ends on the rule's success
// or failure.
StepResult skill_result(double control, const RuleStep& rs);

// A sub-task: one rule on the arm, ended by its success or failure.
template <class Rule>
class JacoSkill : public JacoEnv {
 public:
  JacoSkill(const std::string& name, const JacoConfig& c, const std::string& model, bool with_rotation,
            const typename Rule::Config& rule)
      : JacoEnv(name, c, model, with_rotation) {
    rule_.cfg = rule;
    for (const auto& f : Rule::feature_names()) spec_.feature_names.push_back(f);
  }
  const Rule& rule() const { return rule_; }
  void features(double* out) const override {
    JacoEnv::features(out);
    rule_.write_features(out + kArmFeatures);
  }

 protected:
  void place_task_object() override { rule_.place(*this, rng_); }
  void begin_task() override { rule_.begin(*this); }
  void after_random_steps() override { rule_.after_random_steps(*this, rng_); }
  StepResult score(const float* action) override { return skill_result(control_cost(action), rule_.step(*this)); }
  void save_task_state(std::vector<double>& out) const override { append_state(out, rule_.s); }
  void restore_task_state(const double* in, size_t n) override { read_state(in, n, spec_.name, rule_.s); }

 private:
  Rule rule_;
};

using JacoPick = JacoSkill<PickRule>;
using JacoCatch = JacoSkill<CatchRule>;
using JacoToss = JacoSkill<TossRule>;
using JacoHit = JacoSkill<HitRule>;

}  // namespace segue
