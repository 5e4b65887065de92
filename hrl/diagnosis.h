#pragma once
// `segue diagnose`: where a composite task's method loses its episodes.
//
// Per transition a->b, from states of S_a (collected With TP, as the method meets them),
// how often pi_b achieves its subtask (judged as switch training judges it, run_subtask)
// when control passes to it
//   at the interval's start       Without TP at the paper's fixed point;
//   at the interval's end         With TP: pi_ab drives the whole interval;
//   where q_ab switches           With TP + Q;
//   at the best fixed point       the one of several points spread along pi_ab's path
//                                 (the same share of it for every state) that wins most:
//                                 what a switch blind to the state could reach;
//   at the best of those points per state, in hindsight (q_ab's among them): what a
//                                 switch that foresaw each hand-over's outcome could reach.
//                                 Where outcomes scatter along the path as chance would,
//                                 it nears 100% whatever the switch could learn: read it
//                                 beside the best fixed point.
// Each skill alone from its own start: its own task (the reference's settings, push-free
// as the composite tasks run), the success rate of its deterministic policy.
// And over the method's evaluation episodes (the recipe's seeds, as `segue report` runs
// them): who was in control when each episode ended, at which success count, and how.
#include <string>
#include <vector>

#include "hrl/composite_recipe.h"
#include "hrl/evaluation.h"
#include "hrl/switch_interval.h"

namespace segue {

struct HandOverRates {
  std::string transition;  // "walk-jump"
  int starts = 0;          // S_a states tried
  double at_start = 0, at_end = 0, oracle = 0;
  std::vector<double> along;  // the rate at each of the oracle's points, in order along pi_ab's path
  // The best fixed point: the most often won of `along` (the earlier on a tie), and where it
  // lies on pi_ab's path (0 its start, 1 its end).
  double best_fixed() const;
  double best_fixed_at() const;
  double with_q = -1;        // -1: no q_ab
  double q_progress = -1;    // mean step of q_ab's hand-over over the interval's length (0 start, 1 end),
                             // over the starts where pi_ab did not fall
  double interval_steps = 0; // mean steps pi_ab drives before the interval ends (or it falls)
  double fell = 0;           // share of starts where pi_ab fell inside the interval
};

// The rates over every state of `interval`'s S_a; `q_ab` may be null. `points` >= 2
// hand-over points are spread evenly along pi_ab's path, its start and end among them (on
// a path pi_ab fell on, along the mean length of the paths it completed, those past the
// fall lost). The oracle counts a start as won when any of them or q_ab's succeeds; the
// best fixed point is the one of them with the most wins over all starts.
HandOverRates handover_rates(SwitchInterval& interval, const Policy* q_ab, int points);

struct SkillAlone {
  std::string skill, task;  // task "": the skill names none (Skill::task)
  int episodes = 0;
  double success = -1;      // -1: not run
};

// `skill` alone on its own task, `episodes` episodes from `seed`.
SkillAlone skill_alone(const Skill& skill, int episodes, uint64_t seed, int threads);

struct EpisodeEnd {
  std::string in_control;  // a skill, or "a->b" while a transition policy drove
  int success_count = 0;
  std::string how;         // "success" (the task done), "terminated" (a fall, a contact), "time limit"
  int episodes = 0;
};

struct Diagnosis {
  std::string task, method;
  std::vector<HandOverRates> transitions;
  std::vector<SkillAlone> skills;
  int episodes = 0;  // evaluation episodes, all seeds
  double success_count_mean = 0;
  std::vector<EpisodeEnd> ends;  // most frequent first
};

// Episodes grouped by how they ended, most frequent first.
std::vector<EpisodeEnd> episode_ends(const EvalResult& result);

// Every part on the recipe's shipped (or --recipe's) artefacts: `starts` states of S_a per
// transition collected from `seed` (and as many episodes of each skill alone), and the
// method's evaluation at `episodes` per seed of the recipe's eval.seeds.
Diagnosis diagnose(const CompositeRecipe& recipe, const std::string& method, int starts, int points,
                   int episodes, uint64_t seed, int threads);

std::string diagnosis_text(const Diagnosis& d);
std::string diagnosis_json(const Diagnosis& d);

}  // namespace segue
