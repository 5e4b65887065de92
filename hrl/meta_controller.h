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
#include <functional>
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
  // Where pi_b's own demonstrations T_b are recorded: in episodes that pi_b runs from the
  // start, while these hold (`expert: {when: ...}`; by default the interval itself).
  std::vector<Condition> expert_when;
  // Or, where pi_b alone never reaches the interval in this task (the crawl falls in the
  // open before the first ceiling; the hit never runs alone in Serve): pi_b's episodes on
  // its own sub-task, their first expert_steps steps (`expert: {task: walker_crawl, steps:
  // 150}`) and/or while expert_when holds over that task's features (`expert: {task:
  // jaco_hit, when: {steps: [21, 200], object_z: [0.9, 10], hit: 0}}`).
  std::string expert_task;
  int expert_steps = 0;
  // Keep only the windows after which pi_b goes on to succeed (`expert: {successful: true}`):
  // the states pi_b expects are those it succeeds from. Matters when pi_b itself often
  // fails (stage 13's jump cleared 38%): matching all its states would match its failures too.
  bool expert_successful = false;
  // Or record pi_b where it actually takes over: one episode from each of S_a's training
  // states (not the held-out ones), pi_b in control from there (`expert: {after_handover:
  // true}`). When pi_b was trained to take over from pi_a (a `lead_in`), its own start's
  // states are not the ones it succeeds from in the task; matching them leads pi_ab away.
  bool expert_after_handover = false;
  // |S_a| for this transition (`start_states: N`); 0 takes collect.start_states. A late
  // interval is reached only as often as every earlier hand-over succeeds, so a recipe
  // may ask for fewer states there rather than run tens of thousands of episodes.
  int start_states = 0;
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
  // The window pi_ab's own training episodes run in (`training: {when: ..., max_steps: N}`;
  // by default the interval): episodes start at S_a, where the interval begins, and may run
  // on past where the switch must hand over, so that pi_ab does not learn to hand over at
  // the very edge of its own episodes (the reference trains Hurdle's walk->jump from 4 to
  // 2 m before the curb and evaluates it from 4 to 3 m; pick->pick until the box lifts off,
  // where the switch is forced after 30 steps). Its `env:` (CompositeRecipe::training_envs)
  // is where they run.
  std::vector<Condition> training_when;
  int training_max_steps = 0;
  // This transition with its training window as the interval.
  Transition training_window() const;
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
  // task_features: the feature names of a sub-task named by `expert.task`.
  MetaController(const Section& root, const std::vector<Skill>& skills, const std::vector<std::string>& feature_names,
                 const std::function<std::vector<std::string>(const std::string&)>& task_features = nullptr);
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
