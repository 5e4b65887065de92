#include "environments/walker_obstacles.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace segue {

ObstacleConfig ObstacleConfig::read(const Section& s, ObstacleConfig c) {
  c.detect_distance = s.get("detect_distance", c.detect_distance, Range::positive());
  c.curb_far_start = s.get("curb_far_start", c.curb_far_start, Range::non_negative());
  c.curb_far_end = s.get("curb_far_end", c.curb_far_end, Range::non_negative());
  c.ceiling_far_start = s.get("ceiling_far_start", c.ceiling_far_start, Range::non_negative());
  c.ceiling_far_end = s.get("ceiling_far_end", c.ceiling_far_end, Range::non_negative());
  c.pass_margin = s.get("pass_margin", c.pass_margin, Range::non_negative());
  c.ceiling_pass_margin = s.get("ceiling_pass_margin", c.ceiling_pass_margin, Range::non_negative());
  c.contact_penalty = s.get("contact_penalty", c.contact_penalty, Range::non_negative());
  c.ceiling_length = s.get("ceiling_length", c.ceiling_length, Range::positive());
  return c;
}

WalkerObstacleEnv::WalkerObstacleEnv(const std::string& name, const WalkerConfig& walker,
                                     const ObstacleConfig& o, bool observe_obstacle)
    : WalkerEnv(name, walker, "walker/walker_obstacles.xml"), ocfg_(o), observe_obstacle_(observe_obstacle) {
  if (observe_obstacle_) spec_.obs_dim = kBaseObsDim + 2;
  geom_kind_.assign(model_->ngeom, 0);
  for (int i = 0;; ++i) {
    int curb = mj_name2id(model_, mjOBJ_GEOM, ("curb" + std::to_string(i)).c_str());
    int ceiling = mj_name2id(model_, mjOBJ_GEOM, ("ceiling" + std::to_string(i)).c_str());
    if (curb < 0 && ceiling < 0) break;
    if (curb >= 0) curb_geoms_.push_back(curb), geom_kind_[curb] = int(ObstacleKind::Curb);
    if (ceiling >= 0) ceiling_geoms_.push_back(ceiling), geom_kind_[ceiling] = int(ObstacleKind::Ceiling);
  }
  parked_pos_.assign(model_->geom_pos, model_->geom_pos + 3 * model_->ngeom);
  parked_size_.assign(model_->geom_size, model_->geom_size + 3 * model_->ngeom);
}

void WalkerObstacleEnv::require_obstacles(size_t curbs, size_t ceilings, const std::string& key) const {
  if (curbs > curb_geoms_.size() || ceilings > ceiling_geoms_.size())
    throw Error(spec_.name + ": env." + key + " asks for " + std::to_string(curbs) + " curbs and " +
                std::to_string(ceilings) + " ceilings; the model (assets/walker/walker_obstacles.xml) holds " +
                std::to_string(curb_geoms_.size()) + " and " + std::to_string(ceiling_geoms_.size()));
}

void WalkerObstacleEnv::set_obstacles(const std::vector<Obstacle>& layout) {
  obstacles_ = layout;
  passed_ = 0;
  for (int g : curb_geoms_)
    for (int k = 0; k < 3; ++k) model_->geom_pos[3 * g + k] = parked_pos_[3 * g + k];
  for (int g : ceiling_geoms_)
    for (int k = 0; k < 3; ++k) {
      model_->geom_pos[3 * g + k] = parked_pos_[3 * g + k];
      model_->geom_size[3 * g + k] = parked_size_[3 * g + k];
    }
  size_t curbs = 0, ceilings = 0;
  for (const auto& o : layout) {
    bool curb = o.kind == ObstacleKind::Curb;
    auto& pool = curb ? curb_geoms_ : ceiling_geoms_;
    size_t& used = curb ? curbs : ceilings;
    if (used >= pool.size()) throw Error(spec_.name + ": the obstacle model has too few " + (curb ? "curbs" : "ceilings"));
    int g = pool[used++];
    model_->geom_pos[3 * g] = 0.5 * (o.start + o.end);
    if (!curb) model_->geom_size[3 * g] = 0.5 * (o.end - o.start);
    // The broad phase uses the bounding sphere: keep it in step with the size.
    const double* s = &model_->geom_size[3 * g];
    model_->geom_rbound[g] = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  }
}

void WalkerObstacleEnv::set_curb_height(size_t index, double height) {
  if (index >= curb_geoms_.size()) throw Error(spec_.name + ": no curb " + std::to_string(index));
  int g = curb_geoms_[index];
  model_->geom_size[3 * g + 2] = 0.5 * height;
  model_->geom_pos[3 * g + 2] = 0.5 * height;
  const double* s = &model_->geom_size[3 * g];
  model_->geom_rbound[g] = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
}

int WalkerObstacleEnv::next_obstacle() const {
  double x = min_x();
  for (size_t i = 0; i < obstacles_.size(); ++i)
    if (obstacles_[i].end > x) return static_cast<int>(i);
  return -1;
}

void WalkerObstacleEnv::obstacle_observation(double& start, double& end) const {
  int i = next_obstacle();
  double x = min_x();
  bool ceiling = i >= 0 && obstacles_[i].kind == ObstacleKind::Ceiling;
  if (i >= 0 && obstacles_[i].start - x <= ocfg_.detect_distance) {
    start = obstacles_[i].start - x;
    end = obstacles_[i].end - x;
  } else {
    start = ceiling ? ocfg_.ceiling_far_start : ocfg_.curb_far_start;
    end = ceiling ? ocfg_.ceiling_far_end : ocfg_.curb_far_end;
  }
}

const Obstacle* WalkerObstacleEnv::obstacle_ahead() const {
  const double x = min_x();
  for (const auto& o : obstacles_)
    if (o.start > x) return &o;
  return nullptr;
}

const Obstacle* WalkerObstacleEnv::obstacle_behind() const {
  const double x = min_x();
  for (auto it = obstacles_.rbegin(); it != obstacles_.rend(); ++it)
    if (it->end < x) return &*it;
  return nullptr;
}

void WalkerObstacleEnv::ahead_and_behind(double* out) const {
  const Obstacle* ahead = obstacle_ahead();
  const Obstacle* behind = obstacle_behind();
  out[0] = ahead ? ahead->start - min_x() : kFar;
  out[1] = behind ? min_x() - behind->end : kFar;
}

bool WalkerObstacleEnv::touching(int kind) const {
  for (int c = 0; c < data_->ncon; ++c) {
    int k1 = geom_kind_[data_->contact[c].geom1], k2 = geom_kind_[data_->contact[c].geom2];
    if ((k1 && (kind == 0 || k1 == kind)) || (k2 && (kind == 0 || k2 == kind))) return true;
  }
  return false;
}

int WalkerObstacleEnv::update_passed() {
  int before = passed_;
  double x = min_x();
  auto margin = [&](const Obstacle& o) {
    return o.kind == ObstacleKind::Ceiling ? ocfg_.ceiling_pass_margin : ocfg_.pass_margin;
  };
  while (passed_ < int(obstacles_.size()) && x > obstacles_[passed_].end + margin(obstacles_[passed_])) ++passed_;
  return passed_ - before;
}

void WalkerObstacleEnv::observe(float* obs) const {
  WalkerEnv::observe(obs);
  if (!observe_obstacle_) return;
  double s, e;
  obstacle_observation(s, e);
  obs[kBaseObsDim] = static_cast<float>(s);
  obs[kBaseObsDim + 1] = static_cast<float>(e);
}

void WalkerObstacleEnv::save_task_state(std::vector<double>& out) const {
  out.push_back(double(obstacles_.size()));
  for (const auto& o : obstacles_) {
    out.push_back(double(int(o.kind)));
    out.push_back(o.start);
    out.push_back(o.end);
  }
  out.push_back(passed_);
  size_t before = out.size();
  save_extra(out);
  out.push_back(double(out.size() - before));
}

void WalkerObstacleEnv::restore_task_state(const double* in, size_t n) {
  if (n < 2) throw Error(spec_.name + ": saved state has no obstacle layout");
  size_t count = size_t(in[0]);
  std::vector<Obstacle> layout;
  for (size_t i = 0; i < count; ++i)
    layout.push_back({ObstacleKind(int(in[1 + 3 * i])), in[2 + 3 * i], in[3 + 3 * i]});
  set_obstacles(layout);
  passed_ = int(in[1 + 3 * count]);
  size_t extra = size_t(in[n - 1]);
  restore_extra(in + 2 + 3 * count, extra);
}

// ---- jump ------------------------------------------------------------------------------

WalkerJump::Config WalkerJump::Config::read(const Section& env, const ObstacleConfig& obstacles) {
  Config c;
  c.curb_x = env.get("curb_x", c.curb_x, Range::any());
  c.curb_noise = env.get("curb_noise", c.curb_noise, Range::non_negative());
  c.cross_bonus = env.get("cross_bonus", c.cross_bonus, Range::non_negative());
  c.upward_weight = env.get("upward_weight", c.upward_weight, Range::non_negative());
  c.height_weight = env.get("height_weight", c.height_weight, Range::non_negative());
  c.end_x = env.get("end_x", c.end_x, Range::any());
  c.curb_height = env.get("curb_height", c.curb_height, Range::positive());
  c.curb_height_min = env.get("curb_height_min", c.curb_height, Range::positive());
  if (c.curb_height_min > c.curb_height) throw env.error("curb_height_min", "must be at most curb_height");
  c.curbs = env.get("curbs", c.curbs, Range::at_least(1));
  c.curb_spacing = env.get("curb_spacing", c.curb_spacing, Range::positive());
  c.contact_ends = env.get("contact_ends", c.contact_ends);
  c.mark_upward_weight = env.get("mark_upward_weight", c.mark_upward_weight, Range::non_negative());
  if (c.curbs > 1 && c.curb_spacing <= 2 * c.curb_noise + obstacles.curb_width)
    throw env.error("curb_spacing", "must exceed 2 curb_noise + curb_width so curbs do not overlap");
  return c;
}

WalkerJump::WalkerJump(const std::string& name, const WalkerConfig& w, const ObstacleConfig& o, const Config& c)
    : WalkerObstacleEnv(name, w, o, true), jcfg_(c) {
  spec_.feature_names = {"curb_ahead", "curb_behind"};
  require_obstacles(size_t(jcfg_.curbs), 0, "curbs");
}

void WalkerJump::reset_task() {
  std::vector<Obstacle> layout;
  heights_.clear();
  for (int k = 0; k < jcfg_.curbs; ++k) {
    double start = jcfg_.curb_x + k * jcfg_.curb_spacing + rng_.symmetric(jcfg_.curb_noise);
    layout.push_back({ObstacleKind::Curb, start, start + ocfg_.curb_width});
    heights_.push_back(rng_.uniform(jcfg_.curb_height_min, jcfg_.curb_height));
  }
  set_obstacles(layout);
  for (size_t k = 0; k < heights_.size(); ++k) set_curb_height(k, heights_[k]);
  crossed_ = 0, touched_ = 0;
  WalkerEnv::reset_task();
}

StepResult WalkerJump::evaluate(const float* action) {
  StepResult r;
  double v = x_velocity();
  r.reward = walk_reward(v, action, 2.0, jcfg_.height_weight);
  // Bonuses for the trailing foot crossing each curb's start, centre and end.
  const int marks = 3 * int(obstacles_.size());
  while (crossed_ < marks) {
    if (trailing_foot_x() <= curb_marks(obstacles_[crossed_ / 3])[crossed_ % 3]) break;
    if (!(touched_ >> (crossed_ / 3) & 1u)) r.reward += jcfg_.cross_bonus;
    ++crossed_;
  }
  if (jcfg_.mark_upward_weight != 0.0)
    for (const Obstacle& c : obstacles_)
      for (double at : curb_marks(c))
        if (x_before_ <= at && at < torso_x())
          r.reward += jcfg_.mark_upward_weight * std::clamp(z_velocity(), -2.0, 2.0);
  double x = min_x();
  const int next = next_obstacle();
  if (next >= 0) {
    const Obstacle& curb = obstacles_[next];
    if (x > curb.start - 1.0 && x < curb.end) r.reward += jcfg_.upward_weight * std::max(z_velocity(), 0.0);
  }
  const bool contact = touching();
  if (contact) {
    r.reward -= ocfg_.contact_penalty;
    if (next >= 0 && next < 32) touched_ |= 1u << next;
  }
  update_passed();
  r.info.success = passed_ == int(obstacles_.size()) && touched_ == 0;
  r.info.success_count = passed_;
  r.info.metrics[0] = v;
  r.terminated = fallen() || (contact && jcfg_.contact_ends) ||
                 x > jcfg_.end_x + (jcfg_.curbs - 1) * jcfg_.curb_spacing;
  return r;
}

void WalkerJump::save_extra(std::vector<double>& out) const {
  out.push_back(crossed_);
  out.push_back(touched_);
  out.insert(out.end(), heights_.begin(), heights_.end());
}
void WalkerJump::restore_extra(const double* in, size_t n) {
  // A state saved by another layout (or by a Segue whose jump kept more) is refused, not misread.
  if (n != 2 + obstacles_.size())
    throw Error(spec_.name + ": a saved state with " + std::to_string(n) + " numbers of the jump's own, not " +
                std::to_string(2 + obstacles_.size()) + " (saved for another layout, or by another version of Segue)");
  crossed_ = int(in[0]);
  touched_ = uint32_t(in[1]);
  heights_.assign(in + 2, in + n);
  for (size_t k = 0; k < heights_.size(); ++k) set_curb_height(k, heights_[k]);
}

// ---- crawl -----------------------------------------------------------------------------

WalkerCrawl::Config WalkerCrawl::Config::read(const Section& env) {
  Config c;
  c.ceiling_start = env.get("ceiling_start", c.ceiling_start, Range::any());
  c.ceiling_end = env.get("ceiling_end", c.ceiling_end, Range::any());
  c.crouch_weight = env.get("crouch_weight", c.crouch_weight, Range::non_negative());
  c.crouch_height = env.get("crouch_height", c.crouch_height, Range::positive());
  if (!(c.ceiling_start < c.ceiling_end)) throw env.error("ceiling_end", "must be beyond ceiling_start");
  return c;
}

WalkerCrawl::WalkerCrawl(const std::string& name, const WalkerConfig& w, const ObstacleConfig& o, const Config& c)
    : WalkerObstacleEnv(name, w, o, false), ccfg_(c) {
  spec_.feature_names = {"ceiling_ahead", "ceiling_behind"};
}

void WalkerCrawl::reset_task() {
  set_obstacles({{ObstacleKind::Ceiling, ccfg_.ceiling_start, ccfg_.ceiling_end}});
  WalkerEnv::reset_task();
}

StepResult WalkerCrawl::evaluate(const float* action) {
  double reward = walk_reward(x_velocity(), action, 2.0, 0.0);  // no height term: crawling is low
  reward -= ccfg_.crouch_weight * std::abs(torso_z() - ccfg_.crouch_height);
  bool contact = touching();
  if (contact) reward -= ocfg_.contact_penalty;
  return survival_step(reward, fallen() || contact);
}

}  // namespace segue
