#pragma once
// The Patrol task (task `patrol`, assets/walker/walker_patrol.xml): the walker walks back
// and forth between two stones. experiments/patrol.yaml composes it from the walker's
// forward, backward and balance skills.
#include <string>
#include <vector>

#include "environments/walker.h"

namespace segue {

// Patrol: touch the stones at +-stone_x alternately. A turn counts when the torso passes
// the target stone in the current direction; the direction then flips. Starts in a
// random direction. Observation: the 26 walker numbers + (target stone x - torso x).
// Optionally the reference code's speed and leg-length rules (Config).
class WalkerPatrol : public WalkerEnv {
 public:
  struct Config {
    double stone_x = 2.0;
    int max_turns = 5;
    double turn_bonus = 10.0;
    // The reference code's rules (off by default, as in the paper's text and our tables):
    // a stone passed slower than this ends the episode, the turn not counted (its value 2
    // m/s); a leg (from the start or a turn to the next turn) of more control steps ends it (800).
    double min_pass_speed = 0.0;
    int max_leg_steps = 0;  // 0: no limit
    // The speed and height terms' weights (the reference's Patrol reward, which its Single
    // baseline trains on, doubles both, with turn_bonus 100). Defaults: ours.
    double speed_weight = 1.0, height_weight = 1.0;
    static Config read(const Section& env);
  };
  WalkerPatrol(const std::string& name, const WalkerConfig& w, const Config& c);

  // Features: direction (+1 / -1), since_turn (control steps since the last turn, far
  // before the first), progress (metres walked in the current direction since the turn),
  // steps (since the episode start), distance (|torso x - its start x|).
  void features(double* out) const override;
  int direction() const { return direction_; }
  int turns() const { return turns_; }

 protected:
  void reset_task() override;
  StepResult evaluate(const float* action) override;
  void observe(float* obs) const override;
  void save_task_state(std::vector<double>& out) const override;
  void restore_task_state(const double* in, size_t n) override;

 private:
  Config pcfg_;
  int direction_ = 1, turns_ = 0, since_turn_ = 0;
  double turn_x_ = 0.0, start_x_ = 0.0;
};

}  // namespace segue
