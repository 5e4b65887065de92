#include "hrl/skill.h"

#include <algorithm>
#include <filesystem>

#include "core/assets.h"
#include "environments/registry.h"

namespace segue {

std::vector<Skill> read_skills(const Section& section, const EnvSpec& task) {
  std::vector<Skill> skills;
  const std::vector<std::string> tasks = task_names();
  auto is_task = [&](const std::string& t) { return std::find(tasks.begin(), tasks.end(), t) != tasks.end(); };
  for (const auto& name : section.keys()) {
    Section s = section.sub(name);
    Skill k;
    k.name = name;
    std::string file = s.require<std::string>("policy");
    k.policy_path = repo_path(file);
    if (!std::filesystem::exists(k.policy_path))
      throw s.error("policy", "no such policy file '" + file + "'");
    try {
      k.policy = Policy::load(k.policy_path);
    } catch (const Error& e) {
      throw s.error("policy", e.what());
    }
    std::vector<int> slice = s.get("obs", std::vector<int>{0, k.policy.obs_dim()}, Range::non_negative());
    if (slice.size() != 2 || slice[0] < 0 || slice[1] > task.obs_dim || slice[1] - slice[0] != k.policy.obs_dim())
      throw s.error("obs", "policy '" + file + "' takes " + std::to_string(k.policy.obs_dim()) +
                               " observation numbers; the slice must be [begin, end) within task '" +
                               task.name + "''s " + std::to_string(task.obs_dim));
    if (k.policy.act_dim() != task.act_dim)
      throw s.error("policy", "'" + file + "' acts in " + std::to_string(k.policy.act_dim()) +
                                  " dimensions, task '" + task.name + "' in " + std::to_string(task.act_dim));
    k.obs_begin = slice[0];
    k.obs_end = slice[1];
    const std::string stem = std::filesystem::path(file).stem().string();
    k.task = s.get<std::string>("task", is_task(stem) ? stem : "");
    if (!k.task.empty() && !is_task(k.task)) throw s.error("task", "unknown task '" + k.task + "'");
    skills.push_back(std::move(k));
  }
  if (skills.empty()) throw section.error("", "names no skills");
  return skills;
}

int skill_index(const std::vector<Skill>& skills, const std::string& name) {
  for (size_t i = 0; i < skills.size(); ++i)
    if (skills[i].name == name) return static_cast<int>(i);
  return -1;
}

}  // namespace segue
