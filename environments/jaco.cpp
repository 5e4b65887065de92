#include "environments/jaco.h"

#include <algorithm>
#include <cmath>

namespace segue {

double distance(const Vec3& a, const Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

Vec3 read_vec3(const Section& env, const std::string& key, const Vec3& fallback) {
  auto v = env.get(key, std::vector<double>(fallback.begin(), fallback.end()), Range::any());
  if (v.size() != 3) throw env.error(key, "must be a list of 3 numbers (x, y, z)");
  return {v[0], v[1], v[2]};
}

JacoConfig JacoConfig::read(const Section& s, JacoConfig c) {
  c.max_episode_steps = s.get("max_episode_steps", c.max_episode_steps, Range::positive());
  c.init_noise = s.get("init_noise", c.init_noise, Range::non_negative());
  c.init_random_steps = s.get("init_random_steps", c.init_random_steps, Range::non_negative());
  c.ctrl_cost = s.get("ctrl_cost", c.ctrl_cost, Range::non_negative());
  c.qvel_cost = s.get("qvel_cost", c.qvel_cost, Range::non_negative());
  c.qacc_cost = s.get("qacc_cost", c.qacc_cost, Range::non_negative());
  return c;
}

JacoEnv::JacoEnv(const std::string& name, const JacoConfig& config, const std::string& model_file,
                 bool with_rotation)
    : MujocoEnv(model_file, 4), cfg_(config), with_rotation_(with_rotation) {
  spec_.name = name;
  spec_.obs_dim = with_rotation ? 49 : 39;
  spec_.max_episode_steps = cfg_.max_episode_steps;
  spec_.metric_names = {"object_height"};
  object_body_ = body_id("object");
  object_qpos_ = joint_qpos("object");
  object_dof_ = model_->jnt_dofadr[mj_name2id(model_, mjOBJ_JOINT, "object")];
  const char* hand[4] = {"jaco_link_hand", "jaco_link_finger_1", "jaco_link_finger_2", "jaco_link_finger_3"};
  for (int i = 0; i < 4; ++i) hand_geoms_[i] = mj_name2id(model_, mjOBJ_GEOM, hand[i]);
  base_geom_ = mj_name2id(model_, mjOBJ_GEOM, "jaco_link_base");
  if (base_geom_ < 0 || *std::min_element(hand_geoms_.begin(), hand_geoms_.end()) < 0)
    throw Error(model_file + ": the arm needs geoms jaco_link_base, jaco_link_hand and jaco_link_finger_1..3");
  random_action_.resize(model_->nu);
  spec_.feature_names = {"steps", "object_z"};
}

void JacoEnv::features(double* out) const {
  out[0] = t_;
  out[1] = object_z();
}

Vec3 JacoEnv::hand_pos() const {
  Vec3 h{0, 0, 0};
  for (int g : hand_geoms_)
    for (int k = 0; k < 3; ++k) h[k] += 0.25 * data_->geom_xpos[3 * g + k];
  return h;
}

Vec3 JacoEnv::object_pos() const {
  const double* p = data_->qpos + object_qpos_;
  return {p[0], p[1], p[2]};
}

Vec3 JacoEnv::object_velocity() const {
  const double* v = data_->qvel + object_dof_;
  return {v[0], v[1], v[2]};
}

void JacoEnv::pin_object(const Vec3& pos) {
  double* q = data_->qpos + object_qpos_;
  for (int k = 0; k < 3; ++k) q[k] = pos[k];
  q[3] = 1.0;
  q[4] = q[5] = q[6] = 0.0;
  std::fill(data_->qvel + object_dof_, data_->qvel + object_dof_ + 6, 0.0);
}

void JacoEnv::place_object(const Vec3& pos, double quat_noise, double vel_noise) {
  pin_object(pos);
  double* q = data_->qpos + object_qpos_;
  for (int k = 3; k < 7; ++k) q[k] += rng_.symmetric(quat_noise);
  for (int k = 0; k < 6; ++k) data_->qvel[object_dof_ + k] = rng_.symmetric(vel_noise);
}

void JacoEnv::throw_object(double force, const Vec3& aim) {
  mj_kinematics(model_, data_);
  const double* centre = data_->geom_xpos + 3 * base_geom_;
  Vec3 box = object_pos();
  Vec3 dir{centre[0] + aim[0] - box[0], centre[1] + aim[1] - box[1], centre[2] + aim[2] - box[2]};
  double n = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  double* f = data_->xfrc_applied + 6 * object_body_;
  for (int k = 0; k < 3; ++k) f[k] = force * dir[k] / n;
  random_steps(1);
  std::fill(f, f + 6, 0.0);
}

void JacoEnv::unwind_arm() {
  for (int i = 0; i < kArmJoints; ++i) data_->qpos[i] = std::remainder(data_->qpos[i], 2 * M_PI);
}

void JacoEnv::move_geom(const char* name, const Vec3& pos) {
  int id = mj_name2id(model_, mjOBJ_GEOM, name);
  if (id < 0) throw Error(spec_.name + ": the model has no geom '" + name + "'");
  std::copy(pos.begin(), pos.end(), model_->geom_pos + 3 * id);
}

void JacoEnv::random_steps(int n) {
  for (int k = 0; k < n; ++k) {
    for (auto& a : random_action_) a = static_cast<float>(rng_.symmetric(1.0));
    simulate(random_action_.data());
  }
}

void JacoEnv::reset_task() {
  for (int i = 0; i < kArmDof; ++i) {
    data_->qpos[i] = model_->qpos0[i] + rng_.symmetric(cfg_.init_noise);
    data_->qvel[i] = rng_.symmetric(cfg_.init_noise);
  }
  place_task_object();
  mj_forward(model_, data_);
  begin_task();
  random_steps(cfg_.init_random_steps);
  after_random_steps();
}

StepResult JacoEnv::evaluate(const float* action) {
  // mj_step leaves positions at the start of its last substep: bring them up to date so
  // that rewards and the observation read the state the step ended in.
  mj_kinematics(model_, data_);
  StepResult r = score(action);
  r.info.metrics[0] = object_z();
  return r;
}

double JacoEnv::control_cost(const float* a) const {
  double ctrl = 0.0, vel = 0.0, acc = 0.0;
  for (int i = 0; i < model_->nu; ++i) ctrl += double(a[i]) * a[i];
  for (int i = 0; i < model_->nv; ++i) {
    vel += std::abs(data_->qvel[i]);
    acc += std::abs(data_->qacc[i]);
  }
  return -cfg_.ctrl_cost * ctrl - cfg_.qvel_cost * vel / model_->nv - cfg_.qacc_cost * acc / model_->nv;
}

// docs/reference/jaco.md#observation: qpos, qvel clipped to +-30, raw qacc, hand position.
// Without rotation the object's quaternion and angular velocity are left out (12 of each
// instead of 16/15/15).
void JacoEnv::observe(float* obs) const {
  const int np = with_rotation_ ? model_->nq : kArmDof + 3;
  const int nv = with_rotation_ ? model_->nv : kArmDof + 3;
  int k = 0;
  for (int i = 0; i < np; ++i) obs[k++] = static_cast<float>(data_->qpos[i]);
  for (int i = 0; i < nv; ++i) obs[k++] = static_cast<float>(std::clamp(data_->qvel[i], -30.0, 30.0));
  for (int i = 0; i < nv; ++i) obs[k++] = static_cast<float>(data_->qacc[i]);
  for (double h : hand_pos()) obs[k++] = static_cast<float>(h);
}

}  // namespace segue
