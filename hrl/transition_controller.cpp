#include "hrl/transition_controller.h"

namespace segue {

TransitionController::TransitionController(const std::vector<Skill>& skills, const MetaController& meta,
                                           std::vector<TransitionArtefacts> artefacts, SwitchRule rule,
                                           HandOverPoint point)
    : skills_(skills), meta_(meta), artefacts_(std::move(artefacts)), rule_(rule), point_(point) {
  artefacts_.resize(meta_.transitions().size());  // those not given: Without TP
}

void TransitionController::reset(const Env& env, const float*, uint64_t seed) {
  rng_.seed(mix_seed(seed, 0x68616e64));  // a stream of its own, apart from the task's
  features_.resize(env.spec().feature_names.size());
  entry_features_.resize(features_.size());
  env.features(features_.data());
  resume(env, meta_.start_skill(features_.data()));
}

void TransitionController::resume(const Env& env, int skill) {
  features_.resize(env.spec().feature_names.size());
  skill_ = skill;
  transition_ = -1;
  entered_ = -1;
  acted_ = -1;
  // Handed over inside an interval into `skill`: that interval counts as taken, or a skill
  // that hands over to itself would enter it again at once.
  taken_.assign(meta_.transitions().size(), 0);
  env.features(features_.data());
  for (size_t t = 0; t < taken_.size(); ++t)
    taken_[t] = meta_.transitions()[t].to == skill && MetaController::holds(meta_.transitions()[t].when, features_.data());
}

bool TransitionController::hand_over(const float* obs) {
  if (rule_ == SwitchRule::IntervalEnd && point_ == HandOverPoint::Random)
    return meta_.transitions()[transition_].progress(entry_features_.data(), features_.data(), steps_) >=
           hand_over_at_;
  const TransitionArtefacts& a = artefacts_[transition_];
  if (rule_ == SwitchRule::TerminationHead && a.policy->max_steps() > 0 && steps_ >= a.policy->max_steps()) return true;
  if (rule_ == SwitchRule::QNetwork && a.q) {
    float q[2];
    a.q->act(obs, 1, q);
    return q[1] > q[0];
  }
  return false;
}

void TransitionController::act(const Env& env, const float* obs, float* action) {
  env.features(features_.data());
  entered_ = -1;
  for (size_t t = 0; t < taken_.size(); ++t)
    if (taken_[t] && !MetaController::holds(meta_.transitions()[t].when, features_.data())) taken_[t] = 0;
  if (transition_ >= 0) {
    const Transition& tr = meta_.transitions()[transition_];
    if (!tr.running(features_.data(), steps_) || hand_over(obs)) transition_ = -1;
  }
  if (transition_ < 0) {
    int t = meta_.active_transition(skill_, features_.data(), &taken_);
    if (t >= 0) {
      entered_ = t;
      taken_[t] = 1;
      skill_ = meta_.transitions()[t].to;  // pi_b is next, whoever drives the interval
      const bool random = rule_ == SwitchRule::IntervalEnd && point_ == HandOverPoint::Random;
      if (artefacts_[t].policy || random) {
        transition_ = t, steps_ = 0;
        if (random) {
          hand_over_at_ = rng_.uniform(0.0, 1.0);
          entry_features_ = features_;
        }
        if (hand_over(obs)) transition_ = -1;  // q_ab may switch at the interval's first state
      }
    }
  }
  const Skill& b = skills_[skill_];
  acted_ = transition_;
  if (transition_ < 0) {
    b.policy.act(obs + b.obs_begin, 1, action);
    return;
  }
  if (!artefacts_[transition_].policy) {  // Without TP, a random hand-over point: pi_a until then
    const Skill& a = skills_[meta_.transitions()[transition_].from];
    a.policy.act(obs + a.obs_begin, 1, action);
    ++steps_;
    return;
  }
  const Policy& pi_ab = *artefacts_[transition_].policy;
  const int A = env.spec().act_dim;
  out_.resize(pi_ab.act_dim());
  const bool sample = rule_ == SwitchRule::TerminationHead && !pi_ab.log_std().empty();
  pi_ab.act(obs + b.obs_begin, 1, out_.data(), sample ? &rng_ : nullptr);
  ++steps_;
  // Lee et al.: the transition policy's own termination output hands over at once.
  if (rule_ == SwitchRule::TerminationHead && pi_ab.act_dim() > A && out_[A] > 0.0f) {
    transition_ = acted_ = -1;
    b.policy.act(obs + b.obs_begin, 1, action);
    return;
  }
  std::copy(out_.begin(), out_.begin() + A, action);
}

std::string TransitionController::in_control() const {
  if (acted_ < 0) return skills_[skill_].name;
  const Transition& tr = meta_.transitions()[acted_];
  return skills_[tr.from].name + "->" + skills_[tr.to].name;
}

}  // namespace segue
