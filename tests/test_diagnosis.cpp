// segue diagnose (hrl/diagnosis.h): the hand-over rates equal a by-hand replay from the
// same S_a states with the shipped forward->balance pi_ab and q_ab, each skill alone is
// its own task's push-free evaluation, and the evaluation episodes it groups are
// report's, episode for episode.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "core/assets.h"
#include "environments/registry.h"
#include "hrl/collection.h"
#include "hrl/diagnosis.h"
#include "tests/transition_fixture.h"

namespace segue {

namespace {

// handover_rates by hand: pi_ab's path from each state of S_a, then pi_b from points on it.
HandOverRates replay(const CompositeRecipe& r, const Policy& pi_ab, const Policy& q_ab,
                     const StartStates& starts, int points) {
  const Transition& tr = r.meta.transitions()[0];
  const Skill& b = r.skills[tr.to];
  const int max_steps = r.pipeline.switching.max_subtask_steps, n = starts.size();
  auto env = r.make_env();
  TransitionController after(r.skills, r.meta, {}, SwitchRule::IntervalEnd);
  std::vector<float> obs(r.spec.obs_dim), act(r.spec.act_dim), q(2);
  std::vector<double> f(r.spec.feature_names.size()), state;
  HandOverRates h;
  h.starts = n;
  h.along.assign(points, 0.0);
  h.with_q = 0;
  double q_point = 0;
  int q_counted = 0;
  struct Walked {
    std::vector<std::vector<double>> path;  // the state at each of pi_ab's steps
    int q_at = -1;
    bool fell = false;
  };
  std::vector<Walked> walked(n);
  double completed = 0, length = 0;
  for (int i = 0; i < n; ++i) {
    Walked& w = walked[i];
    starts.state(i, state);
    env->restore_state(state, obs.data());
    for (int t = 0;; ++t) {
      w.path.emplace_back();
      env->save_state(w.path.back());
      q_ab.act(obs.data(), 1, q.data());
      if (w.q_at < 0 && q[1] > q[0]) w.q_at = t;
      pi_ab.act(obs.data() + b.obs_begin, 1, act.data());
      StepResult sr = env->step(act.data(), obs.data());
      env->features(f.data());
      if ((w.fell = sr.terminated)) break;
      if (sr.truncated || !tr.running(f.data(), t + 1)) {
        w.path.emplace_back();
        env->save_state(w.path.back());
        break;
      }
    }
    if (!w.fell) ++completed, length += double(w.path.size() - 1);
  }
  if (completed > 0) length /= completed;
  for (Walked& w : walked) {
    const int last = int(w.path.size()) - 1;
    h.interval_steps += w.fell ? w.path.size() : last;  // the forced switch's state is one past pi_ab's last
    if (w.q_at < 0 && !w.fell) w.q_at = last;
    if (!w.fell) q_point += double(w.q_at) / last, ++q_counted;
    auto succeeds = [&](int k) {
      if (k > last) return false;  // past pi_ab's fall
      env->restore_state(w.path[k], obs.data());
      return run_subtask(*env, after, tr.to, obs.data(), 1, max_steps);
    };
    h.at_start += succeeds(0);
    if (!w.fell) h.at_end += succeeds(last);
    // A fallen path's points lie along the completed paths' mean length (its own if none completed).
    const double span = w.fell && completed > 0 ? length : last;
    bool won = false;
    for (int j = 0; j < points; ++j) {
      const bool ok = succeeds(int(std::lround(j * span / (points - 1))));
      h.along[j] += ok;
      won |= ok;
    }
    if (w.q_at >= 0) {
      const bool ok = succeeds(w.q_at);
      h.with_q += ok;
      won |= ok;
    }
    h.oracle += won;
    h.fell += w.fell;
  }
  h.at_start /= n, h.at_end /= n, h.with_q /= n, h.oracle /= n, h.fell /= n, h.interval_steps /= n;
  for (double& a : h.along) a /= n;
  if (q_counted) h.q_progress = q_point / q_counted;
  return h;
}

void expect_equal(const HandOverRates& h, const HandOverRates& want) {
  EXPECT_EQ(h.starts, want.starts);
  EXPECT_DOUBLE_EQ(h.at_start, want.at_start);
  EXPECT_DOUBLE_EQ(h.at_end, want.at_end);
  EXPECT_DOUBLE_EQ(h.with_q, want.with_q);
  EXPECT_DOUBLE_EQ(h.oracle, want.oracle);
  EXPECT_DOUBLE_EQ(h.fell, want.fell);
  EXPECT_DOUBLE_EQ(h.interval_steps, want.interval_steps);
  EXPECT_DOUBLE_EQ(h.q_progress, want.q_progress);
  ASSERT_EQ(h.along.size(), want.along.size());
  for (size_t j = 0; j < want.along.size(); ++j) EXPECT_DOUBLE_EQ(h.along[j], want.along[j]) << "point " << j;
  // The best fixed point: the most won, the earlier on a tie.
  size_t best = 0;
  for (size_t j = 1; j < want.along.size(); ++j)
    if (want.along[j] > want.along[best]) best = j;
  EXPECT_DOUBLE_EQ(h.best_fixed(), want.along[best]);
  EXPECT_DOUBLE_EQ(h.best_fixed_at(), double(best) / double(want.along.size() - 1));
  EXPECT_LE(h.best_fixed(), h.oracle);
}

}  // namespace

TEST_F(TransitionTraining, HandOverRatesMatchAByHandReplay) {
  CompositeRecipe r = tiny({"methods.transitions=" + repo_path("assets/policies/walker/patrol")});
  const auto trained = load_transition_artefacts(r, r.transitions_dir, "policy.pt", /*with_q=*/true);
  ASSERT_TRUE(trained[0].policy && trained[0].q);
  const Policy &pi_ab = *trained[0].policy, &q_ab = *trained[0].q;
  const int max_steps = r.pipeline.switching.max_subtask_steps, points = 4;
  StartStates starts = collect_start_states(r, 0, 8, 5);
  SwitchInterval interval(r.make_env, r.skills, r.meta, 0, starts, pi_ab, {}, 1, max_steps);
  const HandOverRates h = handover_rates(interval, &q_ab, points);
  const HandOverRates want = replay(r, pi_ab, q_ab, starts, points);
  ASSERT_EQ(h.starts, 8);
  ASSERT_GT(want.q_progress, -1);
  expect_equal(h, want);
  // pi_b (balance) falls when it takes over from the walk at once; pi_ab's hand-over helps.
  EXPECT_LT(h.at_start, h.at_end);
  // Without q_ab there is no q_ab column.
  SwitchInterval again(r.make_env, r.skills, r.meta, 0, starts, pi_ab, {}, 1, max_steps);
  const HandOverRates plain = handover_rates(again, nullptr, points);
  EXPECT_EQ(plain.with_q, -1);
  EXPECT_DOUBLE_EQ(plain.at_end, h.at_end);

  // States from which pi_ab falls inside the interval (6% of Patrol's) beside some it
  // completes: a fallen path's points lie along the completed paths' length, those past
  // the fall lost.
  StartStates many = collect_start_states(r, 0, 48, 6), mixed = many;
  mixed.states.clear(), mixed.obs.clear();
  SwitchInterval probe(r.make_env, r.skills, r.meta, 0, many, pi_ab, {}, 1, max_steps);
  SwitchInterval::Path path;
  int fell = 0, completed = 0;
  for (int i = 0; i < many.size() && (fell < 2 || completed < 3); ++i) {
    probe.walk(i, nullptr, path);
    if (path.fell ? fell++ >= 2 : completed++ >= 3) continue;  // keep two fallen, three completed
    mixed.states.insert(mixed.states.end(), many.states.begin() + size_t(i) * many.state_dim,
                        many.states.begin() + size_t(i + 1) * many.state_dim);
    mixed.obs.insert(mixed.obs.end(), many.obs.begin() + size_t(i) * many.obs_dim,
                     many.obs.begin() + size_t(i + 1) * many.obs_dim);
  }
  ASSERT_GE(fell, 1) << "pi_ab completed every interval from 48 states";
  SwitchInterval cut(r.make_env, r.skills, r.meta, 0, mixed, pi_ab, {}, 1, max_steps);
  const HandOverRates hf = handover_rates(cut, &q_ab, points);
  EXPECT_GT(hf.fell, 0);
  EXPECT_LT(hf.fell, 1);
  expect_equal(hf, replay(r, pi_ab, q_ab, mixed, points));
}

TEST_F(TransitionTraining, DiagnosisGroupsReportsEpisodesByHowTheyEnded) {
  CompositeRecipe r = tiny({"methods.transitions=" + repo_path("assets/policies/walker/patrol"),
                            "eval.seeds=[0, 1]", "eval.episodes=3"});
  const Diagnosis d = diagnose(r, "tp+q", 4, 3, 3, 7, 1);
  ASSERT_EQ(d.transitions.size(), 1u);
  EXPECT_EQ(d.transitions[0].transition, "forward-balance");
  EXPECT_EQ(d.transitions[0].starts, 4);
  ASSERT_EQ(d.episodes, 6);
  // The same episodes as the evaluation `segue report` runs for the method.
  EvalResult want;
  for (int seed : {0, 1}) want.append(evaluate(r.make_env, method_controllers(r, "tp+q"), 3, uint64_t(seed), 1));
  EXPECT_DOUBLE_EQ(d.success_count_mean, summarize(want.success_counts).mean);
  int episodes = 0;
  const std::set<std::string> known{"forward", "backward", "balance", "forward->balance"};
  for (size_t i = 0; i < d.ends.size(); ++i) {
    const EpisodeEnd& e = d.ends[i];
    episodes += e.episodes;
    EXPECT_TRUE(known.count(e.in_control)) << e.in_control;
    EXPECT_TRUE(e.how == "success" || e.how == "terminated" || e.how == "time limit") << e.how;
    if (i > 0) EXPECT_LE(e.episodes, d.ends[i - 1].episodes) << "most frequent first";
    int matching = 0;
    for (size_t k = 0; k < want.returns.size(); ++k)
      matching += want.ended_under[k] == e.in_control && int(std::lround(want.success_counts[k])) == e.success_count &&
                  (want.successes[k] ? "success" : want.terminated[k] ? "terminated" : "time limit") == e.how;
    EXPECT_EQ(matching, e.episodes) << e.in_control << " " << e.success_count << " " << e.how;
  }
  EXPECT_EQ(episodes, 6);
  // The JSON carries the same numbers.
  const std::string json = diagnosis_json(d);
  EXPECT_NE(json.find("\"transition\": \"forward-balance\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"episodes\": 6"), std::string::npos) << json;
}

TEST_F(TransitionTraining, EachSkillAloneRunsItsOwnTaskPushFree) {
  CompositeRecipe r = tiny({"skills.balance.task=walker_balance"});
  ASSERT_EQ(r.skills.size(), 3u);
  EXPECT_EQ(r.skills[0].task, "walker_forward");  // named after its policy file
  EXPECT_EQ(r.skills[2].task, "walker_balance");
  // The balance alone against its task built here: reference settings, no pushes.
  const Recipe settings = Recipe::parse("{push_prob: 0}", "push-free");
  const EvalResult want = evaluate_policy(r.skills[2].policy, task_factory("walker_balance", settings.root()), 6, 3, 1);
  const SkillAlone a = skill_alone(r.skills[2], 6, 3, 1);
  EXPECT_EQ(a.task, "walker_balance");
  EXPECT_EQ(a.episodes, 6);
  EXPECT_DOUBLE_EQ(a.success, want.success_rate());
  // With pushes (the task's default) the episodes differ: the setting took effect.
  const EvalResult pushed = evaluate_policy(r.skills[2].policy, reference_task_factory("walker_balance"), 6, 3, 1);
  EXPECT_NE(summarize(pushed.returns).mean, summarize(want.returns).mean);
  // A task the policy does not fit, or no task at all, is refused naming the key.
  try {
    CompositeRecipe bad = tiny({"skills.balance.task=walker_jump"});
    skill_alone(bad.skills[2], 1, 0, 1);
    ADD_FAILURE() << "a 28-number task for a 26-number policy was run";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("skills.balance.task"), std::string::npos) << e.what();
  }
  try {
    tiny({"skills.balance.task=walker_balanse"});
    ADD_FAILURE() << "an unknown task was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("skills.balance.task"), std::string::npos) << e.what();
  }
}

}  // namespace segue
