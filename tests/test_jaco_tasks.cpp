// The arm's composite tasks against docs/reference/tasks.md#arm-tasks, on scripted state sequences:
// Repetitive picking re-places the box after each success and ends at five; Repetitive
// catching pins the next box at its start and throws it; Serve judges the toss and then
// counts the hit. And the meta-controller on a task whose skill hands over to itself.
#include <gtest/gtest.h>

#include <cmath>

#include "environments/jaco_tasks.h"
#include "hrl/composite_recipe.h"
#include "hrl/switch_training.h"
#include "hrl/transition_controller.h"
#include "core/rng.h"
#include "tests/jaco_fixture.h"

namespace segue {
namespace {

const std::vector<double> kHandLow = {0, 0.3, 0, 0, 0, 0};  // shoulder turned down: the hand at z ~0.1
const std::vector<float> kZero(9, 0.0f);

// One step with the arm held at q and the box pinned in the hand.
StepResult held_step(JacoEnv& env, std::vector<float>& obs, const std::vector<double>& q = kHandLow) {
  hold_arm(env, q);
  env.forward(obs.data());
  pin(env, env.hand_pos(), obs);
  return env.step(kZero.data(), obs.data());
}

std::vector<double> features_of(const Env& env) {
  std::vector<double> f(env.spec().feature_names.size());
  env.features(f.data());
  return f;
}

}  // namespace

TEST(RepetitivePicking, ReplacesTheBoxAfterEachSuccessAndEndsAtFive) {
  auto env = make_arm<JacoRepetitivePick>("repetitive_picking");
  object_contacts_off(*env);
  const std::vector<std::string> names = {"steps", "object_z", "successes", "since_success", "pick_steps"};
  ASSERT_EQ(env->spec().feature_names, names);
  EXPECT_EQ(env->spec().max_episode_steps, 1000);
  std::vector<float> obs(49);
  env->reset(3, obs.data());
  EXPECT_GT(features_of(*env)[3], 1e5);  // since_success: far before the first
  StepResult r;
  for (int pick = 1; pick <= 5; ++pick) {
    for (int t = 1; t <= 50; ++t) {
      r = held_step(*env, obs);
      if (t < 50) ASSERT_FALSE(r.done()) << pick << " " << t;
    }
    EXPECT_EQ(r.info.success_count, pick);
    std::vector<double> f = features_of(*env);
    EXPECT_EQ(f[2], pick);
    EXPECT_EQ(f[3], 0);  // since_success
    EXPECT_EQ(f[4], 0);  // the next pick's clock
    if (pick < 5) {
      // The next box is on its tile again, and the observation shows it there.
      const Vec3 box = env->object_pos();
      EXPECT_NEAR(box[2], 0.03, 0.002);
      EXPECT_GE(box[0], 0.5);
      EXPECT_LE(box[0], 0.6);
      EXPECT_GE(box[1], 0.2);
      EXPECT_LE(box[1], 0.3);
      EXPECT_FLOAT_EQ(obs[9], float(box[0]));
      EXPECT_FALSE(r.done());
    }
  }
  EXPECT_TRUE(r.terminated);
  EXPECT_TRUE(r.info.success);
  EXPECT_EQ(env->episode_step(), 250);
}

TEST(RepetitivePicking, EndsOnADropOrWhenOnePickTakesTooLong) {
  auto env = make_arm<JacoRepetitivePick>("repetitive_picking", "{pick_steps: 120}");
  object_contacts_off(*env);
  std::vector<float> obs(49);
  env->reset(5, obs.data());
  for (int t = 0; t < 50; ++t) held_step(*env, obs);
  held_step(*env, obs);  // the second box picked...
  pin(*env, {0.5, 0.25, 0.4}, obs);  // ... and gone from the hand
  StepResult drop = env->step(kZero.data(), obs.data());
  EXPECT_TRUE(drop.terminated);
  EXPECT_FALSE(drop.info.success);
  EXPECT_EQ(drop.info.success_count, 1);

  env->reset(6, obs.data());
  int steps = 0;
  StepResult r;
  do {
    r = env->step(kZero.data(), obs.data());
    ++steps;
  } while (!r.done());
  EXPECT_EQ(steps, 120);  // the pick's own limit, not the episode's 1000
  EXPECT_TRUE(r.terminated);
  EXPECT_EQ(r.info.success_count, 0);
}

TEST(RepetitiveCatching, PinsTheNextBoxAtTheStartThenThrowsIt) {
  auto env = make_arm<JacoRepetitiveCatch>("repetitive_catching");
  object_contacts_off(*env);
  std::vector<float> obs(49);
  env->reset(2, obs.data());
  const std::vector<std::string> names = {"steps", "object_z", "successes", "since_success", "since_throw", "waiting"};
  ASSERT_EQ(env->spec().feature_names, names);
  // The first box was thrown at reset, toward the arm (about 4.2 m/s, docs/reference/jaco.md#catch).
  const Vec3 v0 = env->object_velocity();
  EXPECT_NEAR(std::sqrt(v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2]), 4.2, 0.4);
  EXPECT_EQ(features_of(*env)[4], 0);  // since_throw
  // Held 50 steps: a catch. Each held step pays 100 + 4 (1 - |(0, 0.2, 0.2) - box|), this
  // task's hold target, and the control cost.
  StepResult r;
  for (int t = 1; t <= 50; ++t) {
    r = held_step(*env, obs);
    if (t == 1) {
      const Vec3 box = env->object_pos();
      const double d = std::sqrt(box[0] * box[0] + (box[1] - 0.2) * (box[1] - 0.2) + (box[2] - 0.2) * (box[2] - 0.2));
      EXPECT_NEAR(r.reward, 100 + 4 * (1 - d), 1e-3);
    }
  }
  EXPECT_EQ(r.info.success_count, 1);
  EXPECT_FALSE(r.done());
  // The next box waits at the start, still, for 49 steps counting the catch's, falls freely
  // for 10 (to z 1.468 at -0.785 m/s, as the Catch sub-task's before its throw), and flies.
  for (int t = 1; t <= 48; ++t) {
    r = env->step(kZero.data(), obs.data());
    ASSERT_FALSE(r.done());
    const Vec3 box = env->object_pos(), v = env->object_velocity();
    ASSERT_NEAR(distance(box, {0.0, 2.0, 1.5}), 0.0, 1e-9) << t;
    ASSERT_EQ(v[0] * v[0] + v[1] * v[1] + v[2] * v[2], 0.0);
    ASSERT_EQ(features_of(*env)[5], 1);
  }
  for (int t = 1; t <= 10; ++t) r = env->step(kZero.data(), obs.data());
  EXPECT_NEAR(env->object_z(), 1.5 - 0.5 * 9.81 * 0.08 * 0.08, 0.003);
  EXPECT_NEAR(env->object_velocity()[2], -0.785, 0.01);
  EXPECT_EQ(features_of(*env)[5], 1);
  r = env->step(kZero.data(), obs.data());
  const Vec3 v = env->object_velocity();
  EXPECT_NEAR(std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), 4.2, 0.4);
  EXPECT_LT(v[1], -3.0);  // toward the arm
  std::vector<double> f = features_of(*env);
  EXPECT_EQ(f[4], 0);  // since_throw
  EXPECT_EQ(f[5], 0);
  EXPECT_EQ(f[3], 59);  // since_success
  // Not caught: it lands, and the episode ends with one catch.
  do r = env->step(kZero.data(), obs.data());
  while (!r.done());
  EXPECT_TRUE(r.terminated);
  EXPECT_EQ(r.info.success_count, 1);
  EXPECT_LE(env->object_z(), 0.05);
}

TEST(Serve, JudgesTheTossWhereTheBallComesDownThenEndsOnTheGround) {
  // The ball launched straight up from 0.75 m at the speed that peaks at 2.0, the arm out
  // of its way: released, a good apex, judged at 0.9 over the toss spot (+100), never hit.
  auto env = make_arm<JacoServe>("serve");
  arm_contacts_off(*env);
  std::vector<float> obs(39);
  env->reset(1, obs.data());
  const std::vector<std::string> names = {"steps", "object_z", "since_release", "falling", "judged", "hit"};
  ASSERT_EQ(env->spec().feature_names, names);
  env->pin_object({0.4, 0.3, 0.75});
  mjData* d = env->mutable_data();
  const int dof = env->model()->jnt_dofadr[mj_name2id(env->model(), mjOBJ_JOINT, "object")];
  const double g = -env->model()->opt.gravity[2];
  d->qvel[dof + 2] = std::sqrt(2 * g * (2.0 - 0.75));
  env->forward(obs.data());
  StepResult r;
  int released_at = -1, falling_at = -1, judged_at = -1;
  double judged_reward = 0;
  for (int t = 1; t < 300; ++t) {
    hold_arm(*env, {M_PI / 2});  // the hand turned away from where the ball comes down
    r = env->step(kZero.data(), obs.data());
    std::vector<double> f = features_of(*env);
    if (released_at < 0 && f[2] == 0) released_at = t;
    if (falling_at < 0 && f[3] == 1) falling_at = t;
    if (judged_at < 0 && f[4] == 1) judged_at = t, judged_reward = r.reward;
    if (released_at > 0) ASSERT_EQ(f[2], t - released_at);
    EXPECT_EQ(f[5], 0);
    if (r.done()) break;
  }
  EXPECT_EQ(released_at, 1);
  // Rising 1.25 m takes sqrt(2 h / g) = 0.505 s, 63 steps of 8 ms; falling 1.1 m, 0.47 s more.
  EXPECT_NEAR(falling_at, 0.505 / 0.008, 2);
  EXPECT_NEAR(judged_at - falling_at, std::sqrt(2 * 1.1 / g) / 0.008, 2);
  EXPECT_NEAR(judged_reward, 100.0, 0.5);  // the toss bonus, besides the tiny control cost
  EXPECT_TRUE(r.terminated);  // on the ground, untouched
  EXPECT_EQ(r.info.success_count, 0);
}

TEST(Serve, AHitAtTheRightHeightThenTheTargetSucceeds) {
  // hit_height moved down to where the held hand is, so a script can touch the falling ball.
  auto env = make_arm<JacoServe>("serve", "{hit_height: 0.15, judge_height: 0.9}");
  object_contacts_off(*env);
  std::vector<float> obs(39);
  env->reset(1, obs.data());
  // A good toss, as above.
  env->pin_object({0.4, 0.3, 0.75});
  const int dof = env->model()->jnt_dofadr[mj_name2id(env->model(), mjOBJ_JOINT, "object")];
  env->mutable_data()->qvel[dof + 2] = std::sqrt(2 * 9.81 * 1.25);
  env->forward(obs.data());
  StepResult r;
  do {
    hold_arm(*env, kHandLow);
    r = env->step(kZero.data(), obs.data());
  } while (!r.done() && features_of(*env)[4] == 0);
  ASSERT_FALSE(r.done());
  // The falling ball, put at the hand at the hit height: a hit (100 (1 - miss) + 100).
  hold_arm(*env, kHandLow);
  env->forward(obs.data());
  Vec3 h = env->hand_pos();
  pin(*env, {h[0], h[1], h[2] + 0.05}, obs);
  env->mutable_data()->qvel[dof + 2] = -1.0;
  r = env->step(kZero.data(), obs.data());
  ASSERT_EQ(features_of(*env)[5], 1) << "z " << env->object_z();
  EXPECT_GT(r.reward, 150.0);
  EXPECT_FALSE(r.done());
  // Then into the target: +1200 and success, 1 of 1.
  pin(*env, {0.4, 2.0, 1.2}, obs);
  r = env->step(kZero.data(), obs.data());
  EXPECT_TRUE(r.terminated);
  EXPECT_TRUE(r.info.success);
  EXPECT_EQ(r.info.success_count, 1);
  EXPECT_GT(r.reward, 1100.0);
}

TEST(RepetitivePicking, ThePickHandsOverToItselfOncePerSuccess) {
  // pick -> pick: the interval is the 30 steps after each success. Entered once each time
  // (the skill is the same before and after, so "the skill changed" cannot tell).
  CompositeRecipe r = CompositeRecipe::load(CompositeRecipe::default_file("repetitive_picking"));
  auto env = r.make_env();
  object_contacts_off(dynamic_cast<MujocoEnv&>(*env));
  auto& arm = dynamic_cast<JacoEnv&>(*env);
  TransitionController without_tp(r.skills, r.meta, {}, SwitchRule::IntervalEnd);
  std::vector<float> obs(49), act(9);
  env->reset(7, obs.data());
  without_tp.reset(*env, obs.data(), 0);
  std::vector<int> entered_at;
  for (int t = 0; t < 400; ++t) {
    without_tp.act(*env, obs.data(), act.data());
    if (without_tp.entered() >= 0) entered_at.push_back(int(features_of(*env)[3]));
    if (held_step(arm, obs).done()) break;
  }
  EXPECT_EQ(entered_at, (std::vector<int>{0, 0, 0, 0}));  // after successes 1-4, at since_success 0

  // A hand-over inside the interval (as switch training makes one) is judged by the next
  // pick, not by the interval it is already in: here the box cannot be grasped (its
  // contacts are off), so the pick times out and the hand-over fails.
  env->reset(8, obs.data());
  for (int t = 0; t < 50; ++t) held_step(arm, obs);
  ASSERT_EQ(features_of(*env)[3], 0);
  for (int t = 0; t < 10; ++t) env->step(kZero.data(), obs.data());  // pi_ab's steps, say
  EXPECT_FALSE(run_subtask(*env, without_tp, 0, obs.data(), /*lookahead=*/1, 3000));
}

TEST(JacoComposites, SnapshotsReplayExactlyWithTheirBookkeeping) {
  // S_a states are such snapshots: restoring one reproduces the next steps exactly, the
  // task's counters (picks, the pinned box, the toss's flags) included.
  for (const std::string task : {"repetitive_picking", "repetitive_catching", "serve"}) {
    auto env = make_task(task);
    const int n = env->spec().obs_dim;
    std::vector<float> obs(n), act(9);
    Rng rng(3);
    env->reset(11, obs.data());
    for (int t = 0; t < 30; ++t) {
      for (auto& a : act) a = float(rng.symmetric(1.0));
      env->step(act.data(), obs.data());
    }
    std::vector<double> state;
    env->save_state(state);
    std::vector<std::vector<float>> first;
    std::vector<float> actions;
    for (int t = 0; t < 20; ++t) {
      for (auto& a : act) a = float(rng.symmetric(1.0)), actions.push_back(a);
      env->step(act.data(), obs.data());
      first.push_back(obs);
      first.back().push_back(float(features_of(*env).back()));
    }
    env->restore_state(state, obs.data());
    for (int t = 0; t < 20; ++t) {
      env->step(actions.data() + 9 * t, obs.data());
      obs.push_back(float(features_of(*env).back()));
      ASSERT_EQ(obs, first[t]) << task << " step " << t;
      obs.resize(n);
    }
  }
}

TEST(JacoComposites, UnwindArmTurnsTheJointsByWholeTurnsAtEachSuccess) {
  // The arm held at kHandLow with its wrist joints wound up (j4 one turn on, j6 two turns
  // back), as a pick or catch leaves them. With unwind_arm a success turns them back to
  // [-pi, pi] (here 0.5 and 0.2); the pose, and so the hand, is the same as without it.
  const double kTurn = 2 * M_PI;
  const std::vector<double> wound = {0, 0.3, 0, kTurn + 0.5, 0, -2 * kTurn + 0.2};
  for (const std::string task : {"repetitive_picking", "repetitive_catching"}) {
    std::vector<std::vector<double>> q(2);
    std::vector<Vec3> hand(2);
    for (int unwind : {0, 1}) {
      auto env = make_arm<JacoEnv>(task, unwind ? "{unwind_arm: true}" : "{}");
      object_contacts_off(*env);
      std::vector<float> obs(49);
      env->reset(4, obs.data());
      StepResult r;
      for (int t = 0; t < 50; ++t) r = held_step(*env, obs, wound);
      ASSERT_EQ(r.info.success_count, 1) << task;
      q[unwind].assign(env->data()->qpos, env->data()->qpos + JacoEnv::kArmJoints);
      hand[unwind] = env->hand_pos();
      EXPECT_EQ(obs[3], float(q[unwind][3])) << task;  // the observation shows the angles as they are
    }
    EXPECT_NEAR(q[0][3], kTurn + 0.5, 0.05) << task;  // the reference's raw angles wind on
    EXPECT_NEAR(q[0][5], -2 * kTurn + 0.2, 0.05) << task;
    for (int i = 0; i < JacoEnv::kArmJoints; ++i) {
      EXPECT_GE(q[1][i], -M_PI) << task << " joint " << i;
      EXPECT_LE(q[1][i], M_PI) << task << " joint " << i;
      const double turns = (q[0][i] - q[1][i]) / kTurn;
      EXPECT_NEAR(turns, std::round(turns), 1e-9) << task << " joint " << i;
    }
    EXPECT_NEAR(q[1][3], 0.5, 0.05) << task;
    EXPECT_NEAR(q[1][5], 0.2, 0.05) << task;
    EXPECT_NEAR(distance(hand[0], hand[1]), 0.0, 1e-9) << task;
  }
}

}  // namespace segue
