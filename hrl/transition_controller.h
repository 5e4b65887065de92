#pragma once
// With TP, With TP + Q and Lee et al.: the meta-controller's skills joined by trained
// transition policies. When transition a->b's interval begins, pi_ab takes over from pi_a;
// control passes to pi_b
//   IntervalEnd      (With TP):       when the interval ends;
//   QNetwork         (With TP + Q):   as soon as q_ab values switch above stay;
//   TerminationHead  (Lee et al.):    when pi_ab's extra output (its termination head) is
//                                     positive (pi_b then acts from that state, as in
//                                     training), or after the policy's max_steps;
//                                     pi_ab's actions, that output included, are sampled
//                                     from its Gaussian as in its training (on the mean
//                                     where the file has no log std).
// Control always passes to pi_b when the interval ends (or its max_steps are spent). A
// transition without a trained pi_ab is taken as Without TP: pi_b from the interval's start.
//
// The reference code evaluates Without TP and With TP otherwise (HandOverPoint::Random):
// control passes to pi_b at a point of the interval drawn uniformly (Transition::progress),
// pi_ab driving until then (With TP) or pi_a carrying on (Without TP). With TP + Q and Lee
// et al. decide for themselves either way.
#include <algorithm>
#include <optional>
#include <vector>

#include "core/rng.h"
#include "hrl/controller.h"
#include "hrl/meta_controller.h"
#include "hrl/skill.h"

namespace segue {

enum class SwitchRule { IntervalEnd, QNetwork, TerminationHead };
// Where Without TP and With TP hand over to pi_b (recipe key eval.handover_point):
// Fixed as the paper's text (at the interval's start / end), Random as the reference code.
enum class HandOverPoint { Fixed, Random };

struct TransitionArtefacts {
  std::optional<Policy> policy;  // pi_ab, on pi_b's observation slice
  std::optional<Policy> q;       // q_ab, on the task observation: [Q(stay), Q(switch)]
};

class TransitionController : public Controller {
 public:
  TransitionController(const std::vector<Skill>& skills, const MetaController& meta,
                       std::vector<TransitionArtefacts> artefacts, SwitchRule rule,
                       HandOverPoint point = HandOverPoint::Fixed);
  void reset(const Env& env, const float* obs, uint64_t seed) override;
  // Carries on an episode already under way with `skill` in control and no transition
  // running (switch training hands the episode over here after pi_ab). An interval into
  // `skill` that holds now is the one just handed over in: it is not entered again.
  void resume(const Env& env, int skill);
  void act(const Env& env, const float* obs, float* action) override;
  int skill() const { return skill_; }
  // Who chose the last action: the skill's name, or "a->b" where transition a->b's pi_ab
  // (or, at a random hand-over point, Without TP's pi_a) did.
  std::string in_control() const override;
  int transition() const { return transition_; }  // the transition pi_ab (or pi_a) drives, or -1
  // The transition whose interval the last act() entered (control passed to pi_ab, or
  // straight to pi_b), or -1.
  int entered() const { return entered_; }

 private:
  bool hand_over(const float* obs);
  std::vector<Skill> skills_;  // own copies: Policy::act keeps scratch buffers
  const MetaController& meta_;
  std::vector<TransitionArtefacts> artefacts_;  // per transition of the recipe
  SwitchRule rule_;
  HandOverPoint point_;
  Rng rng_;                  // the random hand-over points, from the episode's seed
  double hand_over_at_ = 1;  // the drawn point (HandOverPoint::Random), in Transition::progress
  std::vector<double> features_, entry_features_;
  std::vector<float> out_;
  int skill_ = 0, transition_ = -1, steps_ = 0;  // steps_: pi_ab's in this interval
  int entered_ = -1;
  int acted_ = -1;  // the transition whose pi_ab (or pi_a) chose the last action, or -1: pi_b (skill_)
  std::vector<char> taken_;  // per transition: entered, and its interval not left since
};

}  // namespace segue
