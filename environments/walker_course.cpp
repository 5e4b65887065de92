#include "environments/walker_course.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace segue {

WalkerCourse::Config WalkerCourse::Config::read(const Section& env, Config c) {
  c.positions = env.get("positions", c.positions, Range::any());
  c.position_noise = env.get("position_noise", c.position_noise, Range::non_negative());
  c.kinds = env.get("kinds", c.kinds);
  c.shuffle = env.get("shuffle", c.shuffle);
  c.pass_bonus = env.get("pass_bonus", c.pass_bonus, Range::non_negative());
  c.speed_weight = env.get("speed_weight", c.speed_weight, Range::non_negative());
  c.height_weight = env.get("height_weight", c.height_weight, Range::non_negative());
  c.ceiling_height_weight = env.get("ceiling_height_weight", c.ceiling_height_weight, Range::non_negative());
  c.cross_bonus = env.get("cross_bonus", c.cross_bonus, Range::non_negative());
  c.mark_upward_weight = env.get("mark_upward_weight", c.mark_upward_weight, Range::non_negative());
  c.ceiling_zone = env.get("ceiling_zone", c.ceiling_zone, Range::non_negative());
  c.ceiling_fall_height = env.get("ceiling_fall_height", c.ceiling_fall_height, Range::non_negative());
  if (c.kinds.size() != c.positions.size())
    throw env.error("kinds", "needs one entry per position (" + std::to_string(c.positions.size()) + ")");
  for (const auto& k : c.kinds)
    if (k != "curb" && k != "ceiling") throw env.error("kinds", "entries are 'curb' or 'ceiling', got '" + k + "'");
  return c;
}

WalkerCourse::WalkerCourse(const std::string& name, const WalkerConfig& w, const ObstacleConfig& o,
                           const Config& c)
    : WalkerObstacleEnv(name, w, o, true), ccfg_(c) {
  spec_.feature_names = {"curb_ahead", "curb_behind", "ceiling_ahead", "ceiling_behind", "steps", "distance"};
  for (const auto& k : c.kinds) kinds_.push_back(k == "curb" ? ObstacleKind::Curb : ObstacleKind::Ceiling);
  const auto curbs = size_t(std::count(kinds_.begin(), kinds_.end(), ObstacleKind::Curb));
  require_obstacles(curbs, kinds_.size() - curbs, "kinds");
}

void WalkerCourse::reset_task() {
  std::vector<ObstacleKind> order = kinds_;
  if (ccfg_.shuffle) std::shuffle(order.begin(), order.end(), rng_.engine());
  std::vector<Obstacle> layout;
  for (size_t i = 0; i < order.size(); ++i) {
    double start = ccfg_.positions[i] + rng_.symmetric(ccfg_.position_noise);
    double length = order[i] == ObstacleKind::Curb ? ocfg_.curb_width : ocfg_.ceiling_length;
    layout.push_back({order[i], start, start + length});
  }
  set_obstacles(layout);
  WalkerEnv::reset_task();
  start_x_ = torso_x();
  crossed_ = 0;
}

bool WalkerCourse::near_ceiling() const {
  double x = min_x();
  for (const auto& o : obstacles_)
    if (o.kind == ObstacleKind::Ceiling && x > o.start - ccfg_.ceiling_zone && x < o.end + ccfg_.ceiling_zone)
      return true;
  return false;
}

void WalkerCourse::features(double* out) const {
  const double x = min_x();
  out[0] = out[1] = out[2] = out[3] = kFar;
  out[4] = t_;
  out[5] = std::abs(torso_x() - start_x_);
  if (const Obstacle* o = obstacle_ahead()) out[o->kind == ObstacleKind::Curb ? 0 : 2] = o->start - x;
  if (const Obstacle* o = obstacle_behind()) out[o->kind == ObstacleKind::Curb ? 1 : 3] = x - o->end;
}

double WalkerCourse::mark_rewards() {
  double r = 0.0;
  const double foot = trailing_foot_x();
  for (size_t k = 0; k < obstacles_.size(); ++k) {
    if (obstacles_[k].kind != ObstacleKind::Curb) continue;
    const auto marks = curb_marks(obstacles_[k]);
    for (int j = 0; j < 3; ++j) {
      const uint32_t bit = 1u << (3 * k + j);
      if (!(crossed_ & bit) && foot > marks[j]) crossed_ |= bit, r += ccfg_.cross_bonus * (j + 1) / 3.0;
      if (x_before_ <= marks[j] && marks[j] < torso_x())
        r += ccfg_.mark_upward_weight * std::clamp(z_velocity(), -2.0, 2.0);
    }
  }
  return r;
}

StepResult WalkerCourse::evaluate(const float* action) {
  StepResult r;
  bool ceiling = near_ceiling();
  double v = x_velocity();
  r.reward = walk_reward(v, action, ccfg_.speed_weight, ceiling ? ccfg_.ceiling_height_weight : ccfg_.height_weight);
  bool contact = touching();
  if (contact) r.reward -= ocfg_.contact_penalty;
  r.reward += ccfg_.pass_bonus * update_passed() + mark_rewards();
  bool fell = torso_z() < (ceiling ? ccfg_.ceiling_fall_height : cfg_.fall_height);
  bool all = passed_ == int(obstacles_.size());
  r.terminated = fell || contact || all;
  r.info.success = all;
  r.info.success_count = passed_;
  r.info.metrics[0] = v;
  return r;
}

}  // namespace segue
