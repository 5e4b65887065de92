#pragma once
// The rule-based meta-controller. A composite recipe declares, over the task's named
// features, which skill starts an episode and each transition's interval:
//
//   start:
//     - {skill: walk}
//   transitions:
//     - {from: walk, to: jump, when: {curb_ahead: [3, 4]}}      # 3-4 m before a curb
//     - {from: jump, to: walk, when: {curb_behind: [2.5, 3.5]}}
//
// `when` maps features to closed ranges [lo, hi] (a single number means equality); all
// must hold. A transition a->b is "in its interval" while its conditions hold and the
// current skill is a. Nothing here knows any particular task.
#include <string>
#include <vector>

#include "core/recipe.h"
#include "hrl/skill.h"

namespace segue {

struct Condition {
  int feature;
  double lo, hi;
};

struct Transition {
  int from, to;
  std::vector<Condition> when;
  // The interval also ends after this many steps of a transition policy (`max_steps: N`;
  // 0: no cap). The paper's intervals are places, and an adversarially trained pi_ab can
  // learn to stay in one for ever (its reward per step need not be negative); the cap
  // bounds how long the skill after it waits.
  int max_steps = 0;
  bool capped(int steps) const { return max_steps > 0 && steps >= max_steps; }
  // Whether a transition policy that has taken `steps` steps in the interval keeps control.
  bool running(const double* features, int steps) const;
  // How far through the interval a hand-over `steps` steps in, at `features`, is: 0 where it
  // was entered (at `entry`), 1 at its far side. Over max_steps for a capped transition,
  // else over the first condition with a width, as the distance its feature has moved
  // (curb_ahead 4 -> 3.5 is halfway through [3, 4]); 1 (at once) for equalities alone.
  double progress(const double* entry, const double* features, int steps) const;
};

// Reads s's `when:` mapping over these feature names (none: always holds); an unknown
// feature or a bad range is a one-line error naming the key.
std::vector<Condition> read_when(const Section& s, const std::vector<std::string>& features);

// A transition's interval is entered once: after pi_ab (or pi_b) has taken it, it is entered
// again only once its conditions have stopped holding, so that a skill may hand over to
// itself (Repetitive picking's pick->pick) without entering the interval it just left.
class MetaController {
 public:
  MetaController() = default;
  MetaController(const Section& root, const std::vector<Skill>& skills, const std::vector<std::string>& feature_names);
  // The first start rule that holds (or the first rule when none does).
  int start_skill(const double* features) const;
  // The index of the transition out of `skill` whose interval holds now, or -1; with
  // `taken`, transitions marked there (entered, and their interval not yet left) are passed over.
  int active_transition(int skill, const double* features, const std::vector<char>* taken = nullptr) const;
  const std::vector<Transition>& transitions() const { return transitions_; }
  static bool holds(const std::vector<Condition>& when, const double* f);

 private:
  std::vector<std::pair<int, std::vector<Condition>>> start_;
  std::vector<Transition> transitions_;
};

}  // namespace segue
