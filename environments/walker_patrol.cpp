#include "environments/walker_patrol.h"

#include <cmath>

namespace segue {

WalkerPatrol::Config WalkerPatrol::Config::read(const Section& env) {
  Config c;
  c.stone_x = env.get("stone_x", c.stone_x, Range::positive());
  c.max_turns = env.get("max_turns", c.max_turns, Range::at_least(1));
  c.turn_bonus = env.get("turn_bonus", c.turn_bonus, Range::non_negative());
  c.min_pass_speed = env.get("min_pass_speed", c.min_pass_speed, Range::non_negative());
  c.max_leg_steps = env.get("max_leg_steps", c.max_leg_steps, Range::non_negative());
  c.speed_weight = env.get("speed_weight", c.speed_weight, Range::non_negative());
  c.height_weight = env.get("height_weight", c.height_weight, Range::non_negative());
  return c;
}

WalkerPatrol::WalkerPatrol(const std::string& name, const WalkerConfig& w, const Config& c)
    : WalkerEnv(name, w, "walker/walker_patrol.xml"), pcfg_(c) {
  spec_.obs_dim = kBaseObsDim + 1;
  spec_.feature_names = {"direction", "since_turn", "progress", "steps", "distance"};
}

void WalkerPatrol::reset_task() {
  direction_ = rng_.bernoulli(0.5) ? 1 : -1;
  turns_ = 0;
  since_turn_ = 0;
  WalkerEnv::reset_task();
  turn_x_ = start_x_ = torso_x();
}

void WalkerPatrol::features(double* out) const {
  out[0] = direction_;
  out[1] = turns_ > 0 ? since_turn_ : 1e6;
  out[2] = direction_ * (torso_x() - turn_x_);
  out[3] = t_;
  out[4] = std::abs(torso_x() - start_x_);
}

StepResult WalkerPatrol::evaluate(const float* action) {
  StepResult r;
  double v = x_velocity();
  r.reward = walk_reward(direction_ * v, action, pcfg_.speed_weight, pcfg_.height_weight);
  ++since_turn_;
  bool too_slow = false;
  if (direction_ * torso_x() > pcfg_.stone_x && direction_ * v < pcfg_.min_pass_speed) {
    too_slow = true;
  } else if (direction_ * torso_x() > pcfg_.stone_x) {  // passed the target stone
    ++turns_;
    r.reward += pcfg_.turn_bonus;
    direction_ = -direction_;
    since_turn_ = 0;
    turn_x_ = torso_x();
  }
  const bool leg_too_long = pcfg_.max_leg_steps > 0 && since_turn_ >= pcfg_.max_leg_steps;
  r.terminated = fallen() || turns_ >= pcfg_.max_turns || too_slow || leg_too_long;
  r.info.success = turns_ >= pcfg_.max_turns;
  r.info.success_count = turns_;
  r.info.metrics[0] = v;
  return r;
}

void WalkerPatrol::observe(float* obs) const {
  WalkerEnv::observe(obs);
  obs[kBaseObsDim] = static_cast<float>(direction_ * pcfg_.stone_x - torso_x());
}

void WalkerPatrol::save_task_state(std::vector<double>& out) const {
  out.insert(out.end(), {double(direction_), double(turns_), double(since_turn_), turn_x_, start_x_});
}

void WalkerPatrol::restore_task_state(const double* in, size_t n) {
  if (n < 5) throw Error(spec_.name + ": saved state lacks the patrol state");
  direction_ = int(in[0]);
  turns_ = int(in[1]);
  since_turn_ = int(in[2]);
  turn_x_ = in[3];
  start_x_ = in[4];
}

}  // namespace segue
