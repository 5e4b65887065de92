#pragma once
// The arm's composite tasks (docs/reference/tasks.md#arm-tasks): the sub-tasks' rules run again and
// again, or in sequence. Each declares the features its transition intervals are written in;
// the recipes (experiments/<task>.yaml) say which skill runs where.
#include "environments/jaco_skills.h"

namespace segue {

// Repetitive picking up: pick the box and hold it 50 steps, `successes` times. After each
// success the box is put back on its tile (fresh noise) and the pick starts over.
// Ends on a drop, when one pick takes pick_steps steps, or at the last success. With
// unwind_arm the arm's unlimited joints are unwound at each success (docs/jaco.md).
// Features: steps, object_z, successes, since_success (steps since the last success; far
// before the first), pick_steps (steps into the current pick).
class JacoRepetitivePick : public JacoEnv {
 public:
  struct Config {
    int successes = 5;
    int pick_steps = 200;  // the pick's own time limit (its time bonus counts down from it)
    bool unwind_arm = false;  // true: each success also unwinds the arm (JacoEnv::unwind_arm); the reference: no
    PickRule::Config pick;
    static Config read(const Section& env);
  };
  JacoRepetitivePick(const std::string& name, const JacoConfig& c, const Config& k);
  void features(double* out) const override;

 protected:
  void place_task_object() override;
  void begin_task() override;
  StepResult score(const float* action) override;
  void save_task_state(std::vector<double>& out) const override;
  void restore_task_state(const double* in, size_t n) override;

 private:
  struct Count {
    double successes = 0, since_success = 0, pick_t = 0;
  };
  Config k_;
  PickRule pick_;
  Count n_;
};

// Repetitive catching: catch the thrown box and hold it 50 (cumulative) steps, `successes`
// times. After each success the box goes back to its start, is held there for pin_steps
// steps, falls freely for fall_steps and is thrown. Ends on the first drop or at the last
// success. The reference throws from rest (fall_steps 0, and no random steps before the
// first throw), where its Catch sub-task throws after 10 random steps of free fall; our
// default throws every box as the Catch sub-task does (see docs/jaco.md). With unwind_arm
// the arm's unlimited joints are unwound at each success, as in Repetitive picking.
// Features: steps, object_z, successes, since_success (far before the first), since_throw
// (steps since the last throw), waiting (1 from a success to the next throw).
class JacoRepetitiveCatch : public JacoEnv {
 public:
  struct Config {
    int successes = 5;
    int pin_steps = 49;
    int fall_steps = 10;
    bool unwind_arm = false;  // true: each success also unwinds the arm (JacoEnv::unwind_arm); the reference: no
    CatchRule::Config catching;  // its hold target is KeepCatch's, (0, 0.2, 0.2), not Catch's
    static Config read(const Section& env);
  };
  JacoRepetitiveCatch(const std::string& name, const JacoConfig& c, const Config& k);
  void features(double* out) const override;

 protected:
  void place_task_object() override;
  void begin_task() override;
  void after_random_steps() override;
  StepResult score(const float* action) override;
  void save_task_state(std::vector<double>& out) const override;
  void restore_task_state(const double* in, size_t n) override;

 private:
  struct Count {
    double successes = 0, since_success = 0, since_throw = 0, wait = 0;  // wait: steps since the success, to the throw
  };
  Config k_;
  CatchRule catch_;
  Count n_;
};

// Serve: toss the ball up, then hit it on its way down into the target on the wall. The
// toss's rule runs until the hit (its landing not judged); the first time the falling ball
// passes below judge_height or is hit, the toss is judged (+toss_bonus when it came down
// within toss_tolerance of the toss spot); the hit's rule runs once the ball falls from a
// good apex. Success (1 of 1) at the target.
// Features: steps, object_z, since_release (steps since the ball first rose above the
// release height; far before), falling (1 after a good apex), judged (1 once the toss is
// judged), hit (1 after the hit).
class JacoServe : public JacoEnv {
 public:
  struct Config {
    double judge_height = 0.9;
    double toss_bonus = 100.0;
    double toss_tolerance = 0.1;
    TossRule::Config toss;
    HitRule::Config hit;
    static Config read(const Section& env);
  };
  JacoServe(const std::string& name, const JacoConfig& c, const Config& k);
  void features(double* out) const override;

 protected:
  void place_task_object() override;
  void begin_task() override;
  StepResult score(const float* action) override;
  void save_task_state(std::vector<double>& out) const override;
  void restore_task_state(const double* in, size_t n) override;

 private:
  struct Count {
    double since_release = 0, judged = 0;
  };
  Config k_;
  TossRule toss_;
  HitRule hit_;
  Count n_;
};

}  // namespace segue
