#pragma once
// What the pipeline needs to train transition a->b (hrl/pipeline.h), beside the run-time
// rule the meta-controller follows (Transition, hrl/meta_controller.h): where its episodes
// run, how many states S_a holds, where pi_b's own demonstrations T_b are recorded, and the
// window pi_ab's training episodes run in. Read from the same `transitions:` entry:
//
//   - {from: walk, to: jump, when: {curb_ahead: [3, 4]},            # the rule
//      start_states: 500,
//      training: {when: {curb_ahead: [2, 4]}, max_steps: 100, env: {push_prob: 0.2}},
//      expert: {when: {curb_ahead: [2, 4]}, successful: true}}
#include <functional>
#include <string>
#include <vector>

#include "core/recipe.h"
#include "hrl/evaluation.h"
#include "hrl/meta_controller.h"

namespace segue {

struct TransitionTrainingSpec {
  // Where S_a, T_b and pi_ab's episodes run: the task with `training.env` laid over `env:`
  // (the reference collects and trains in the sub-tasks' environments, with their pushes).
  EnvFactory env;
  // |S_a| for this transition (`start_states: N`); 0 takes collect.start_states. A late
  // interval is reached only as often as every earlier hand-over succeeds, so a recipe
  // may ask for fewer states there rather than run tens of thousands of episodes.
  int start_states = 0;
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
  // fails: matching all its states would match its failures too.
  bool expert_successful = false;
  // Or record pi_b where it actually takes over: one episode from each of S_a's training
  // states (not the held-out ones), pi_b in control from there (`expert: {after_handover:
  // true}`). When pi_b was trained to take over from pi_a (a `lead_in`), its own start's
  // states are not the ones it succeeds from in the task; matching them leads pi_ab away.
  bool expert_after_handover = false;
  // The window pi_ab's own training episodes run in (`training: {when: ..., max_steps: N}`;
  // by default the interval): episodes start at S_a, where the interval begins, and may run
  // on past where the switch must hand over, so that pi_ab does not learn to hand over at
  // the very edge of its own episodes (the reference trains Hurdle's walk->jump from 4 to
  // 2 m before the curb and evaluates it from 4 to 3 m; pick->pick until the box lifts off,
  // where the switch is forced after 30 steps).
  std::vector<Condition> training_when;
  int training_max_steps = 0;

  // `rule` with the training window as its interval.
  Transition window(const Transition& rule) const;

  // Reads entry `t` of `transitions:` (its rule already read as `rule`) over the task's
  // feature names; task_features gives a sub-task's, for `expert.task`. `env` is left for
  // the composite recipe to set (it knows the task).
  static TransitionTrainingSpec read(const Section& t, const Transition& rule, const std::vector<std::string>& features,
                                     const std::function<std::vector<std::string>(const std::string&)>& task_features);
};

}  // namespace segue
