#include "hrl/switch_interval.h"

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

}  // namespace segue
