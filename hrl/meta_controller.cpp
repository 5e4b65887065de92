#include "hrl/meta_controller.h"

#include <algorithm>
#include <cmath>

namespace segue {
namespace {

int find_skill(const Section& s, const std::string& key, const std::vector<Skill>& skills) {
  std::string name = s.require<std::string>(key);
  int i = skill_index(skills, name);
  if (i < 0) {
    std::string known;
    for (const auto& k : skills) known += (known.empty() ? "" : ", ") + k.name;
    throw s.error(key, "no skill named '" + name + "' (skills: " + known + ")");
  }
  return i;
}

}  // namespace

std::vector<Condition> read_when(const Section& s, const std::vector<std::string>& features) {
  std::vector<Condition> when;
  if (!s.has("when")) return when;
  Section w = s.sub("when");
  for (const auto& name : w.keys()) {
    auto it = std::find(features.begin(), features.end(), name);
    if (it == features.end()) {
      std::string known;
      for (const auto& f : features) known += (known.empty() ? "" : ", ") + f;
      throw w.error(name, "the task has no feature '" + name + "' (features: " + known + ")");
    }
    std::vector<double> range = w.is_sequence(name) ? w.require<std::vector<double>>(name, Range::any())
                                                    : std::vector<double>(2, w.require<double>(name, Range::any()));
    if (range.size() != 2 || range[0] > range[1]) throw w.error(name, "expects [lo, hi] with lo <= hi");
    when.push_back({int(it - features.begin()), range[0], range[1]});
  }
  return when;
}

MetaController::MetaController(const Section& root, const std::vector<Skill>& skills,
                               const std::vector<std::string>& features) {
  for (const Section& rule : root.items("start"))
    start_.push_back({find_skill(rule, "skill", skills), read_when(rule, features)});
  if (start_.empty()) throw root.error("start", "lists no start skill");
  for (const Section& t : root.items("transitions")) {
    Transition tr;
    tr.from = find_skill(t, "from", skills);
    tr.to = find_skill(t, "to", skills);
    tr.when = read_when(t, features);
    tr.max_steps = t.get<int>("max_steps", 0, Range::positive());  // 0: no cap (not range-checked)
    for (const Transition& other : transitions_)
      if (other.from == tr.from && other.to == tr.to)
        throw t.error("to", "a second transition " + skills[tr.from].name + " -> " + skills[tr.to].name +
                                " (each has one interval and one folder of artefacts)");
    transitions_.push_back(tr);
  }
  if (transitions_.empty()) throw root.error("transitions", "lists no transition");
}

bool Transition::running(const double* features, int steps) const {
  return !capped(steps) && MetaController::holds(when, features);
}

double Transition::progress(const double* entry, const double* f, int steps) const {
  if (max_steps > 0) return double(steps) / max_steps;
  for (const Condition& c : when)
    if (c.hi > c.lo) return std::abs(f[c.feature] - entry[c.feature]) / (c.hi - c.lo);
  return 1.0;
}

bool MetaController::holds(const std::vector<Condition>& when, const double* f) {
  for (const auto& c : when)
    if (f[c.feature] < c.lo || f[c.feature] > c.hi) return false;
  return true;
}

int MetaController::start_skill(const double* f) const {
  for (const auto& [skill, when] : start_)
    if (holds(when, f)) return skill;
  return start_.front().first;
}

int MetaController::active_transition(int skill, const double* f, const std::vector<char>* taken) const {
  for (size_t i = 0; i < transitions_.size(); ++i)
    if (transitions_[i].from == skill && !(taken && (*taken)[i]) && holds(transitions_[i].when, f))
      return static_cast<int>(i);
  return -1;
}

}  // namespace segue
