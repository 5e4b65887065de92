// Composite walker tasks and the meta-controller: success counts increment exactly once
// per obstacle or turn, features match hand-computed distances, and the rule-based
// meta-controller walks through the documented skill sequence.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "tests/task_fixture.h"
#include "environments/walker_course.h"
#include "environments/walker_patrol.h"
#include "hrl/meta_controller.h"
#include "hrl/transition_training_spec.h"

namespace segue {
namespace {

// Skills with names only, for the meta-controller's rules.
std::vector<Skill> named_skills(const std::vector<std::string>& names) {
  std::vector<Skill> skills(names.size());
  for (size_t i = 0; i < names.size(); ++i) skills[i].name = names[i];
  return skills;
}

const float kZero[6] = {0, 0, 0, 0, 0, 0};

// Teleports the walker to torso x (moving at vx) and takes one step with zero action, upright.
StepResult step_at(Env& env, double x, std::vector<float>& obs, double vx = 0) {
  auto& m = dynamic_cast<MujocoEnv&>(env);
  m.mutable_data()->qpos[0] = x;
  m.mutable_data()->qpos[1] = 1.25;
  m.mutable_data()->qpos[2] = 0;
  for (int i = 3; i < 9; ++i) m.mutable_data()->qpos[i] = 0;  // standing straight
  for (int i = 0; i < 9; ++i) m.mutable_data()->qvel[i] = 0;
  m.mutable_data()->qvel[0] = vx;
  m.forward(obs.data());
  return env.step(kZero, obs.data());
}

// Resets Patrol with the first seed that starts forward, for a readable script; returns it.
uint64_t reset_forward(Env& env, std::vector<float>& obs) {
  uint64_t seed = 0;
  do env.reset(++seed, obs.data());
  while (dynamic_cast<WalkerPatrol&>(env).direction() != 1);
  return seed;
}

}  // namespace

TEST(Hurdle, CountsEachCurbOnceAtOnePointFiveMetresPastItsEnd) {
  auto env = make_task("hurdle", "{position_noise: 0, push_prob: 0}");
  auto& course = dynamic_cast<WalkerCourse&>(*env);
  std::vector<float> obs(28);
  env->reset(0, obs.data());
  ASSERT_EQ(course.obstacles().size(), 5u);
  EXPECT_DOUBLE_EQ(course.obstacles()[2].start, 28.0);
  EXPECT_DOUBLE_EQ(course.obstacles()[2].end, 28.2);
  int count = 0;
  // Walk the torso forward in 0.25 m hops, staying off the curbs (a hop onto a curb
  // would be a contact). min_x is the torso's x here: the feet point forward.
  for (double x = 0.5; x < 50.0; x += 0.25) {
    bool on_curb = false;
    for (const auto& o : course.obstacles()) on_curb |= x > o.start - 0.3 && x < o.end + 0.1;
    if (on_curb) continue;
    StepResult r = step_at(*env, x, obs);
    ASSERT_FALSE(r.terminated && r.info.success_count < 5) << "x " << x;
    int expected = 0;
    for (const auto& o : course.obstacles()) expected += course.min_x() > o.end + 1.5;
    ASSERT_EQ(r.info.success_count, expected) << "x " << x;
    ASSERT_LE(r.info.success_count - count, 1) << "x " << x;
    count = r.info.success_count;
    if (r.done()) break;
  }
  EXPECT_EQ(count, 5);
}

// The reference code's Hurdle reward (Single's, off by default): the pass bonus and the
// crossing bonuses (a third, two thirds and all of cross_bonus at the curb's start, centre
// and end) once per curb, the speed and height terms at their weights, the torso's
// vertical speed as it passes a mark. Each is the difference of two twin envs' rewards.
TEST(Hurdle, ReferenceRewardTermsByHand) {
  const std::string base = "{position_noise: 0, push_prob: 0";
  auto reference = make_task("hurdle", base + ", pass_bonus: 200, cross_bonus: 100}");
  auto ours = make_task("hurdle", base + "}");
  std::vector<float> obs(28);
  reference->reset(0, obs.data());
  ours->reset(0, obs.data());
  // Standing straight, the feet are at the torso's x. Teleported past curb 0's start
  // (8.0), its centre (8.1), then 1.5 past its end (8.2): 100 / 3, 200 / 3, then 100 and
  // the pass, 200 - 10, together; a step further on pays nothing more.
  for (auto [x, extra] : {std::pair{8.05, 100.0 / 3}, std::pair{8.15, 200.0 / 3}, std::pair{9.75, 290.0},
                          std::pair{10.0, 0.0}})
    EXPECT_NEAR(step_at(*reference, x, obs).reward - step_at(*ours, x, obs).reward, extra, 1e-9) << x;
  // A snapshot carries the marks crossed: restored elsewhere, curb 0 pays nothing again.
  std::vector<double> snapshot;
  reference->save_state(snapshot);
  auto restored = make_task("hurdle", base + ", pass_bonus: 200, cross_bonus: 100}");
  restored->reset(1, obs.data());
  restored->restore_state(snapshot, obs.data());
  EXPECT_NEAR(step_at(*restored, 10.25, obs).reward - step_at(*ours, 10.25, obs).reward, 0.0, 1e-9);

  // speed_weight w pays w (3 - |v - 3|), height_weight w charges w |1.1 - delta_h|.
  auto weighted = [&](const std::string& weights, double& v, double& delta_h) {
    auto env = make_task("hurdle", base + ", " + weights + "}");
    env->reset(0, obs.data());
    auto& course = dynamic_cast<WalkerCourse&>(*env);
    auto& m = dynamic_cast<MujocoEnv&>(*env);
    m.mutable_data()->qpos[0] = 3.0;
    m.forward(obs.data());
    m.mutable_data()->qvel[0] = 2.0;
    const double x0 = course.torso_x();
    const double r = env->step(kZero, obs.data()).reward;
    v = (course.torso_x() - x0) / 0.008, delta_h = course.delta_h();
    return r;
  };
  double v, delta_h;
  const double speed = weighted("speed_weight: 2, height_weight: 0", v, delta_h) -
                       weighted("speed_weight: 1, height_weight: 0", v, delta_h);
  EXPECT_NEAR(speed, 3 - std::abs(v - 3), 1e-9);
  EXPECT_GT(v, 1.0);
  const double height = weighted("speed_weight: 0, height_weight: 2", v, delta_h) -
                        weighted("speed_weight: 0, height_weight: 1", v, delta_h);
  EXPECT_NEAR(height, -std::abs(1.1 - delta_h), 1e-9);

  // The torso at 7.99, 0.5 m up, moving 3 m/s forward passes the curb's start in one
  // control step: mark_upward_weight 100 pays 100 clip(vz, -2, 2), vz after the step.
  for (double vz : {1.0, -3.0}) {
    double reward[2], vz_after = 0;
    for (int e = 0; e < 2; ++e) {
      auto env = make_task("hurdle", base + (e == 0 ? ", mark_upward_weight: 100}" : "}"));
      env->reset(0, obs.data());
      auto& m = dynamic_cast<MujocoEnv&>(*env);
      double* qpos = m.mutable_data()->qpos;
      double* qvel = m.mutable_data()->qvel;
      std::fill(qpos + 2, qpos + 9, 0.0);
      qpos[0] = 7.99, qpos[1] = 1.75;
      std::fill(qvel, qvel + 9, 0.0);
      qvel[0] = 3.0, qvel[1] = vz;
      m.forward(obs.data());
      reward[e] = env->step(kZero, obs.data()).reward;
      vz_after = m.mutable_data()->qvel[1];
    }
    EXPECT_NEAR(reward[0] - reward[1], 100 * std::clamp(vz_after, -2.0, 2.0), 1e-6) << vz;
    EXPECT_NEAR(vz_after, vz - 9.81 * 0.008, 0.05);  // free flight for one step
  }
}

// The reference code counts a ceiling 0.15 m past its end (ceiling_pass_margin), a curb
// 1.5 m past (pass_margin); by default both are 1.5.
TEST(ObstacleCourse, CountsACeilingAtItsOwnPassMargin) {
  const std::string layout =
      "{position_noise: 0, push_prob: 0, shuffle: false, kinds: [ceiling, curb, curb, curb, ceiling]";
  for (double margin : {1.5, 0.15}) {
    auto env = make_task("obstacle_course", layout + (margin == 1.5 ? "}" : ", ceiling_pass_margin: 0.15}"));
    auto& course = dynamic_cast<WalkerCourse&>(*env);
    std::vector<float> obs(28);
    env->reset(0, obs.data());
    ASSERT_EQ(course.obstacles()[0].kind, ObstacleKind::Ceiling);
    ASSERT_DOUBLE_EQ(course.obstacles()[0].end, 11.0);  // 8 + its 3 m
    // min_x is the torso's x here (upright, feet forward); the ceiling is behind it.
    EXPECT_EQ(step_at(*env, 11.0 + margin - 0.05, obs).info.success_count, 0) << margin;
    EXPECT_EQ(step_at(*env, 11.0 + margin + 0.05, obs).info.success_count, 1) << margin;
    // The next curb (19-19.2) still counts at 1.5 m.
    EXPECT_EQ(step_at(*env, 20.65, obs).info.success_count, 1) << margin;
    EXPECT_EQ(step_at(*env, 20.75, obs).info.success_count, 2) << margin;
  }
}

// The height term's weight is height_weight away from a ceiling and ceiling_height_weight
// within ceiling_zone (3 m) of one: at x 6 (2 m before the ceiling at 8) only the second
// counts, at x 4 only the first.
TEST(ObstacleCourse, HeightTermWeightNearAndAwayFromACeiling) {
  const std::string layout =
      "{position_noise: 0, push_prob: 0, shuffle: false, kinds: [ceiling, curb, curb, curb, ceiling], ";
  std::vector<float> obs(28);
  auto reward_at = [&](double x, const std::string& weights, double& delta_h) {
    auto env = make_task("obstacle_course", layout + weights + "}");
    env->reset(0, obs.data());
    const double r = step_at(*env, x, obs).reward;
    delta_h = dynamic_cast<WalkerCourse&>(*env).delta_h();
    return r;
  };
  double delta_h;
  for (double x : {6.0, 4.0}) {
    const bool near = x == 6.0;
    const double base = reward_at(x, "height_weight: 0, ceiling_height_weight: 0", delta_h);
    const double away = reward_at(x, "height_weight: 2, ceiling_height_weight: 0", delta_h) - base;
    const double close = reward_at(x, "height_weight: 0, ceiling_height_weight: 2", delta_h) - base;
    ASSERT_GT(std::abs(1.1 - delta_h), 0.01) << x;  // the term is not zero here
    EXPECT_NEAR(near ? close : away, -2 * std::abs(1.1 - delta_h), 1e-9) << x;
    EXPECT_NEAR(near ? away : close, 0.0, 1e-12) << x;
  }
}

TEST(Hurdle, FeaturesAreDistancesToCurbs) {
  auto env = make_task("hurdle", "{position_noise: 0, push_prob: 0}");
  std::vector<float> obs(28);
  env->reset(0, obs.data());
  step_at(*env, 4.5, obs);
  auto& course = dynamic_cast<WalkerCourse&>(*env);
  double x = course.min_x(), f[6];
  env->features(f);
  EXPECT_NEAR(f[0], 8.0 - x, 1e-9);         // curb_ahead
  EXPECT_EQ(f[1], WalkerCourse::kFar);       // nothing behind yet
  EXPECT_EQ(f[2], WalkerCourse::kFar);       // no ceilings in Hurdle
  EXPECT_EQ(f[4], 1);                        // steps since the start
  EXPECT_NEAR(f[5], 4.5, 0.1);               // distance from the start (which is near x = 0)
  step_at(*env, 11.0, obs);
  x = course.min_x();
  env->features(f);
  EXPECT_NEAR(f[0], 18.0 - x, 1e-9);
  EXPECT_NEAR(f[1], x - 8.2, 1e-9);          // curb_behind
}

TEST(ObstacleCourse, ThreeCurbsAndTwoCeilingsInASeededOrder) {
  auto a = make_task("obstacle_course"), b = make_task("obstacle_course");
  std::vector<float> obs(28);
  std::vector<std::vector<int>> orders;
  for (uint64_t seed : {1, 2, 3, 4, 5, 6}) {
    a->reset(seed, obs.data());
    auto& course = dynamic_cast<WalkerCourse&>(*a);
    std::vector<int> kinds;
    int curbs = 0;
    for (const auto& o : course.obstacles()) {
      kinds.push_back(int(o.kind));
      curbs += o.kind == ObstacleKind::Curb;
      EXPECT_NEAR(o.end - o.start, o.kind == ObstacleKind::Curb ? 0.2 : 3.0, 1e-12);
    }
    EXPECT_EQ(curbs, 3);
    orders.push_back(kinds);
    b->reset(seed, obs.data());
    auto& same = dynamic_cast<WalkerCourse&>(*b);
    for (size_t i = 0; i < 5; ++i) EXPECT_EQ(same.obstacles()[i].start, course.obstacles()[i].start);
  }
  bool varied = false;
  for (const auto& o : orders) varied |= o != orders[0];
  EXPECT_TRUE(varied) << "six seeds gave one obstacle order";
}

TEST(Patrol, CountsATurnOncePerStoneAndFlipsDirection) {
  auto env = make_task("patrol", "{push_prob: 0}");
  auto& patrol = dynamic_cast<WalkerPatrol&>(*env);
  std::vector<float> obs(27);
  reset_forward(*env, obs);
  EXPECT_NEAR(obs[26], 2.0 - patrol.torso_x(), 1e-6);  // signed distance to the +2 stone
  StepResult r = step_at(*env, 1.5, obs);
  EXPECT_EQ(r.info.success_count, 0);
  r = step_at(*env, 2.2, obs);
  EXPECT_EQ(r.info.success_count, 1);
  EXPECT_EQ(patrol.direction(), -1);
  double f[5];
  env->features(f);
  EXPECT_EQ(f[0], -1);
  EXPECT_EQ(f[1], 0);  // since_turn
  r = step_at(*env, 2.5, obs);  // further out: no second count
  EXPECT_EQ(r.info.success_count, 1);
  r = step_at(*env, -2.1, obs);
  EXPECT_EQ(r.info.success_count, 2);
  EXPECT_EQ(patrol.direction(), 1);
}

// The reference code's rules: a stone passed below 2 m/s ends the episode uncounted; a
// leg of 800 steps ends it. Off by default (the first test above passes at rest).
TEST(Patrol, TheReferenceRulesEndASlowPassAndALongLeg) {
  auto env = make_task("patrol", "{push_prob: 0, min_pass_speed: 2, max_leg_steps: 800}");
  std::vector<float> obs(27);
  const uint64_t seed = reset_forward(*env, obs);
  StepResult r = step_at(*env, 2.2, obs, 2.5);  // fast enough: a turn
  EXPECT_EQ(r.info.success_count, 1);
  EXPECT_FALSE(r.done());
  r = step_at(*env, -2.1, obs, -1.5);  // 1.5 m/s towards the stone: too slow
  EXPECT_TRUE(r.terminated);
  EXPECT_EQ(r.info.success_count, 1);
  EXPECT_FALSE(r.info.success);

  env->reset(seed, obs.data());  // forward again; the leg's 800th step ends the episode
  for (int t = 1; t < 800; ++t) {
    r = step_at(*env, 0.0, obs);
    ASSERT_FALSE(r.done()) << "step " << t;
  }
  r = step_at(*env, 0.0, obs);
  EXPECT_TRUE(r.terminated);
  EXPECT_EQ(r.info.success_count, 0);
}

// speed_weight w pays w (3 - |v - 3|) in the current direction, height_weight w charges
// w |1.1 - delta_h| (the reference's Patrol reward doubles both): each the difference of
// two twin envs' rewards, walking backward towards the -2 stone after the first turn.
TEST(Patrol, SpeedAndHeightWeightsByHand) {
  std::vector<float> obs(27);
  auto reward = [&](const std::string& weights, double& v, double& delta_h) {
    auto env = make_task("patrol", "{push_prob: 0, " + weights + "}");
    auto& patrol = dynamic_cast<WalkerPatrol&>(*env);
    reset_forward(*env, obs);
    step_at(*env, 2.2, obs);  // a turn: now heading for -2
    const double r = step_at(*env, 0.0, obs, -2.0).reward;  // from x 0 at 2 m/s towards it
    v = patrol.direction() * (patrol.torso_x() - 0.0) / 0.008, delta_h = patrol.delta_h();
    return r;
  };
  double v, delta_h;
  const double speed = reward("speed_weight: 2, height_weight: 0", v, delta_h) -
                       reward("speed_weight: 1, height_weight: 0", v, delta_h);
  EXPECT_GT(v, 1.0);  // moving towards the target stone
  EXPECT_NEAR(speed, 3 - std::abs(v - 3), 1e-9);
  const double height = reward("speed_weight: 0, height_weight: 2", v, delta_h) -
                        reward("speed_weight: 0, height_weight: 1", v, delta_h);
  EXPECT_GT(std::abs(1.1 - delta_h), 0.01);
  EXPECT_NEAR(height, -std::abs(1.1 - delta_h), 1e-9);
}

// The reference's composite tasks apply no pushes (prob_apply_force 0); its sub-tasks push
// with probability 0.2 a step, balance with 0.1.
TEST(CompositeTasks, PushNothingWhileSubTasksPushAtTheReferenceRates) {
  auto pushed_steps = [](const std::string& task) {
    auto env = make_task(task, "{}");
    auto& m = dynamic_cast<MujocoEnv&>(*env);
    std::vector<float> obs(env->spec().obs_dim);
    env->reset(11, obs.data());
    int count = 0;
    for (int t = 0; t < 2000; ++t) {
      if (env->step(kZero, obs.data()).done()) env->reset(obs.data());
      count += pushed(m);
    }
    return count;
  };
  EXPECT_EQ(pushed_steps("patrol"), 0);
  EXPECT_EQ(pushed_steps("hurdle"), 0);
  EXPECT_EQ(pushed_steps("obstacle_course"), 0);
  // Binomial(2000, p) within 4.5 standard deviations of 2000 p: the two rates cannot overlap.
  const int jump = pushed_steps("walker_jump"), balance = pushed_steps("walker_balance");
  EXPECT_GE(jump, 320);
  EXPECT_LE(jump, 480);
  EXPECT_GE(balance, 140);
  EXPECT_LE(balance, 260);
}

TEST(MetaController, HurdleSkillSequenceOnAScriptedEpisode) {
  Recipe recipe = Recipe::parse(R"(
start: [{skill: walk}]
transitions:
  - {from: walk, to: jump, when: {curb_ahead: [3, 4]}}
  - {from: jump, to: walk, when: {curb_behind: [2.5, 3.5]}})",
                                "hurdle-rules");
  const std::vector<Skill> skills = named_skills({"walk", "jump"});
  auto env = make_task("hurdle", "{position_noise: 0, push_prob: 0}");
  MetaController meta(recipe.root(), skills, env->spec().feature_names);
  std::vector<float> obs(28);
  env->reset(0, obs.data());
  double f[6];
  env->features(f);
  int skill = meta.start_skill(f);
  std::vector<std::pair<double, int>> switches;  // (x, new skill)
  for (double x = 0.5; x < 32.0; x += 0.1) {
    bool on_curb = false;
    for (double c : {8.0, 18.0, 28.0}) on_curb |= x > c - 0.3 && x < c + 0.3;
    if (on_curb) continue;
    step_at(*env, x, obs);
    env->features(f);
    int t = meta.active_transition(skill, f);
    if (t >= 0) {
      skill = meta.transitions()[t].to;
      switches.push_back({x, skill});
    }
  }
  // walk -> jump when the curb is 4 m ahead; jump -> walk 2.5 m after its end.
  ASSERT_EQ(switches.size(), 6u);
  const double curbs[3] = {8.0, 18.0, 28.0};
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(switches[2 * k].second, 1);
    EXPECT_NEAR(switches[2 * k].first, curbs[k] - 4.0, 0.11);
    EXPECT_EQ(switches[2 * k + 1].second, 0);
    EXPECT_NEAR(switches[2 * k + 1].first, curbs[k] + 0.2 + 2.5, 0.11);
  }
}

TEST(MetaController, PatrolStartsByDirectionAndBalancesBetweenWalks) {
  Recipe recipe = Recipe::parse(R"(
start: [{skill: forward, when: {direction: 1}}, {skill: backward, when: {direction: -1}}]
transitions:
  - {from: forward, to: balance, when: {since_turn: [0, 100]}}
  - {from: backward, to: balance, when: {since_turn: [0, 100]}}
  - {from: balance, to: forward, when: {direction: 1, since_turn: [100, 1.0e+6], progress: [-1.0e+6, 4]}}
  - {from: balance, to: backward, when: {direction: -1, since_turn: [100, 1.0e+6], progress: [-1.0e+6, 4]}})",
                                "patrol-rules");
  const std::vector<Skill> skills = named_skills({"forward", "backward", "balance"});
  MetaController meta(recipe.root(), skills, {"direction", "since_turn", "progress"});
  double f[3] = {-1, 1e6, 0};
  EXPECT_EQ(meta.start_skill(f), 1);
  f[0] = 1;
  EXPECT_EQ(meta.start_skill(f), 0);
  EXPECT_EQ(meta.active_transition(0, f), -1);  // walking, no turn yet
  // Turn at the stone: direction flips to -1, since_turn = 0.
  double g[3] = {-1, 0, 0};
  int t = meta.active_transition(0, g);
  ASSERT_GE(t, 0);
  EXPECT_EQ(meta.transitions()[t].to, 2);        // balance
  g[1] = 50;
  EXPECT_EQ(meta.active_transition(2, g), -1);  // still balancing
  g[1] = 100;
  t = meta.active_transition(2, g);
  ASSERT_GE(t, 0);
  EXPECT_EQ(meta.transitions()[t].to, 1);        // walk backward, the new direction
  g[2] = 4.5;                                    // walked more than 4 m: the interval is over
  EXPECT_EQ(meta.active_transition(2, g), -1);
}

TEST(MetaController, RefusesUnknownSkillsAndFeatures) {
  const std::vector<Skill> skills = named_skills({"walk"});
  Recipe bad_skill = Recipe::parse("start: [{skill: run}]", "r.yaml");
  try {
    MetaController(bad_skill.root(), skills, {"curb_ahead"});
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "r.yaml: key 'start.0.skill': no skill named 'run' (skills: walk)");
  }
  Recipe bad_feature = Recipe::parse("start: [{skill: walk, when: {hurdle_ahead: [1, 2]}}]", "r.yaml");
  EXPECT_THROW(MetaController(bad_feature.root(), skills, {"curb_ahead"}), Error);
}

// Transition 0's training spec (hrl/transition_training_spec.h), read as a composite
// recipe reads it: the rule first, then the training keys of the same entry.
static TransitionTrainingSpec spec_of(const Recipe& r, const std::vector<Skill>& skills, const std::vector<std::string>& features,
                                      const std::function<std::vector<std::string>(const std::string&)>& own = nullptr) {
  MetaController meta(r.root(), skills, features);
  return TransitionTrainingSpec::read(r.root().items("transitions")[0], meta.transitions()[0], features, own);
}

TEST(TransitionTrainingSpec, ReadsAndChecksAnExpertWindowOnTheSkillsOwnTask) {
  const std::vector<Skill> skills = named_skills({"walk", "crawl"});
  const std::string head = "start: [{skill: walk}]\ntransitions:\n  - {from: walk, to: crawl, when: {ceiling_ahead: [2, 3]}, ";
  Recipe ok = Recipe::parse(head + "expert: {task: walker_crawl, steps: 150}}", "r.yaml");
  // The sub-task's own features, for an expert window written in them.
  auto own = [](const std::string& task) {
    if (task != "walker_crawl") throw Error("unknown task '" + task + "'");
    return std::vector<std::string>{"steps", "ceiling_behind"};
  };
  const TransitionTrainingSpec spec = spec_of(ok, skills, {"ceiling_ahead"}, own);
  EXPECT_EQ(spec.expert_task, "walker_crawl");
  EXPECT_EQ(spec.expert_steps, 150);
  EXPECT_TRUE(spec.expert_when.empty());  // not the interval: that is this task's
  Recipe windowed = Recipe::parse(head + "expert: {task: walker_crawl, when: {ceiling_behind: [1, 2]}}}", "r.yaml");
  const TransitionTrainingSpec w = spec_of(windowed, skills, {"ceiling_ahead"}, own);
  EXPECT_EQ(w.expert_steps, 0);
  ASSERT_EQ(w.expert_when.size(), 1u);
  EXPECT_EQ(w.expert_when[0].feature, 1);  // ceiling_behind among the sub-task's features
  EXPECT_EQ(w.expert_when[0].lo, 1.0);
  auto refused = [&](const std::string& expert, const std::string& message) {
    Recipe r = Recipe::parse(head + "expert: " + expert + "}", "r.yaml");
    try {
      spec_of(r, skills, {"ceiling_ahead"}, own);
      ADD_FAILURE() << expert;
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()), message);
    }
  };
  // expert.successful alone keeps the interval as the window.
  Recipe kept = Recipe::parse(head + "expert: {successful: true}}", "r.yaml");
  const TransitionTrainingSpec filtered = spec_of(kept, skills, {"ceiling_ahead"});
  ASSERT_EQ(filtered.expert_when.size(), 1u);
  EXPECT_EQ(filtered.expert_when[0].lo, 2.0);
  EXPECT_EQ(filtered.expert_when[0].hi, 3.0);
  EXPECT_TRUE(filtered.expert_successful);
  EXPECT_FALSE(spec.expert_successful);
  refused("{task: walker_crawl}", "r.yaml: key 'transitions.0.expert.task': give pi_b's window on it: expert.steps "
                                  "and/or expert.when (over its features)");
  refused("{task: walker_crawl, steps: 0}", "r.yaml: key 'transitions.0.expert.steps' must be > 0, got 0");
  refused("{task: walker_crawl, steps: 9, when: {ceiling_ahead: [0, 1]}}",
          "r.yaml: key 'transitions.0.expert.when.ceiling_ahead': the task has no feature 'ceiling_ahead' "
          "(features: steps, ceiling_behind)");
  refused("{task: walker_jog, steps: 9}", "r.yaml: key 'transitions.0.expert.task': unknown task 'walker_jog'");
}

TEST(MetaController, ATransitionsMaxStepsCapsItsInterval) {
  const std::vector<Skill> skills = named_skills({"walk", "crawl"});
  const std::string head = "start: [{skill: walk}]\ntransitions:\n  - {from: walk, to: crawl, when: {ceiling_ahead: [2, 3]}";
  Recipe plain = Recipe::parse(head + "}", "r.yaml");
  EXPECT_EQ(MetaController(plain.root(), skills, {"ceiling_ahead"}).transitions()[0].max_steps, 0);  // no cap unless asked
  Recipe capped = Recipe::parse(head + ", max_steps: 300}", "r.yaml");
  const Transition c = MetaController(capped.root(), skills, {"ceiling_ahead"}).transitions()[0];
  EXPECT_EQ(c.max_steps, 300);
  const double inside[1] = {2.5};
  EXPECT_TRUE(c.running(inside, 299));
  EXPECT_FALSE(c.running(inside, 300));
  try {
    Recipe zero = Recipe::parse(head + ", max_steps: 0}", "r.yaml");
    MetaController(zero.root(), skills, {"ceiling_ahead"});
    ADD_FAILURE() << "max_steps 0 was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "r.yaml: key 'transitions.0.max_steps' must be > 0, got 0");
  }
}

TEST(TransitionTrainingSpec, ATrainingWindowApartFromTheInterval) {
  const std::vector<Skill> skills = named_skills({"walk", "jump"});
  const std::string head = "start: [{skill: walk}]\ntransitions:\n  - {from: walk, to: jump, when: {curb_ahead: [3, 4]}";
  // By default pi_ab trains in the interval itself, with its cap.
  Recipe plain = Recipe::parse(head + ", max_steps: 50}", "r.yaml");
  const TransitionTrainingSpec p = spec_of(plain, skills, {"curb_ahead"});
  ASSERT_EQ(p.training_when.size(), 1u);
  EXPECT_EQ(p.training_when[0].lo, 3.0);
  EXPECT_EQ(p.training_max_steps, 50);
  // The reference's Hurdle: evaluated 4 to 3 m before the curb, trained from 4 to 2 m.
  Recipe wide = Recipe::parse(head + ", max_steps: 50, training: {when: {curb_ahead: [2, 4]}}}", "r.yaml");
  const Transition t = MetaController(wide.root(), skills, {"curb_ahead"}).transitions()[0];
  const Transition window = spec_of(wide, skills, {"curb_ahead"}).window(t);
  const double at_2_5[1] = {2.5}, at_3_5[1] = {3.5};
  EXPECT_FALSE(t.running(at_2_5, 0));
  EXPECT_TRUE(window.running(at_2_5, 0));
  EXPECT_TRUE(window.running(at_3_5, 0));
  EXPECT_EQ(window.max_steps, 0);  // a training window without max_steps has no cap
  EXPECT_TRUE(window.running(at_3_5, 1000));
  EXPECT_FALSE(t.running(at_3_5, 50));
  EXPECT_EQ(window.from, t.from);
  EXPECT_EQ(window.to, t.to);
  try {
    Recipe empty = Recipe::parse(head + ", training: {}}", "r.yaml");
    spec_of(empty, skills, {"curb_ahead"});
    ADD_FAILURE() << "an empty training window was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "r.yaml: key 'transitions.0.training': give its window (when and/or max_steps) or its env");
  }
  // A training env alone keeps the interval as the window.
  Recipe pushed = Recipe::parse(head + ", max_steps: 50, training: {env: {push_prob: 0.2}}}", "r.yaml");
  const TransitionTrainingSpec e = spec_of(pushed, skills, {"curb_ahead"});
  ASSERT_EQ(e.training_when.size(), 1u);
  EXPECT_EQ(e.training_when[0].lo, 3.0);
  EXPECT_EQ(e.training_max_steps, 50);
}

}  // namespace segue
