#pragma once
// A pretrained skill as a composite task uses it: its policy and the slice of the task's
// observation it was trained on (the walk policy sees the first 26 of Hurdle's 28).
#include <string>
#include <vector>

#include "algorithms/policy.h"
#include "core/recipe.h"

namespace segue {

struct Skill {
  std::string name;
  std::string policy_path;
  Policy policy;
  int obs_begin = 0, obs_end = 0;  // [begin, end) of the task observation
  // Its own task, where `segue diagnose` runs it alone: `task:`, by default the policy
  // file's name where that names a task (walker_jump.pt); "" when neither does.
  std::string task;
};

// Reads the `skills:` mapping  name: {policy: FILE, obs: [begin, end], task: NAME}  (obs
// defaults to the first policy.obs_dim() numbers). Refuses missing files and sizes that do not fit.
std::vector<Skill> read_skills(const Section& skills, const EnvSpec& task);
int skill_index(const std::vector<Skill>& skills, const std::string& name);  // -1 if absent

}  // namespace segue
