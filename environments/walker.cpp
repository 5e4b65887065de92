#include "environments/walker.h"

#include <algorithm>
#include <cmath>

namespace segue {

WalkerConfig WalkerConfig::read(const Section& s, WalkerConfig c) {
  c.max_episode_steps = s.get("max_episode_steps", c.max_episode_steps, Range::positive());
  c.success_steps = s.get("success_steps", c.success_steps, Range::positive());
  c.init_noise = s.get("init_noise", c.init_noise, Range::non_negative());
  c.init_random_steps = s.get("init_random_steps", c.init_random_steps, Range::non_negative());
  c.push_prob = s.get("push_prob", c.push_prob, Range::closed(0, 1));
  c.push_force = s.get("push_force", c.push_force, Range::non_negative());
  c.fall_height = s.get("fall_height", c.fall_height, Range::non_negative());
  c.target_speed = s.get("target_speed", c.target_speed, Range::non_negative());
  c.height_target = s.get("height_target", c.height_target, Range::positive());
  c.upright_weight = s.get("upright_weight", c.upright_weight, Range::non_negative());
  c.alive_bonus = s.get("alive_bonus", c.alive_bonus, Range::non_negative());
  c.foot_cost = s.get("foot_cost", c.foot_cost, Range::non_negative());
  c.ctrl_cost = s.get("ctrl_cost", c.ctrl_cost, Range::non_negative());
  return c;
}

WalkerEnv::WalkerEnv(const std::string& name, const WalkerConfig& config, const std::string& model_file)
    : MujocoEnv(model_file, 4), cfg_(config) {
  spec_.name = name;
  spec_.obs_dim = kBaseObsDim;
  spec_.max_episode_steps = cfg_.max_episode_steps;
  spec_.metric_names = {"x_velocity"};
  qx_ = joint_qpos("rootx");
  qz_ = joint_qpos("rootz");
  qpitch_ = joint_qpos("rooty");
  torso_ = body_id("torso");
  foot_ = body_id("foot");
  foot_left_ = body_id("foot_left");
  foot_dof_ = model_->jnt_dofadr[mj_name2id(model_, mjOBJ_JOINT, "foot_joint")];
  foot_left_dof_ = model_->jnt_dofadr[mj_name2id(model_, mjOBJ_JOINT, "foot_left_joint")];
}

double WalkerEnv::delta_h() const {
  return data_->xpos[3 * torso_ + 2] -
         std::max(data_->xpos[3 * foot_ + 2], data_->xpos[3 * foot_left_ + 2]);
}

double WalkerEnv::min_x() const {
  return std::min({data_->xpos[3 * torso_], data_->xpos[3 * foot_], data_->xpos[3 * foot_left_]});
}

double WalkerEnv::trailing_foot_x() const {
  return std::min(data_->xpos[3 * foot_], data_->xpos[3 * foot_left_]);
}

double WalkerEnv::walk_reward(double v, const float* action, double speed_weight, double height_weight) const {
  return speed_weight * speed_term(v, cfg_.target_speed) - height_weight * std::abs(cfg_.height_target - delta_h()) +
         posture_terms(action);
}

void WalkerEnv::reset_task() {
  for (int i = 0; i < model_->nq; ++i) data_->qpos[i] = model_->qpos0[i] + rng_.symmetric(cfg_.init_noise);
  for (int i = 0; i < model_->nv; ++i) data_->qvel[i] = rng_.symmetric(cfg_.init_noise);
  // A few random actions, so episodes do not all start from one pose.
  std::vector<float> a(model_->nu);
  for (int k = 0; k < cfg_.init_random_steps; ++k) {
    for (auto& x : a) x = static_cast<float>(rng_.symmetric(1.0));
    simulate(a.data());
  }
  x_before_ = torso_x();
}

void WalkerEnv::before_physics() {
  x_before_ = torso_x();
  // A push lasts one control step.
  std::fill(data_->xfrc_applied, data_->xfrc_applied + 6 * model_->nbody, 0.0);
  if (cfg_.push_prob > 0 && rng_.bernoulli(cfg_.push_prob)) {
    int body = rng_.integer(1, model_->nbody - 1);
    data_->xfrc_applied[6 * body] = rng_.symmetric(cfg_.push_force);
  }
}

void WalkerEnv::observe(float* obs) const {
  const mjModel* m = model_;
  int k = 0;
  for (int i = 1; i < m->nq; ++i) obs[k++] = static_cast<float>(data_->qpos[i]);
  for (int i = 0; i < m->nv; ++i) obs[k++] = static_cast<float>(std::clamp(data_->qvel[i], -10.0, 10.0));
  for (int i = 0; i < m->nv; ++i) obs[k++] = static_cast<float>(data_->qacc[i]);
}

double WalkerEnv::posture_terms(const float* a) const {
  double ctrl = 0.0;
  for (int i = 0; i < model_->nu; ++i) ctrl += double(a[i]) * a[i];
  double foot = std::abs(data_->qvel[foot_dof_]) + std::abs(data_->qvel[foot_left_dof_]);
  return cfg_.upright_weight * std::cos(pitch()) + cfg_.alive_bonus - cfg_.foot_cost * foot -
         cfg_.ctrl_cost * ctrl;
}

WalkerWalk::WalkerWalk(const std::string& name, const WalkerConfig& config, double direction)
    : WalkerEnv(name, config), direction_(direction) {}

StepResult WalkerEnv::survival_step(double reward, bool ended) const {
  StepResult r;
  r.reward = reward;
  r.terminated = ended;
  r.info.success = !ended && t_ >= cfg_.success_steps;
  r.info.success_count = r.info.success ? 1 : 0;
  r.info.metrics[0] = x_velocity();
  if (r.info.success) r.truncated = true;
  return r;
}

StepResult WalkerWalk::evaluate(const float* action) {
  return survival_step(walk_reward(direction_ * x_velocity(), action, 1.0, 1.0), fallen());
}

}  // namespace segue
