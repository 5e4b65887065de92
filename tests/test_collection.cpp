// Algorithm 1's data: S_a states restore into an environment that then replays pi_a
// exactly; T_b is pi_b's own contiguous trajectory inside its window; files round-trip.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "core/assets.h"
#include "core/run_dir.h"
#include "environments/registry.h"
#include "hrl/collection.h"
#include "tests/temp_dir.h"

namespace segue {
namespace {

// Patrol with the shipped walk and balance skills, pushes off so a replay needs no
// random stream.
CompositeRecipe patrol() {
  return CompositeRecipe::load(CompositeRecipe::default_file("patrol"), {"env.push_prob=0"});
}

// f() must throw a segue::Error whose message contains `message`.
template <class F>
void expect_error(F f, const std::string& message) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one with: " << message;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(Collection, StartStatesAreAtTheIntervalAndReplayPiA) {
  CompositeRecipe r = patrol();
  StartStates s = collect_start_states(r, /*forward -> balance*/ 0, 4, 11);
  ASSERT_EQ(s.size(), 4);
  auto a = r.make_env(), b = r.make_env();
  const Skill& pi_a = r.skills[r.meta.transitions()[0].from];
  std::vector<float> oa(s.obs_dim), ob(s.obs_dim), act(6);
  std::vector<double> f(a->spec().feature_names.size());
  for (int i = 0; i < s.size(); ++i) {
    std::vector<double> state;
    s.state(i, state);
    a->restore_state(state, oa.data());
    ASSERT_EQ(oa, std::vector<float>(s.obs.begin() + i * s.obs_dim, s.obs.begin() + (i + 1) * s.obs_dim));
    a->features(f.data());
    EXPECT_TRUE(MetaController::holds(r.meta.transitions()[0].when, f.data())) << "state " << i;
    // Two environments restored from the state run pi_a identically.
    b->reset(999, ob.data());
    b->restore_state(state, ob.data());
    for (int t = 0; t < 50; ++t) {
      pi_a.policy.act(oa.data() + pi_a.obs_begin, 1, act.data());
      StepResult ra = a->step(act.data(), oa.data());
      pi_a.policy.act(ob.data() + pi_a.obs_begin, 1, act.data());
      StepResult rb = b->step(act.data(), ob.data());
      ASSERT_EQ(oa, ob) << "state " << i << " step " << t;
      if (ra.done() || rb.done()) break;
    }
  }
}

// Collection tests that write their data to files and read it back.
class CollectionFiles : public TempDirTest {
 protected:
  CollectionFiles() : TempDirTest("collect") {}
  // Hurdle (walk->jump's T_b from the windows the jump succeeds from) with stage 13's 38%
  // jump (a test fixture: its failures are what the filter drops), and `expert_extra`
  // (", key: value") added to walk->jump's expert.
  CompositeRecipe hurdle_with_stage13_jump(const std::string& expert_extra) {
    std::string text = read_file(CompositeRecipe::default_file("hurdle"));
    const std::string expert = "successful: true";  // walk -> jump's expert section
    if (text.find(expert) == std::string::npos) throw Error("hurdle.yaml no longer has '" + expert + "'");
    text.insert(text.find(expert) + expert.size(), expert_extra);
    std::ofstream(path("hurdle.yaml")) << text;
    return CompositeRecipe::load(path("hurdle.yaml"), {"skills.jump.policy=tests/data/walker_jump_stage13.pt"});
  }
};

TEST_F(CollectionFiles, DemonstrationsArePiBsOwnStepsInItsWindow) {
  CompositeRecipe r = patrol();
  // forward -> balance: T_b is balance's first 100 steps from its own start.
  Demonstrations d = collect_demonstrations(r, 0, 250, 3);
  ASSERT_EQ(d.size(), 250);
  EXPECT_EQ(d.obs_dim, 26);  // balance's slice of Patrol's 27 numbers
  const Skill& balance = r.skills[r.meta.transitions()[0].to];
  std::vector<float> a(6);
  int episode_starts = 1;
  for (int i = 0; i < d.size(); ++i) {
    // The recorded action is pi_b's action for the recorded observation.
    balance.policy.act(&d.obs[size_t(i) * 26], 1, a.data());
    for (int j = 0; j < 6; ++j) ASSERT_EQ(a[j], d.act[size_t(i) * 6 + j]) << i;
    if (i + 1 < d.size()) {
      bool continues = std::equal(d.next_obs.begin() + i * 26, d.next_obs.begin() + (i + 1) * 26,
                                  d.obs.begin() + (i + 1) * 26);
      episode_starts += !continues;
    }
  }
  // 101 steps per episode (steps 0..100) unless balance fell first: at least 3 episodes.
  EXPECT_GE(episode_starts, 3);
  EXPECT_LE(episode_starts, 250 / 20);

  save(d, path("t_b.pt"));
  Demonstrations back = load_demonstrations(path("t_b.pt"));
  EXPECT_EQ(back.obs, d.obs);
  EXPECT_EQ(back.act, d.act);
  EXPECT_EQ(back.next_obs, d.next_obs);
  EXPECT_EQ(back.done, d.done);
  EXPECT_EQ(back.source, r.spec.name + " forward-balance");
  StartStates s = collect_start_states(r, 0, 2, 5);
  save(s, path("s_a.pt"));
  StartStates s2 = load_start_states(path("s_a.pt"));
  EXPECT_EQ(s2.states, s.states);
  EXPECT_EQ(s2.obs, s.obs);
  EXPECT_EQ(s2.source, back.source);
}

TEST(Collection, ThreadsRunEpisodesSideBySideToTheOneThreadResult) {
  CompositeRecipe r = patrol();
  // 5 states and 333 steps: the last episode taken is cut part-way in both.
  const StartStates one = collect_start_states(r, 0, 5, 11);
  const StartStates three = collect_start_states(r, 0, 5, 11, {}, kStartStateEpisodes, nullptr, /*threads=*/3);
  ASSERT_EQ(one.size(), 5);
  EXPECT_EQ(one.states, three.states);
  EXPECT_EQ(one.obs, three.obs);
  const Demonstrations d1 = collect_demonstrations(r, 0, 333, 12);
  const Demonstrations d3 = collect_demonstrations(r, 0, 333, 12, kDemonstrationEpisodes, nullptr, nullptr, 3);
  ASSERT_EQ(d1.size(), 333);
  EXPECT_EQ(d1.obs, d3.obs);
  EXPECT_EQ(d1.act, d3.act);
  EXPECT_EQ(d1.next_obs, d3.next_obs);
  EXPECT_EQ(d1.done, d3.done);
}

TEST(Collection, StartStatesWhereATransitionPolicyIntoAHandsOver) {
  // On Patrol balance never runs alone: With TP, walk->balance's pi_ab drives the 100
  // balance steps and balance->walk's interval begins the step after. S_a of balance->
  // forward is the state where that hand-over happens, with balance's phase done.
  CompositeRecipe r = patrol();
  const int t = 2;
  ASSERT_EQ(r.transition_name(t), "balance-forward");
  auto trained = load_transition_artefacts(r, repo_path(r.transitions_dir), "policy.pt", false);
  StartStates s = collect_start_states(r, t, 3, 7, trained, 50);
  ASSERT_EQ(s.size(), 3);
  auto env = r.make_env();
  std::vector<float> obs(s.obs_dim);
  std::vector<double> f(env->spec().feature_names.size());
  const auto& names = env->spec().feature_names;
  const int since_turn = int(std::find(names.begin(), names.end(), "since_turn") - names.begin());
  for (int i = 0; i < s.size(); ++i) {
    std::vector<double> state;
    s.state(i, state);
    env->restore_state(state, obs.data());
    env->features(f.data());
    EXPECT_TRUE(MetaController::holds(r.meta.transitions()[t].when, f.data())) << "state " << i;
    EXPECT_EQ(f[since_turn], 101) << "the interval's first state (walk->balance holds to 100)";
  }
}

TEST(Collection, RefusesATransitionThatIsNeverEntered) {
  // Balance -> forward needs a turn first; with a 10-step cap no episode gets there.
  CompositeRecipe capped = CompositeRecipe::load(CompositeRecipe::default_file("patrol"),
                                                 {"env.push_prob=0", "env.max_episode_steps=10"});
  EXPECT_THROW(collect_start_states(capped, 2, 1, 0, {}, 5), Error);
}

}  // namespace segue

#include "hrl/transition_env.h"

namespace segue {

// Runs pi_b in `env` from the observation after a reset until the episode ends: the last
// step's result and the number of steps.
static std::pair<StepResult, int> finish_episode(TransitionEnv& env, const Skill& b, std::vector<float>& obs) {
  std::vector<float> act(env.spec().act_dim);
  int steps = 0;
  StepResult sr;
  do {
    b.policy.act(obs.data(), 1, act.data());
    sr = env.step(act.data(), obs.data());
    ++steps;
  } while (!sr.done());
  return {sr, steps};
}

TEST(TransitionEnv, EpisodesStartInSaAndEndWithTheInterval) {
  CompositeRecipe r = CompositeRecipe::load(CompositeRecipe::default_file("patrol"), {"env.push_prob=0"});
  const Transition& t = r.meta.transitions()[0];  // forward -> balance: since_turn in [0, 100]
  StartStates s = collect_start_states(r, 0, 3, 1);
  const Skill& b = r.skills[t.to];
  TransitionEnv env(r.make_env(), s, t, b.obs_begin, b.obs_end);
  EXPECT_EQ(env.spec().obs_dim, 26);
  std::vector<float> obs(26);
  std::vector<double> f(env.task().spec().feature_names.size());
  for (int episode = 0; episode < 3; ++episode) {
    env.reset(100 + episode, obs.data());
    // The start is one of the S_a observations (its first 26 numbers).
    bool found = false;
    for (int i = 0; i < s.size(); ++i)
      found |= std::equal(obs.begin(), obs.end(), s.obs.begin() + size_t(i) * s.obs_dim);
    EXPECT_TRUE(found);
    auto [sr, steps] = finish_episode(env, b, obs);
    env.features(f.data());
    if (sr.truncated) EXPECT_FALSE(MetaController::holds(t.when, f.data()));  // left the interval
    EXPECT_LE(steps, 101);  // since_turn runs 0..100 from the start state
  }
}

// max_steps: the interval also ends after that many of pi_ab's steps, as a time limit.
TEST(TransitionEnv, MaxStepsEndTheIntervalEarly) {
  CompositeRecipe r = CompositeRecipe::load(CompositeRecipe::default_file("patrol"), {"env.push_prob=0"});
  Transition t = r.meta.transitions()[0];  // forward -> balance: since_turn in [0, 100]
  StartStates s = collect_start_states(r, 0, 3, 1);
  const Skill& b = r.skills[t.to];
  auto run = [&](const Transition& tr, uint64_t seed) {
    TransitionEnv env(r.make_env(), s, tr, b.obs_begin, b.obs_end);
    std::vector<float> obs(26);
    env.reset(seed, obs.data());
    auto [sr, steps] = finish_episode(env, b, obs);
    return std::make_tuple(steps, sr.truncated, sr.info.success);
  };
  t.max_steps = 30;
  for (uint64_t seed : {100, 101, 102}) {
    ASSERT_GT(std::get<0>(run(r.meta.transitions()[0], seed)), 30);  // without the cap it runs on
    // A time limit, not a success: the interval's end was not reached.
    EXPECT_EQ(run(t, seed), std::make_tuple(30, true, false));
  }
}

// expert.task: T_b from pi_b's own sub-task, its first expert.steps steps of each episode.
TEST(Collection, DemonstrationsFromTheSkillsOwnTaskAreItsFirstSteps) {
  CompositeRecipe r = CompositeRecipe::load(CompositeRecipe::default_file("obstacle_course"));
  const int t = 1;  // walk -> crawl
  ASSERT_EQ(r.transition_name(t), "walk-crawl");
  ASSERT_EQ(r.training[t].expert_task, "walker_crawl");
  const int steps = r.training[t].expert_steps;
  Demonstrations d = collect_demonstrations(r, t, steps + 20, 5);
  ASSERT_EQ(d.size(), steps + 20);
  ASSERT_EQ(d.obs_dim, 26);
  // Episode 0 replayed by hand on the crawl's own task: the first `steps` rows are its
  // steps, then episode 1 begins at its reset observation.
  auto env = reference_task_factory("walker_crawl")();
  const Skill& crawl = r.skills[r.meta.transitions()[t].to];
  std::vector<float> obs(26), act(6);
  env->reset(mix_seed(5, 0), obs.data());
  for (int k = 0; k < steps; ++k) {
    ASSERT_EQ(std::vector<float>(d.obs.begin() + k * 26, d.obs.begin() + (k + 1) * 26), obs) << "step " << k;
    crawl.policy.act(obs.data(), 1, act.data());
    if (env->step(act.data(), obs.data()).done()) break;
  }
  env->reset(mix_seed(5, 1), obs.data());
  EXPECT_EQ(std::vector<float>(d.obs.begin() + steps * 26, d.obs.begin() + (steps + 1) * 26), obs);
}

// expert.successful: T_b keeps only the windows after which pi_b succeeds. On Hurdle's
// walk -> jump the window is 2-4 m before the first curb and success is clearing it;
// the expected T_b is rebuilt by replaying each episode of the jump by hand.
TEST_F(CollectionFiles, SuccessfulDemonstrationsAreTheWindowsPiBSucceedsFrom) {
  // Stage 13's jump (38%), so that some windows are dropped whatever the shipped jump's rate.
  CompositeRecipe r = hurdle_with_stage13_jump("");
  const TransitionTrainingSpec& tr = r.training[0];
  ASSERT_TRUE(tr.expert_successful);
  const int count = 300;
  Demonstrations d = collect_demonstrations(r, 0, count, 11);

  auto env = r.make_env();
  const Skill& jump = r.skills[r.meta.transitions()[0].to];
  const int D = jump.obs_end - jump.obs_begin;
  std::vector<float> obs(env->spec().obs_dim), act(env->spec().act_dim), want;
  std::vector<double> f(env->spec().feature_names.size());
  int kept = 0, dropped = 0;
  for (int e = 0; int(want.size()) < count * D; ++e) {
    env->reset(mix_seed(11, e), obs.data());
    std::vector<float> window;
    bool entered = false, past = false, cleared = false;
    for (;;) {
      env->features(f.data());
      bool inside = MetaController::holds(tr.expert_when, f.data());
      past |= entered && !inside;
      if (past && cleared) break;
      entered |= inside;
      if (inside && !past)
        window.insert(window.end(), obs.begin() + jump.obs_begin, obs.begin() + jump.obs_end);
      jump.policy.act(obs.data() + jump.obs_begin, 1, act.data());
      StepResult sr = env->step(act.data(), obs.data());
      cleared |= entered && sr.info.success_count > 0;  // the first curb is the window's
      if (sr.done()) break;
    }
    if (cleared) ++kept, want.insert(want.end(), window.begin(), window.end());
    else if (entered) ++dropped;
  }
  EXPECT_GT(kept, 0);
  EXPECT_GT(dropped, 0);  // the jump fails from some windows: they are not in T_b
  EXPECT_EQ(d.obs, want);
  EXPECT_EQ(collect_demonstrations(r, 0, count, 11, kDemonstrationEpisodes, nullptr, nullptr, 2).obs, d.obs)
      << "two threads keep other windows";
}

// training.env: walk->jump's S_a and T_b come from Hurdle with its settings laid over the
// recipe's `env:`. Recipe A writes the pushes there; recipe B writes the pushed task as its
// `env:`: their S_a and T_b are identical, A's training env steps as B's task does, and A's
// evaluated task (and its other transition) stays without pushes.
TEST_F(CollectionFiles, ATransitionsTrainingEnvIsTheTaskWithItsSettingsLaidOverEnv) {
  const std::string text = read_file(CompositeRecipe::default_file("hurdle"));
  auto write = [&](const std::string& name, const std::string& env, const std::string& training) {
    std::string t = text;
    ASSERT_NE(t.find("env: {}"), std::string::npos);
    t.replace(t.find("env: {}"), 7, env);
    ASSERT_NE(t.find("training: {"), std::string::npos);  // walk -> jump's, the first
    t.insert(t.find("training: {") + 11, training);
    std::ofstream(path(name)) << t;
  };
  write("a.yaml", "env: {push_force: 50}", "env: {push_prob: 0.3}, ");
  write("b.yaml", "env: {push_force: 50, push_prob: 0.3}", "");
  write("typo.yaml", "env: {}", "env: {push_prb: 0.3}, ");
  CompositeRecipe a = CompositeRecipe::load(path("a.yaml")), b = CompositeRecipe::load(path("b.yaml"));

  auto trace = [](const EnvFactory& make) {
    auto env = make();
    std::vector<float> obs(env->spec().obs_dim), act(env->spec().act_dim, 0.1f), out;
    env->reset(7, obs.data());
    for (int i = 0; i < 150; ++i) {
      if (env->step(act.data(), obs.data()).done()) break;
      out.insert(out.end(), obs.begin(), obs.end());
    }
    return out;
  };
  EXPECT_EQ(trace(a.training[0].env), trace(b.make_env));
  EXPECT_NE(trace(a.make_env), trace(b.make_env));  // the pushes act
  EXPECT_EQ(trace(a.training[1].env), trace(a.make_env));

  StartStates sa = collect_start_states(a, 0, 8, 4), sb = collect_start_states(b, 0, 8, 4);
  EXPECT_EQ(sa.states, sb.states);
  EXPECT_EQ(collect_demonstrations(a, 0, 200, 5).obs, collect_demonstrations(b, 0, 200, 5).obs);
  EXPECT_NE(collect_start_states(a, 1, 4, 4).states, collect_start_states(b, 1, 4, 4).states);

  expect_error([&] { CompositeRecipe::load(path("typo.yaml")); },
               "typo.yaml: unknown key 'transitions.0.training.env.push_prb'; did you mean "
               "'transitions.0.training.env.push_prob'?");
}

TEST_F(CollectionFiles, ExpertWindowsAreCheckedAtLoadAndAfterAThousandEmptyEpisodes) {
  // The crawl run alone on the course falls in the open before any ceiling is 2-3 m ahead.
  std::string text = read_file(CompositeRecipe::default_file("obstacle_course"));
  const std::string expert = ", expert: {task: walker_crawl, steps: 150}";
  ASSERT_NE(text.find(expert), std::string::npos);
  text.erase(text.find(expert), expert.size());
  std::ofstream(path("course.yaml")) << text;
  CompositeRecipe r = CompositeRecipe::load(path("course.yaml"));
  // The recipe's own checks on expert.task: a task that exists, and one whose observation
  // is the crawl's (26 numbers; the jump's task has 28).
  for (const auto& [task, message] : std::vector<std::pair<std::string, std::string>>{
           {"walker_sideways", "key 'transitions.1.expert.task': unknown task 'walker_sideways'"},
           {"walker_jump", "key 'transitions.1.expert.task': 'walker_jump' has obs_dim 28, but skill 'crawl' sees 26"}}) {
    std::string bad = text;
    const std::string when = "when: {ceiling_ahead: [2, 3]}";
    bad.insert(bad.find(when) + when.size(), ", expert: {task: " + task + ", steps: 9}");
    std::ofstream(path("bad.yaml")) << bad;
    expect_error([&] { CompositeRecipe::load(path("bad.yaml")); }, message);
  }
  expect_error([&] { collect_demonstrations(r, 1, 100, 5); },
               "transition walk-crawl gave only 0 demonstration steps in 1000 episodes");
}

// expert.after_handover: T_b is pi_b's window from each S_a state it is given, once each;
// with expert.successful only those after which pi_b clears the curb it took over for
// (also at later curbs, where the episode's count is already above 0). Rebuilt by hand:
// restore each state, run the jump while T_b's window (expert.when) holds, then on to its next success.
TEST_F(CollectionFiles, DemonstrationsAfterTheHandOverStartAtSaAndKeepTheWindowsPiBSucceedsFrom) {
  CompositeRecipe r = hurdle_with_stage13_jump(", after_handover: true");
  const TransitionTrainingSpec& tr = r.training[0];
  ASSERT_TRUE(tr.expert_after_handover && tr.expert_successful);
  StartStates s = collect_start_states(r, 0, 24, 4);
  s.keep_first(20);  // as the pipeline drops the held-out states
  ASSERT_EQ(s.size(), 20);
  ASSERT_EQ(s.obs.size(), size_t(20 * s.obs_dim));
  Demonstrations d = collect_demonstrations(r, 0, 100000, 9, kDemonstrationEpisodes, nullptr, &s);

  auto env = r.make_env();
  const Skill& jump = r.skills[r.meta.transitions()[0].to];
  std::vector<float> obs(env->spec().obs_dim), act(env->spec().act_dim), want;
  std::vector<double> f(env->spec().feature_names.size()), state;
  int kept = 0, dropped = 0, later_curbs = 0;
  for (int i = 0; i < s.size(); ++i) {
    s.state(i, state);
    env->restore_state(state, obs.data());
    std::vector<float> window;
    int before = -1;  // the episode's success count as the jump takes over
    bool past = false, cleared = false;
    for (;;) {
      env->features(f.data());
      past |= !MetaController::holds(tr.expert_when, f.data());
      if (past && cleared) break;
      if (!past) window.insert(window.end(), obs.begin() + jump.obs_begin, obs.begin() + jump.obs_end);
      jump.policy.act(obs.data() + jump.obs_begin, 1, act.data());
      StepResult sr = env->step(act.data(), obs.data());
      if (before < 0) before = sr.info.success_count, later_curbs += before > 0;
      cleared |= sr.info.success_count > before;
      if (sr.done()) break;
    }
    if (cleared) ++kept, want.insert(want.end(), window.begin(), window.end());
    else ++dropped;
  }
  EXPECT_GT(kept, 0);
  EXPECT_GT(dropped, 0);
  EXPECT_GT(later_curbs, 0);
  EXPECT_EQ(d.obs, want);

  // Without S_a's states, or with the skill's own task, it is refused.
  expect_error([&] { collect_demonstrations(r, 0, 100, 9); },
               "transition walk-jump: expert.after_handover needs S_a's states");
  std::string text = read_file(CompositeRecipe::default_file("obstacle_course"));
  const std::string own = "expert: {task: walker_crawl, steps: 150";
  ASSERT_NE(text.find(own), std::string::npos);
  text.insert(text.find(own) + own.size(), ", after_handover: true");
  std::ofstream(path("course.yaml")) << text;
  expect_error([&] { CompositeRecipe::load(path("course.yaml")); },
               "key 'transitions.1.expert.after_handover': S_a's states are this task's");
}

}  // namespace segue
