#include "environments/jaco_skills.h"

#include <algorithm>
#include <cmath>

namespace segue {

PickRule::Config PickRule::Config::read(const Section& e) {
  Config c;
  c.in_hand = e.get("in_hand", c.in_hand, Range::positive());
  c.in_air = e.get("in_air", c.in_air, Range::non_negative());
  c.tile = read_vec3(e, "tile", c.tile);
  c.tile_size = e.get("tile_size", c.tile_size, Range::non_negative());
  c.quat_noise = e.get("quat_noise", c.quat_noise, Range::non_negative());
  c.vel_noise = e.get("vel_noise", c.vel_noise, Range::non_negative());
  c.guide_weight = e.get("guide_weight", c.guide_weight, Range::non_negative());
  c.lift_weight = e.get("lift_weight", c.lift_weight, Range::non_negative());
  c.lift_cap = e.get("lift_cap", c.lift_cap, Range::positive());
  c.hold_height = e.get("hold_height", c.hold_height, Range::positive());
  c.hold_weight = e.get("hold_weight", c.hold_weight, Range::non_negative());
  c.hold_steps = e.get("hold_steps", c.hold_steps, Range::at_least(1));
  c.time_bonus = e.get("time_bonus", c.time_bonus, Range::non_negative());
  return c;
}

void PickRule::place(JacoEnv& env, Rng& rng) const {
  Vec3 p = cfg.tile;
  p[0] += rng.uniform(0, cfg.tile_size);
  p[1] += rng.uniform(0, cfg.tile_size);
  env.place_object(p, cfg.quat_noise, cfg.vel_noise);
}

void PickRule::begin(const JacoEnv& env) {
  s = State();
  Vec3 box = env.object_pos();
  s.target = {box[0], box[1], cfg.hold_height};
  s.prev_dist = env.hand_object_distance();
}

RuleStep PickRule::step(const JacoEnv& env, int t, int max_steps) {
  RuleStep r;
  const double d = env.hand_object_distance(), z = env.object_z();
  const bool hand = d < cfg.in_hand, air = z > cfg.in_air;
  if (!s.picked) r.reward += cfg.guide_weight * (s.prev_dist - d);
  s.prev_dist = d;
  if (hand && air) {
    s.picked = 1;
    const double gain = std::min(cfg.lift_cap, z) - s.pick_height;
    if (gain > 0) {
      r.reward += cfg.lift_weight * gain;
      s.pick_height = z;
    }
    r.reward += cfg.hold_weight * (1 - distance(s.target, env.object_pos()));
    s.held += 1;
    if (s.held >= cfg.hold_steps) {
      r.success = true;
      r.reward += cfg.time_bonus * (max_steps - t);
    }
  } else if (s.picked && !hand) {
    r.failed = true;  // dropped
  }
  return r;
}

CatchRule::Config CatchRule::Config::read(const Section& e, const Vec3& hold_target) {
  Config c;
  c.hold_target = hold_target;
  c.in_hand = e.get("in_hand", c.in_hand, Range::positive());
  c.in_air = e.get("in_air", c.in_air, Range::non_negative());
  c.on_ground = e.get("on_ground", c.on_ground, Range::non_negative());
  c.start = read_vec3(e, "start", c.start);
  c.quat_noise = e.get("quat_noise", c.quat_noise, Range::non_negative());
  c.throw_force = e.get("throw_force", c.throw_force, Range::non_negative());
  c.aim = read_vec3(e, "aim", c.aim);
  c.aim_spread = e.get("aim_spread", c.aim_spread, Range::non_negative());
  c.catch_bonus = e.get("catch_bonus", c.catch_bonus, Range::non_negative());
  c.hold_weight = e.get("hold_weight", c.hold_weight, Range::non_negative());
  c.hold_target = read_vec3(e, "hold_target", c.hold_target);
  c.hold_steps = e.get("hold_steps", c.hold_steps, Range::at_least(1));
  return c;
}

void CatchRule::place(JacoEnv& env, Rng&) const { env.place_object(cfg.start, cfg.quat_noise, 0.0); }

void CatchRule::throw_box(JacoEnv& env, Rng& rng) const {
  Vec3 aim = cfg.aim;
  aim[0] += rng.uniform(0, cfg.aim_spread);
  aim[1] += rng.uniform(0, cfg.aim_spread);
  env.throw_object(cfg.throw_force, aim);
}

RuleStep CatchRule::step(const JacoEnv& env) {
  RuleStep r;
  const double z = env.object_z();
  if (env.in_hand(cfg.in_hand) && z > cfg.in_air) {
    r.reward += cfg.catch_bonus + cfg.hold_weight * (1 - distance(cfg.hold_target, env.object_pos()));
    s.held += 1;
    r.success = s.held >= cfg.hold_steps;
  }
  if (z <= cfg.on_ground) r.failed = true;
  return r;
}

TossRule::Config TossRule::Config::read(const Section& e) {
  Config c;
  c.in_hand = e.get("in_hand", c.in_hand, Range::positive());
  c.in_air = e.get("in_air", c.in_air, Range::non_negative());
  c.start = read_vec3(e, "start", c.start);
  c.start_noise = e.get("start_noise", c.start_noise, Range::non_negative());
  c.vel_noise = e.get("vel_noise", c.vel_noise, Range::non_negative());
  c.guide_weight = e.get("guide_weight", c.guide_weight, Range::non_negative());
  c.lift_weight = e.get("lift_weight", c.lift_weight, Range::non_negative());
  c.release_height = e.get("release_height", c.release_height, Range::positive());
  c.release_bonus = e.get("release_bonus", c.release_bonus, Range::non_negative());
  c.stable_weight = e.get("stable_weight", c.stable_weight, Range::non_negative());
  c.stable_slack = e.get("stable_slack", c.stable_slack, Range::non_negative());
  c.land_x = e.get("land_x", c.land_x, Range::any());
  c.land_y = e.get("land_y", c.land_y, Range::any());
  c.apex_height = e.get("apex_height", c.apex_height, Range::positive());
  c.apex_weight = e.get("apex_weight", c.apex_weight, Range::non_negative());
  c.apex_tolerance = e.get("apex_tolerance", c.apex_tolerance, Range::positive());
  c.apex_bonus = e.get("apex_bonus", c.apex_bonus, Range::non_negative());
  c.land_tolerance = e.get("land_tolerance", c.land_tolerance, Range::positive());
  c.success_bonus = e.get("success_bonus", c.success_bonus, Range::non_negative());
  if (!(c.apex_height > c.release_height)) throw e.error("apex_height", "must be above release_height");
  return c;
}

void TossRule::place(JacoEnv& env, Rng& rng) const {
  Vec3 p = cfg.start;
  p[0] += rng.symmetric(cfg.start_noise);
  p[1] += rng.symmetric(cfg.start_noise);
  env.place_object(p, 0.0, cfg.vel_noise);
}

void TossRule::begin(const JacoEnv& env) {
  s = State();
  s.ball_top = env.object_pos();
  s.ball_top[2] += 0.04;
  s.prev_dist = distance(env.hand_pos(), s.ball_top);
  s.prev_z = env.object_z();
}

RuleStep TossRule::step(const JacoEnv& env) {
  RuleStep r;
  const Vec3 ball = env.object_pos();
  const double z = ball[2];
  const bool hand = env.in_hand(cfg.in_hand), air = z > cfg.in_air;
  const double d_top = distance(env.hand_pos(), s.ball_top);
  if (!s.picked && !(hand && air)) r.reward += cfg.guide_weight * (s.prev_dist - d_top);
  s.prev_dist = d_top;
  if (hand && !s.released) {
    const double gain = std::min(z, cfg.release_height) - s.pick_height;
    if (gain > 0) {
      r.reward += cfg.lift_weight * gain;
      s.picked = 1;
      s.pick_height = z;
    }
  }
  if (!s.released && z > cfg.release_height) {
    if (hand) r.failed = true;  // carried above the release height: not a toss
    else {
      r.reward += cfg.release_bonus;
      s.released = 1;
    }
  }
  if (s.picked)
    r.reward -= cfg.stable_weight * (std::abs(ball[0] - cfg.land_x) + std::abs(ball[1] - cfg.land_y) - cfg.stable_slack);
  if (s.released && !s.falling && !r.failed && z <= s.prev_z) {  // the apex
    const double miss = std::abs(cfg.apex_height - z);
    r.reward += cfg.apex_weight * (1 - miss / cfg.apex_height);
    if (miss < cfg.apex_tolerance) {
      r.reward += cfg.apex_bonus;
      s.falling = 1;
    } else {
      r.failed = true;
    }
  }
  if (judge_landing && s.falling && z < cfg.release_height) {
    if (std::abs(ball[0] - cfg.land_x) < cfg.land_tolerance && std::abs(ball[1] - cfg.land_y) < cfg.land_tolerance) {
      r.reward += cfg.success_bonus;
      r.success = true;
    } else {
      r.failed = true;
    }
  }
  if (s.picked && !hand && !air) r.failed = true;  // dropped
  s.prev_z = z;
  return r;
}

HitRule::Config HitRule::Config::read(const Section& e) {
  Config c;
  c.hit_distance = e.get("hit_distance", c.hit_distance, Range::positive());
  c.on_ground = e.get("on_ground", c.on_ground, Range::non_negative());
  c.start = read_vec3(e, "start", c.start);
  c.start_noise = e.get("start_noise", c.start_noise, Range::non_negative());
  c.vel_noise = e.get("vel_noise", c.vel_noise, Range::non_negative());
  c.hit_height = e.get("hit_height", c.hit_height, Range::positive());
  c.hit_weight = e.get("hit_weight", c.hit_weight, Range::non_negative());
  c.hit_tolerance = e.get("hit_tolerance", c.hit_tolerance, Range::positive());
  c.hit_bonus = e.get("hit_bonus", c.hit_bonus, Range::non_negative());
  c.vx_cost = e.get("vx_cost", c.vx_cost, Range::non_negative());
  c.target = read_vec3(e, "target", c.target);
  c.target_radius = e.get("target_radius", c.target_radius, Range::positive());
  c.target_bonus = e.get("target_bonus", c.target_bonus, Range::non_negative());
  c.miss_weight = e.get("miss_weight", c.miss_weight, Range::non_negative());
  c.approach_weight = e.get("approach_weight", c.approach_weight, Range::non_negative());
  return c;
}

void HitRule::place(JacoEnv& env, Rng& rng) const {
  Vec3 p = cfg.start;
  for (auto& x : p) x += rng.symmetric(cfg.start_noise);
  env.place_object(p, 0.0, cfg.vel_noise);
  place_target(env);
}

void HitRule::begin(const JacoEnv& env) {
  s = State();
  s.prev_x = env.object_pos()[0];
}

RuleStep HitRule::step(const JacoEnv& env) {
  RuleStep r;
  const Vec3 ball = env.object_pos();
  const double z = ball[2];
  if (!s.hit && env.hand_object_distance() < cfg.hit_distance) {
    const double miss = std::abs(z - cfg.hit_height);
    r.reward += cfg.hit_weight * (1 - miss);
    if (miss < cfg.hit_tolerance) {
      r.reward += cfg.hit_bonus;
      s.hit = 1;
      s.prev_to_target = distance(cfg.target, ball);
    } else {
      r.failed = true;  // touched at the wrong height
    }
  }
  if (s.hit) {
    r.reward -= cfg.vx_cost * std::abs(ball[0] - s.prev_x) / env.control_dt();
    const double to_target = distance(cfg.target, ball);
    s.closest = std::min(s.closest, to_target);
    r.reward += cfg.approach_weight * (s.prev_to_target - to_target);
    s.prev_to_target = to_target;
    if (to_target < cfg.target_radius) {
      r.reward += cfg.target_bonus;
      r.success = true;
    } else if (z < cfg.on_ground) {
      r.reward += cfg.miss_weight * (2 - s.closest) / 2;
      r.failed = true;
    }
  } else if (z < cfg.on_ground) {
    // Our choice: the reference lets a missed ball lie until the time limit; nothing can
    // happen any more, so the episode ends (the same score, less wasted simulation).
    r.failed = true;
  }
  s.prev_x = ball[0];
  return r;
}

StepResult skill_result(double control, const RuleStep& rs) {
  StepResult r;
  r.reward = control + rs.reward;
  r.terminated = rs.success || rs.failed;
  r.info.success = rs.success;
  r.info.success_count = rs.success ? 1 : 0;
  return r;
}

}  // namespace segue
