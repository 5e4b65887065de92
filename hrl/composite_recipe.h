#pragma once
// A composite task recipe (experiments/<task>.yaml): the task, its skills, the
// meta-controller's rules (start skill, transition intervals) and the artefacts of each
// method. Adding a composite task means a recipe and a small task class; nothing here.
//
//   task: hurdle
//   env: {}
//   skills:
//     walk: {policy: assets/policies/walker/walker_forward.pt}
//     jump: {policy: assets/policies/walker/walker_jump.pt}
//   start: [{skill: walk}]
//   transitions:
//     - {from: walk, to: jump, when: {curb_ahead: [3, 4]}}
//     - {from: jump, to: walk, when: {curb_behind: [2.5, 3.5]}}
//   methods:
//     single: {policy: assets/policies/walker/single/hurdle.pt}
//     transitions: assets/policies/walker/hurdle   # NAME/policy.pt, q.pt per transition
//   eval: {episodes: 50, seeds: [0, 1, 2], handover_point: fixed}
//   ... and the pipeline's settings (hrl/pipeline_config.h).
#include <set>
#include <string>
#include <vector>

#include "core/recipe.h"
#include "hrl/evaluation.h"
#include "hrl/meta_controller.h"
#include "hrl/pipeline_config.h"
#include "hrl/transition_controller.h"
#include "hrl/transition_training_spec.h"
#include "hrl/skill.h"

namespace segue {

struct CompositeRecipe {
  std::string file, task;
  EnvFactory make_env;
  EnvSpec spec;
  std::vector<Skill> skills;
  MetaController meta;  // the run-time rules: start skill, transition intervals
  std::vector<TransitionTrainingSpec> training;  // per transition, what `segue run` trains it on
  std::string single_policy;    // methods.single.policy ("" when absent)
  std::string transitions_dir;  // methods.transitions ("" when absent)
  PipelineConfig pipeline;
  std::string resolved;         // the recipe as read, defaults included (for run dirs)
  std::set<std::string> defaulted;  // its keys left at their defaults
  std::map<std::string, KeyRule> key_rules;  // each key's type and range (segue keys)
  int eval_episodes = 50;
  std::vector<int> eval_seeds{0, 1, 2};
  // Where Without TP and With TP hand over (eval.handover_point): fixed, as the paper's text
  // says, or at a uniform random point of the interval, as the reference code evaluates.
  HandOverPoint handover_point = HandOverPoint::Fixed;

  // Reads and validates everything (missing skills or policies, sizes that do not fit),
  // then refuses unknown keys.
  static CompositeRecipe load(const std::string& file, const std::vector<std::string>& overrides = {});
  // The recipe for a task name: experiments/<task>.yaml in the source tree.
  static std::string default_file(const std::string& task);
  // "from-to", e.g. "walk-jump": the transition's folder name among the artefacts.
  std::string transition_name(int t) const;
  // "TASK from-to", e.g. "hurdle walk-jump": what the files trained for transition t (S_a,
  // T_b, pi_ab, q_ab, Lee's policy) record they were made for.
  std::string transition_source(int t) const;
  // |S_a| to collect for transition t: its own `start_states`, else collect.start_states.
  int start_state_count(int t) const;
};

// Method names from the paper: single, without-tp, tp, lee, tp+q.
const std::vector<std::string>& method_names();
// The transition artefacts in DIR/NAME/ for each transition: `policy_file` (policy.pt, or
// lee.pt for Lee et al.'s) and, with_q, q.pt, where they exist, checked to fit the task.
std::vector<TransitionArtefacts> load_transition_artefacts(const CompositeRecipe& recipe, const std::string& dir,
                                                          const std::string& policy_file, bool with_q);
// Controllers for `method` on this recipe; throws segue::Error when the method's
// artefacts are not available.
ControllerFactory method_controllers(const CompositeRecipe& recipe, const std::string& method);

}  // namespace segue
