#include "hrl/diagnosis.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <tuple>

#include "core/assets.h"
#include "environments/registry.h"
#include "hrl/collection.h"

namespace segue {

double HandOverRates::best_fixed() const { return along.empty() ? 0.0 : *std::max_element(along.begin(), along.end()); }

double HandOverRates::best_fixed_at() const {
  if (along.size() < 2) return 0.0;
  return double(std::max_element(along.begin(), along.end()) - along.begin()) / double(along.size() - 1);
}

HandOverRates handover_rates(SwitchInterval& interval, const Policy* q_ab, int points) {
  if (points < 2) throw Error("hand-over rates: points must be at least 2 (the interval's start and end)");
  HandOverRates r;
  r.starts = interval.starts();
  // pi_ab's path from every state first: a path pi_ab fell on is cut short, so its points
  // are placed on the length of the paths it completed (a fixed point does not know of the
  // fall to come), and those past the fall are lost.
  std::vector<SwitchInterval::Path> paths(size_t(r.starts));
  double completed = 0, length = 0;
  for (int i = 0; i < r.starts; ++i) {
    interval.walk(i, q_ab, paths[size_t(i)]);
    if (!paths[size_t(i)].fell) ++completed, length += double(paths[size_t(i)].states.size() - 1);
  }
  if (completed > 0) length /= completed;
  std::vector<int> judged;  // pi_b's outcome from each point: -1 not yet tried
  r.along.assign(size_t(points), 0.0);
  int q_counted = 0;
  double q_won = 0, q_progress = 0;
  for (const SwitchInterval::Path& path : paths) {
    const int last = int(path.states.size()) - 1;
    int q_at = -1;  // q_ab's hand-over: its first switch, else the forced one (+inf)
    for (int k = 0; k < int(path.gap.size()) && q_at < 0; ++k)
      if (path.gap[k] > 0) q_at = k;
    judged.assign(path.states.size(), -1);
    auto judge = [&](int k) {
      if (k > last) return false;  // pi_ab fell before this point
      if (judged[k] < 0) judged[k] = interval.hand_over_at(path, size_t(k));
      return judged[k] == 1;
    };
    r.at_start += judge(0);
    if (!path.fell) r.at_end += judge(last);
    const double span = path.fell && completed > 0 ? length : double(last);
    bool won = false;
    for (int j = 0; j < points; ++j) {
      const bool ok = judge(int(std::lround(double(j) * span / (points - 1))));
      r.along[size_t(j)] += ok;
      won |= ok;
    }
    if (q_at >= 0) {
      const bool ok = judge(q_at);
      q_won += ok;
      won |= ok;
      if (!path.fell) q_progress += double(q_at) / std::max(last, 1), ++q_counted;
    }
    r.oracle += won;
    r.fell += path.fell;
    r.interval_steps += path.steps;
  }
  const double n = std::max(1, r.starts);
  r.at_start /= n, r.at_end /= n, r.oracle /= n, r.fell /= n, r.interval_steps /= n;
  for (double& a : r.along) a /= n;
  if (q_ab) r.with_q = q_won / n;
  if (q_counted) r.q_progress = q_progress / q_counted;
  return r;
}

SkillAlone skill_alone(const Skill& skill, int episodes, uint64_t seed, int threads) {
  SkillAlone a{skill.name, skill.task};
  if (skill.task.empty()) return a;
  // The walker's sub-tasks push the walker by default (the reference trains them so); the
  // composite tasks never do, so the skill runs push-free. A task without pushes leaves
  // the key unread and runs at its reference settings.
  const Recipe settings = Recipe::parse("{push_prob: 0}", "push-free " + skill.task);
  const EnvFactory own = task_factory(skill.task, settings.root());
  const EnvSpec spec = own()->spec();
  if (spec.obs_dim != skill.policy.obs_dim() || spec.act_dim != skill.policy.act_dim())
    throw Error("key 'skills." + skill.name + ".task': task '" + skill.task + "' observes " +
                std::to_string(spec.obs_dim) + " numbers, skill '" + skill.name + "''s policy " +
                std::to_string(skill.policy.obs_dim()));
  a.episodes = episodes;
  a.success = evaluate_policy(skill.policy, own, episodes, seed, threads).success_rate();
  return a;
}

std::vector<EpisodeEnd> episode_ends(const EvalResult& e) {
  std::map<std::tuple<std::string, int, std::string>, int> counts;
  for (size_t i = 0; i < e.returns.size(); ++i) {
    const std::string how = e.successes[i] ? "success" : e.terminated[i] ? "terminated" : "time limit";
    ++counts[{e.ended_under[i], int(std::lround(e.success_counts[i])), how}];
  }
  std::vector<EpisodeEnd> out;
  for (const auto& [key, n] : counts) out.push_back({std::get<0>(key), std::get<1>(key), std::get<2>(key), n});
  std::stable_sort(out.begin(), out.end(), [](const EpisodeEnd& a, const EpisodeEnd& b) { return a.episodes > b.episodes; });
  return out;
}

Diagnosis diagnose(const CompositeRecipe& r, const std::string& method, int starts, int points, int episodes,
                   uint64_t seed, int threads) {
  if (r.transitions_dir.empty())
    throw Error(r.file + ": key 'methods.transitions' is not set: no transition policies to diagnose");
  Diagnosis d;
  d.task = r.task, d.method = method;
  const std::vector<TransitionArtefacts> trained =
      load_transition_artefacts(r, repo_path(r.transitions_dir), "policy.pt", /*with_q=*/true);
  // With TP's: S_a collected as the pipeline collects it, episodes carried on after pi_b as
  // switch training carries them (switch.lookahead > 1).
  std::vector<TransitionArtefacts> policies = trained;
  for (auto& a : policies) a.q.reset();
  const SwitchConfig& sw = r.pipeline.switching;
  for (int t = 0; t < int(trained.size()); ++t) {
    if (!trained[t].policy)
      throw Error(r.transitions_dir + "/" + r.transition_name(t) + ": no policy.pt (pi_ab) to diagnose");
    StartStates s = collect_start_states(r, t, starts, mix_seed(seed, t), policies, kStartStateEpisodes, nullptr, threads);
    SwitchInterval interval(r.make_env, r.skills, r.meta, t, std::move(s), *trained[t].policy, policies, sw.lookahead,
                            sw.max_subtask_steps);
    HandOverRates h = handover_rates(interval, trained[t].q ? &*trained[t].q : nullptr, points);
    h.transition = r.transition_name(t);
    d.transitions.push_back(h);
  }
  for (const Skill& k : r.skills) try {
      d.skills.push_back(skill_alone(k, starts, seed, threads));
    } catch (const Error& e) {
      throw Error(r.file + ": " + e.what());
    }
  EvalResult all;
  const ControllerFactory controllers = method_controllers(r, method);
  for (int s : r.eval_seeds) all.append(evaluate(r.make_env, controllers, episodes, uint64_t(s), threads));
  d.episodes = int(all.returns.size());
  d.success_count_mean = summarize(all.success_counts).mean;
  d.ends = episode_ends(all);
  return d;
}

namespace {
std::string num(double x, int digits = 3) {
  if (x < 0) return "null";
  std::ostringstream o;
  o.precision(digits);
  o << std::fixed << x;
  return o.str();
}
}  // namespace

std::string diagnosis_text(const Diagnosis& d) {
  std::ostringstream o;
  char line[256];
  o << d.task << ": hand-overs from " << (d.transitions.empty() ? 0 : d.transitions[0].starts)
    << " states of S_a per transition, pi_b judged as in switch training (share that succeed)\n";
  std::snprintf(line, sizeof line, "  %-22s %9s %8s %10s %15s %11s %11s %10s %9s\n", "transition", "at start",
                "at end", "with q_ab", "best fixed (at)", "per state", "pi_ab fell", "q_ab at", "interval");
  o << line;
  for (const HandOverRates& h : d.transitions) {
    std::snprintf(line, sizeof line, "  %-22s %9.2f %8.2f %10s %8.2f (%.2f) %11.2f %11.2f %10s %6.0f st\n",
                  h.transition.c_str(), h.at_start, h.at_end, h.with_q < 0 ? "-" : num(h.with_q, 2).c_str(),
                  h.best_fixed(), h.best_fixed_at(), h.oracle, h.fell, h.q_progress < 0 ? "-" : num(h.q_progress, 2).c_str(),
                  h.interval_steps);
    o << line;
  }
  o << "  (best fixed: the best of the points along pi_ab's path, the same for every state; per state: the\n"
       "   best of them for each state, in hindsight; at: where on the interval, 0 its start, 1 its end)\n";
  o << "each skill alone from its own start (its own task, push-free; share that succeed)\n";
  for (const SkillAlone& a : d.skills) {
    if (a.task.empty())
      std::snprintf(line, sizeof line, "  %-22s %-16s %9s\n", a.skill.c_str(), "(no task)", "-");
    else
      std::snprintf(line, sizeof line, "  %-22s %-16s %9.2f  (%d episodes)\n", a.skill.c_str(), a.task.c_str(),
                    a.success, a.episodes);
    o << line;
  }
  std::snprintf(line, sizeof line, "%s's %d evaluation episodes (mean success count %.2f) ended:\n", d.method.c_str(),
                d.episodes, d.success_count_mean);
  o << line;
  std::snprintf(line, sizeof line, "  %8s  %-22s %5s  %s\n", "episodes", "in control", "count", "how");
  o << line;
  for (const EpisodeEnd& e : d.ends) {
    std::snprintf(line, sizeof line, "  %8d  %-22s %5d  %s\n", e.episodes, e.in_control.empty() ? "-" : e.in_control.c_str(),
                  e.success_count, e.how.c_str());
    o << line;
  }
  return o.str();
}

std::string diagnosis_json(const Diagnosis& d) {
  std::ostringstream o;
  o << "{\"task\": \"" << d.task << "\", \"method\": \"" << d.method << "\", \"transitions\": [";
  for (size_t i = 0; i < d.transitions.size(); ++i) {
    const HandOverRates& h = d.transitions[i];
    o << (i ? ", " : "") << "{\"transition\": \"" << h.transition << "\", \"starts\": " << h.starts
      << ", \"at_start\": " << num(h.at_start) << ", \"at_end\": " << num(h.at_end) << ", \"with_q\": " << num(h.with_q)
      << ", \"best_fixed\": " << num(h.best_fixed()) << ", \"best_fixed_at\": " << num(h.best_fixed_at())
      << ", \"along\": [";
    for (size_t j = 0; j < h.along.size(); ++j) o << (j ? ", " : "") << num(h.along[j]);
    o << "]"
      << ", \"oracle\": " << num(h.oracle) << ", \"pi_ab_fell\": " << num(h.fell)
      << ", \"q_progress\": " << num(h.q_progress) << ", \"interval_steps\": " << num(h.interval_steps, 1) << "}";
  }
  o << "], \"skills\": [";
  for (size_t i = 0; i < d.skills.size(); ++i) {
    const SkillAlone& a = d.skills[i];
    o << (i ? ", " : "") << "{\"skill\": \"" << a.skill << "\", \"task\": \"" << a.task
      << "\", \"episodes\": " << a.episodes << ", \"success\": " << num(a.success) << "}";
  }
  o << "], \"episodes\": " << d.episodes << ", \"success_count_mean\": " << num(d.success_count_mean)
    << ", \"ends\": [";
  for (size_t i = 0; i < d.ends.size(); ++i) {
    const EpisodeEnd& e = d.ends[i];
    o << (i ? ", " : "") << "{\"in_control\": \"" << e.in_control << "\", \"success_count\": " << e.success_count
      << ", \"how\": \"" << e.how << "\", \"episodes\": " << e.episodes << "}";
  }
  o << "]}";
  return o.str();
}

}  // namespace segue
