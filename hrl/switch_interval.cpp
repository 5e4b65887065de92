#include "hrl/switch_interval.h"

#include <limits>

namespace segue {

bool run_subtask(Env& env, TransitionController& after, int to, float* obs, int lookahead, int max_steps,
                 int64_t* steps) {
  std::vector<float> act(env.spec().act_dim);
  after.resume(env, to);
  int begun = 0;
  for (int step = 0; step < max_steps; ++step) {
    after.act(env, obs, act.data());
    if (after.entered() >= 0 && ++begun == lookahead) return true;  // a transition began
    StepResult sr = env.step(act.data(), obs);
    if (steps) ++*steps;
    if (sr.terminated) return sr.info.success;  // a fall, or the whole task done (the last pick)
    if (sr.truncated) return true;
  }
  return true;
}

SwitchInterval::SwitchInterval(const EnvFactory& make_env, const std::vector<Skill>& skills,
                               const MetaController& meta, int transition, StartStates starts, Policy pi_ab,
                               std::vector<TransitionArtefacts> trained, int lookahead, int max_subtask_steps)
    : env_(make_env()),
      transition_(meta.transitions().at(transition)),
      to_(transition_.to),
      obs_begin_(skills.at(transition_.to).obs_begin),
      starts_(std::move(starts)),
      pi_ab_(std::move(pi_ab)),
      after_(skills, meta, std::move(trained), SwitchRule::IntervalEnd),
      lookahead_(lookahead),
      max_subtask_steps_(max_subtask_steps),
      act_(env_->spec().act_dim),
      obs_(env_->spec().obs_dim),
      q_(2),
      features_(env_->spec().feature_names.size()) {}

void SwitchInterval::begin(int i, float* obs) {
  starts_.state(i, state_);
  env_->restore_state(state_, obs);
}

SwitchInterval::Stay SwitchInterval::stay(const float* obs, int t, float* next_obs) {
  pi_ab_.act(obs + obs_begin_, 1, act_.data());
  const StepResult sr = env_->step(act_.data(), next_obs);
  ++env_steps_;
  env_->features(features_.data());
  if (sr.terminated) return Stay::Fell;
  if (sr.truncated || !transition_.running(features_.data(), t + 1)) return Stay::Ended;
  return Stay::On;
}

bool SwitchInterval::hand_over(float* obs) {
  return run_subtask(*env_, after_, to_, obs, lookahead_, max_subtask_steps_, &env_steps_);
}

void SwitchInterval::walk(int i, const Policy* q_ab, Path& path) {
  path.states.clear(), path.gap.clear();
  path.fell = false;
  begin(i, obs_.data());
  for (int t = 0;; ++t) {
    path.states.emplace_back();
    env_->save_state(path.states.back());
    if (q_ab) {
      q_ab->act(obs_.data(), 1, q_.data());
      path.gap.push_back(q_[1] - q_[0]);
    }
    const Stay s = stay(obs_.data(), t, obs_.data());
    path.steps = t + 1;
    if ((path.fell = s == Stay::Fell)) return;  // no hand-over point after this one
    if (s == Stay::Ended) {
      path.states.emplace_back();
      env_->save_state(path.states.back());
      if (q_ab) path.gap.push_back(std::numeric_limits<float>::infinity());
      return;
    }
  }
}

bool SwitchInterval::hand_over_at(const Path& path, size_t k) {
  env_->restore_state(path.states[k], obs_.data());
  return hand_over(obs_.data());
}

}  // namespace segue
