#include "hrl/transition_training_spec.h"

namespace segue {

Transition TransitionTrainingSpec::window(const Transition& rule) const {
  Transition w = rule;
  w.when = training_when, w.max_steps = training_max_steps;
  return w;
}

TransitionTrainingSpec TransitionTrainingSpec::read(
    const Section& t, const Transition& rule, const std::vector<std::string>& features,
    const std::function<std::vector<std::string>(const std::string&)>& task_features) {
  TransitionTrainingSpec s;
  // The default 0 stands for an absent key (the pipeline's collect.start_states): a default
  // is not range-checked, a value written is.
  s.start_states = t.get<int>("start_states", 0, Range::positive());
  Section w = t.sub("training");
  if (w.has("when") || w.has("max_steps")) {
    if (w.has("when")) s.training_when = read_when(w, features);
    s.training_max_steps = w.get<int>("max_steps", 0, Range::positive());
  } else if (t.has("training") && !w.has("env")) {
    throw t.error("training", "give its window (when and/or max_steps) or its env");
  } else {
    s.training_when = rule.when, s.training_max_steps = rule.max_steps;
  }
  s.expert_when = rule.when;
  if (!t.has("expert")) return s;
  Section e = t.sub("expert");
  s.expert_task = e.get<std::string>("task", "");
  s.expert_successful = e.get<bool>("successful", false);
  s.expert_after_handover = e.get<bool>("after_handover", false);
  if (s.expert_task.empty()) {
    if (e.has("when")) s.expert_when = read_when(e, features);  // else the interval
    return s;
  }
  if (s.expert_after_handover) throw e.error("after_handover", "S_a's states are this task's; not with expert.task");
  if (!e.has("steps") && !e.has("when"))
    throw e.error("task", "give pi_b's window on it: expert.steps and/or expert.when (over its features)");
  std::vector<std::string> own;
  try {
    own = task_features ? task_features(s.expert_task) : std::vector<std::string>{};
  } catch (const Error& err) {
    throw e.error("task", err.what());
  }
  s.expert_when = read_when(e, own);
  s.expert_steps = e.get<int>("steps", 0, Range::positive());
  return s;
}

}  // namespace segue
