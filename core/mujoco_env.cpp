#include "core/mujoco_env.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <mutex>

#include "core/assets.h"
#include "core/error.h"

namespace segue {
namespace {

// Parsing MJCF is slow next to copying a compiled model, and a vector env builds many.
const mjModel* cached_model(const std::string& path) {
  static std::mutex mutex;
  static std::map<std::string, mjModel*> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto it = cache.find(path);
  if (it != cache.end()) return it->second;
  char error[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, error, sizeof(error));
  if (!m) throw Error(path + ": MuJoCo could not load the model: " + error);
  cache[path] = m;
  return m;
}

template <class T>
void append(std::vector<double>& out, const T* p, int n) {
  out.insert(out.end(), p, p + n);
}
void take(const double*& in, mjtNum* p, int n) {
  std::copy(in, in + n, p);
  in += n;
}

// MuJoCo's own handlers write MUJOCO_LOG.TXT and, on an error, wait for Enter on stdin: a
// run would hang. Errors (e.g. an allocation that fails) become segue::Error instead, and
// warnings (an unstable simulation, which MuJoCo resets) a line on stderr.
void on_mujoco_error(const char* msg) { throw Error(std::string("MuJoCo: ") + msg); }
void on_mujoco_warning(const char* msg) { std::fprintf(stderr, "warning: MuJoCo: %s\n", msg); }

}  // namespace

void install_mujoco_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = on_mujoco_error;
    mju_user_warning = on_mujoco_warning;
  });
}

MujocoEnv::MujocoEnv(const std::string& model_file, int frame_skip) : frame_skip_(frame_skip) {
  install_mujoco_handlers();
  model_ = mj_copyModel(nullptr, cached_model(asset_path(model_file)));
  data_ = mj_makeData(model_);
  spec_.act_dim = model_->nu;
  for (int i = 0; i < model_->nu; ++i) {
    bool limited = model_->actuator_ctrllimited[i];
    spec_.act_low.push_back(limited ? model_->actuator_ctrlrange[2 * i] : -1e30f);
    spec_.act_high.push_back(limited ? model_->actuator_ctrlrange[2 * i + 1] : 1e30f);
  }
  clipped_.resize(model_->nu);
}

MujocoEnv::~MujocoEnv() {
  mj_deleteData(data_);
  mj_deleteModel(model_);
}

void MujocoEnv::reset(uint64_t seed, float* obs) {
  rng_.seed(seed);
  reset(obs);
}

void MujocoEnv::reset(float* obs) {
  mj_resetData(model_, data_);
  t_ = 0;
  reset_task();
  mj_forward(model_, data_);
  observe(obs);
}

void MujocoEnv::simulate(const float* ctrl) {
  for (int i = 0; i < model_->nu; ++i) data_->ctrl[i] = ctrl[i];
  for (int k = 0; k < frame_skip_; ++k) mj_step(model_, data_);
  physics_steps_ += frame_skip_;
}

StepResult MujocoEnv::step(const float* action, float* obs) {
  for (int i = 0; i < model_->nu; ++i)
    clipped_[i] = std::clamp(action[i], spec_.act_low[i], spec_.act_high[i]);
  before_physics();
  simulate(clipped_.data());
  ++t_;
  StepResult r = evaluate(clipped_.data());
  if (!r.terminated && t_ >= spec_.max_episode_steps) r.truncated = true;
  observe(obs);
  return r;
}

// Snapshot layout: time, step counter, then every mjData array the next mj_step reads
// (qacc_warmstart seeds the constraint solver, so it is needed for bit-exact replay; qacc
// is observed), then the task's own state.
void MujocoEnv::save_state(std::vector<double>& out) const {
  const mjModel* m = model_;
  out.clear();
  out.push_back(data_->time);
  out.push_back(t_);
  append(out, data_->qpos, m->nq);
  append(out, data_->qvel, m->nv);
  append(out, data_->act, m->na);
  append(out, data_->ctrl, m->nu);
  append(out, data_->qacc_warmstart, m->nv);
  append(out, data_->qacc, m->nv);
  append(out, data_->qfrc_applied, m->nv);
  append(out, data_->xfrc_applied, 6 * m->nbody);
  append(out, data_->mocap_pos, 3 * m->nmocap);
  append(out, data_->mocap_quat, 4 * m->nmocap);
  save_task_state(out);
}

void MujocoEnv::restore_state(const std::vector<double>& state, float* obs) {
  const mjModel* m = model_;
  size_t physics = 2 + m->nq + 4 * m->nv + m->na + m->nu + 6 * m->nbody + 7 * m->nmocap;
  if (state.size() < physics)
    throw Error(spec_.name + ": a saved state of size " + std::to_string(state.size()) +
                " is too small for this model (needs at least " + std::to_string(physics) + ")");
  const double* in = state.data();
  data_->time = *in++;
  t_ = static_cast<int>(*in++);
  take(in, data_->qpos, m->nq);
  take(in, data_->qvel, m->nv);
  take(in, data_->act, m->na);
  take(in, data_->ctrl, m->nu);
  take(in, data_->qacc_warmstart, m->nv);
  std::vector<mjtNum> warmstart(data_->qacc_warmstart, data_->qacc_warmstart + m->nv);
  std::vector<mjtNum> qacc(in, in + m->nv);
  in += m->nv;
  take(in, data_->qfrc_applied, m->nv);
  take(in, data_->xfrc_applied, 6 * m->nbody);
  take(in, data_->mocap_pos, 3 * m->nmocap);
  take(in, data_->mocap_quat, 4 * m->nmocap);
  restore_task_state(in, state.size() - physics);
  // Derived quantities (body positions, contacts) for observe(); mj_forward also
  // overwrites qacc and the warmstart, so put the recorded ones back.
  mj_forward(model_, data_);
  std::copy(warmstart.begin(), warmstart.end(), data_->qacc_warmstart);
  std::copy(qacc.begin(), qacc.end(), data_->qacc);
  observe(obs);
}

bool MujocoEnv::save_episode(std::vector<double>& state, std::string& rng) const {
  save_state(state);
  rng = rng_.state();
  return true;
}

void MujocoEnv::restore_episode(const std::vector<double>& state, const std::string& rng, float* obs) {
  restore_state(state, obs);
  rng_.set_state(rng);
}

void MujocoEnv::forward(float* obs) {
  mj_forward(model_, data_);
  observe(obs);
}

int MujocoEnv::body_id(const char* name) const {
  int id = mj_name2id(model_, mjOBJ_BODY, name);
  if (id < 0) throw Error(spec_.name + ": the model has no body '" + name + "'");
  return id;
}

int MujocoEnv::joint_qpos(const char* name) const {
  int id = mj_name2id(model_, mjOBJ_JOINT, name);
  if (id < 0) throw Error(spec_.name + ": the model has no joint '" + name + "'");
  return model_->jnt_qposadr[id];
}

}  // namespace segue
