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

TEST_F(TransitionTraining, HandOverRatesMatchAByHandReplay) {
  CompositeRecipe r = tiny({"methods.transitions=" + repo_path("assets/policies/walker/patrol")});
  const auto trained = load_transition_artefacts(r, r.transitions_dir, "policy.pt", /*with_q=*/true);
  ASSERT_TRUE(trained[0].policy && trained[0].q);
  const Policy &pi_ab = *trained[0].policy, &q_ab = *trained[0].q;
  const Transition& tr = r.meta.transitions()[0];
  const Skill& b = r.skills[tr.to];
  const int max_steps = r.pipeline.switching.max_subtask_steps, points = 4;
  StartStates starts = collect_start_states(r, 0, 8, 5);
  SwitchInterval interval(r.make_env, r.skills, r.meta, 0, starts, pi_ab, {}, 1, max_steps);
  const HandOverRates h = handover_rates(interval, &q_ab, points);
  ASSERT_EQ(h.starts, 8);

  auto env = r.make_env();
  TransitionController after(r.skills, r.meta, {}, SwitchRule::IntervalEnd);
  std::vector<float> obs(r.spec.obs_dim), act(r.spec.act_dim), q(2);
  std::vector<double> f(r.spec.feature_names.size()), state;
  double at_start = 0, at_end = 0, with_q = 0, oracle = 0, fell_share = 0, steps = 0, q_point = 0;
  int q_counted = 0;
  for (int i = 0; i < starts.size(); ++i) {
    starts.state(i, state);
    // pi_ab's path through the interval: the state at each of its steps.
    std::vector<std::vector<double>> path;
    int q_at = -1;
    bool fell = false;
    env->restore_state(state, obs.data());
    for (int t = 0;; ++t) {
      path.emplace_back();
      env->save_state(path.back());
      q_ab.act(obs.data(), 1, q.data());
      if (q_at < 0 && q[1] > q[0]) q_at = t;
      pi_ab.act(obs.data() + b.obs_begin, 1, act.data());
      StepResult sr = env->step(act.data(), obs.data());
      env->features(f.data());
      if ((fell = sr.terminated)) break;
      if (sr.truncated || !tr.running(f.data(), t + 1)) {
        path.emplace_back();
        env->save_state(path.back());
        break;
      }
    }
    const int last = int(path.size()) - 1;
    steps += fell ? path.size() : last;  // pi_ab's steps: the forced switch's state is one past its last
    if (q_at < 0 && !fell) q_at = last;
    if (!fell) q_point += double(q_at) / last, ++q_counted;
    auto succeeds = [&](int k) {
      env->restore_state(path[k], obs.data());
      return run_subtask(*env, after, tr.to, obs.data(), 1, max_steps);
    };
    at_start += succeeds(0);
    if (!fell) at_end += succeeds(last);
    bool won = false;
    for (int j = 0; j < points; ++j) won |= succeeds(int(std::lround(double(j) * last / (points - 1))));
    if (q_at >= 0) {
      const bool ok = succeeds(q_at);
      with_q += ok;
      won |= ok;
    }
    oracle += won;
    fell_share += fell;
  }
  EXPECT_DOUBLE_EQ(h.at_start, at_start / 8);
  EXPECT_DOUBLE_EQ(h.at_end, at_end / 8);
  EXPECT_DOUBLE_EQ(h.with_q, with_q / 8);
  EXPECT_DOUBLE_EQ(h.oracle, oracle / 8);
  EXPECT_DOUBLE_EQ(h.fell, fell_share / 8);
  EXPECT_DOUBLE_EQ(h.interval_steps, steps / 8);
  ASSERT_GT(q_counted, 0);
  EXPECT_DOUBLE_EQ(h.q_progress, q_point / q_counted);
  // pi_b (balance) falls when it takes over from the walk at once; pi_ab's hand-over helps.
  EXPECT_LT(h.at_start, h.at_end);
  // Without q_ab there is no q_ab column.
  SwitchInterval again(r.make_env, r.skills, r.meta, 0, starts, pi_ab, {}, 1, max_steps);
  const HandOverRates plain = handover_rates(again, nullptr, points);
  EXPECT_EQ(plain.with_q, -1);
  EXPECT_DOUBLE_EQ(plain.at_end, h.at_end);
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
