// Walker sub-tasks: reset determinism, success rules triggered by scripted states,
// obstacle observations against hand-computed values, snapshots that carry the layout.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "core/rng.h"
#include "tests/task_fixture.h"
#include "environments/walker_obstacles.h"

namespace segue {
namespace {

// Moves the whole walker by dx along x (rootx) and recomputes positions.
void shift_x(Env& env, double x, std::vector<float>& obs) {
  auto& m = dynamic_cast<MujocoEnv&>(env);
  m.mutable_data()->qpos[0] = x;
  m.forward(obs.data());
}

const float kZero[6] = {0, 0, 0, 0, 0, 0};

// Stands the walker on its feet (foot radius 0.06) with both ankles at x = 7.0 + at, the
// jump's curb starting at 7.0 without noise; returns the ankles' x offset from rootx.
double stand_before_curb(Env& env, double at, std::vector<float>& obs) {
  auto& m = dynamic_cast<MujocoEnv&>(env);
  const int foot = mj_name2id(m.model(), mjOBJ_BODY, "foot");
  shift_x(env, 0.0, obs);
  const double ankle_offset = m.data()->xpos[3 * foot];  // the ankles' x in the standing pose
  m.mutable_data()->qpos[1] -= m.data()->xpos[3 * foot + 2] - 0.06;  // lowered onto its feet
  shift_x(env, 7.0 + at - ankle_offset, obs);
  return ankle_offset;
}

// The reward of one zero-action step of `task` (with `settings`) from its seed-0 start
// after `place` has edited qpos: two calls that differ in one reward term's weight differ
// by exactly that term.
double reward_after_placing(const std::string& task, const std::string& settings,
                            const std::function<void(double* qpos)>& place) {
  auto env = make_task(task, settings);
  std::vector<float> obs(env->spec().obs_dim);
  env->reset(0, obs.data());
  auto& m = dynamic_cast<MujocoEnv&>(*env);
  place(m.mutable_data()->qpos);
  m.forward(obs.data());
  return env->step(kZero, obs.data()).reward;
}

}  // namespace

TEST(WalkerSubtasks, ShapesFollowTheSpec) {
  EXPECT_EQ(make_task("walker_backward")->spec().obs_dim, 26);
  EXPECT_EQ(make_task("walker_balance")->spec().obs_dim, 26);
  EXPECT_EQ(make_task("walker_crawl")->spec().obs_dim, 26);
  EXPECT_EQ(make_task("walker_jump")->spec().obs_dim, 28);
  for (auto t : {"walker_backward", "walker_balance", "walker_crawl", "walker_jump"})
    EXPECT_EQ(make_task(t)->spec().act_dim, 6) << t;
}

TEST(WalkerSubtasks, ResetIsDeterministicPerSeed) {
  for (auto t : {"walker_backward", "walker_balance", "walker_crawl", "walker_jump"}) {
    auto a = make_task(t), b = make_task(t);
    int d = a->spec().obs_dim;
    std::vector<float> oa(d), ob(d);
    a->reset(9, oa.data());
    b->reset(9, ob.data());
    EXPECT_EQ(oa, ob) << t;
    b->reset(10, ob.data());
    EXPECT_NE(oa, ob) << t;
  }
}

TEST(WalkerJump, ObstacleObservationByHand) {
  auto env = make_task("walker_jump", "{curb_noise: 0, init_noise: 0, init_random_steps: 0, push_prob: 0}");
  auto& jump = dynamic_cast<WalkerObstacleEnv&>(*env);
  std::vector<float> obs(28);
  env->reset(0, obs.data());
  // Curb from 7.0 to 7.2. At the reference pose the smallest x of torso and feet is the
  // ankle bodies' and torso's x = 0: the curb is 7 m away, beyond the 5 m detection
  // distance, so the pair takes the curb's "far" values.
  EXPECT_FLOAT_EQ(obs[26], 5.1f);
  EXPECT_FLOAT_EQ(obs[27], 5.2f);
  shift_x(*env, 3.0, obs);  // now 4 m before the curb: within detection
  EXPECT_NEAR(jump.min_x(), 3.0, 1e-9);
  EXPECT_NEAR(obs[26], 4.0, 1e-6);
  EXPECT_NEAR(obs[27], 4.2, 1e-6);
  shift_x(*env, 7.1, obs);  // on top of the curb: start behind, end ahead
  EXPECT_NEAR(obs[26], -0.1, 1e-6);
  EXPECT_NEAR(obs[27], 0.1, 1e-6);
  shift_x(*env, 7.5, obs);  // past it: no obstacle ahead
  EXPECT_FLOAT_EQ(obs[26], 5.1f);
}

TEST(WalkerJump, PassingTheCurbSucceedsAndTouchingItFails) {
  auto env = make_task("walker_jump", "{curb_noise: 0, push_prob: 0}");
  std::vector<float> obs(28);
  env->reset(1, obs.data());
  // Lift the walker and put it 1.5 m past the curb's end (7.2): success on the next step.
  auto& m = dynamic_cast<MujocoEnv&>(*env);
  m.mutable_data()->qpos[0] = 7.2 + 1.5 + 0.05;
  m.forward(obs.data());
  StepResult r = env->step(kZero, obs.data());
  EXPECT_TRUE(r.info.success);
  EXPECT_EQ(r.info.success_count, 1);
  // The three crossing bonuses (start, centre, end) were paid at once.
  EXPECT_GT(r.reward, 25.0);
  EXPECT_FALSE(r.terminated);

  // Standing inside the curb: contact ends the episode with the penalty.
  env->reset(2, obs.data());
  m.mutable_data()->qpos[0] = 6.9;  // feet (0.2 m ahead of the ankle) overlap the curb's start
  m.forward(obs.data());
  r = env->step(kZero, obs.data());
  EXPECT_TRUE(r.terminated);
  EXPECT_FALSE(r.info.success);
  EXPECT_LT(r.reward, -5.0);
}

TEST(WalkerJump, TouchingGoesOnButForfeitsTheCurbWithContactEndsFalse) {
  // Training-only contact_ends false: a touch costs the penalty and goes on, and the
  // touched curb's three crossing bonuses (10 each) are not paid. Twin envs, one touched.
  const char* opts = "{curb_noise: 0, push_prob: 0, contact_ends: false, cross_bonus: 10}";
  auto touched = make_task("walker_jump", opts), clean = make_task("walker_jump", opts);
  std::vector<float> obs(28);
  touched->reset(2, obs.data());
  clean->reset(2, obs.data());
  shift_x(*touched, 6.9, obs);  // the feet overlap the curb's start, as above
  StepResult r = touched->step(kZero, obs.data());
  EXPECT_FALSE(r.terminated);
  EXPECT_LT(r.reward, -5.0);
  // The touched walker takes the clean one's pose; both are put 1.5 m past the curb.
  auto& from = dynamic_cast<MujocoEnv&>(*clean);
  auto& to = dynamic_cast<MujocoEnv&>(*touched);
  std::copy_n(from.mutable_data()->qpos, 9, to.mutable_data()->qpos);
  std::copy_n(from.mutable_data()->qvel, 9, to.mutable_data()->qvel);
  double reward[2];
  for (int e = 0; e < 2; ++e) {
    Env& env = e == 0 ? *touched : *clean;
    shift_x(env, 7.2 + 1.5 + 0.05, obs);
    r = env.step(kZero, obs.data());
    reward[e] = r.reward;
    EXPECT_EQ(r.info.success_count, 1);
    EXPECT_EQ(r.info.success, e == 1) << "a touched curb is no success";
  }
  EXPECT_NEAR(reward[1] - reward[0], 3 * 10.0, 1e-6);
}

TEST(WalkerJump, CapsuleDepthInACurbMatchesHandComputedValues) {
  // Curb [-0.1, 0.1] x [0, 0.4]. Inside, the signed distance is minus the distance to the
  // nearest face; outside, the distance to the box.
  // A shin (r 0.04) standing in it from z 0.1 up: nearest face 0.1 away, depth 0.14.
  EXPECT_NEAR(capsule_depth_in_box({0.0, 0.1}, {0.0, 0.6}, 0.04, -0.1, 0.1, 0.4), 0.14, 1e-12);
  // A foot (r 0.06) lying across its top at z 0.45 grazes it by 0.01; at 0.5 it is clear.
  EXPECT_NEAR(capsule_depth_in_box({-0.2, 0.45}, {0.2, 0.45}, 0.06, -0.1, 0.1, 0.4), 0.01, 1e-12);
  EXPECT_EQ(capsule_depth_in_box({-0.2, 0.5}, {0.2, 0.5}, 0.06, -0.1, 0.1, 0.4), 0.0);
  // Beside its face, 0.03 away: a 0.04 capsule reaches 0.01 in.
  EXPECT_NEAR(capsule_depth_in_box({0.13, 0.1}, {0.13, 0.3}, 0.04, -0.1, 0.1, 0.4), 0.01, 1e-12);
  // Off its top corner by (0.03, 0.04), 0.05 away: a 0.06 capsule reaches 0.01 in.
  EXPECT_NEAR(capsule_depth_in_box({0.13, 0.44}, {0.13, 0.44}, 0.06, -0.1, 0.1, 0.4), 0.01, 1e-12);
}

TEST(WalkerJump, GhostCurbsLetTheWalkerThroughButChargeTheDepthAndForfeitTheCurb) {
  // ghost_curbs: the curb makes no MuJoCo contact, the feet overlapping its start (as in
  // the touch tests) cost ghost_depth_cost x their summed depth, and the curb can no
  // longer count as a success. Twin envs differ only in the cost.
  const std::string opts = "{curb_noise: 0, push_prob: 0, contact_ends: false, ghost_curbs: true, ghost_depth_cost: ";
  auto charged = make_task("walker_jump", opts + "100}"), free = make_task("walker_jump", opts + "0}");
  std::vector<float> obs(28);
  double reward[2];
  for (int e = 0; e < 2; ++e) {
    Env& env = e == 0 ? *charged : *free;
    env.reset(2, obs.data());
    shift_x(env, 6.9, obs);
    StepResult r = env.step(kZero, obs.data());
    EXPECT_FALSE(r.terminated);
    EXPECT_FALSE(dynamic_cast<WalkerObstacleEnv&>(env).touching()) << "a ghost curb makes no contact";
    reward[e] = r.reward;
  }
  // The depth, summed over the walker's capsules in the pose the step ended in.
  auto& m = dynamic_cast<MujocoEnv&>(*charged);
  const mjModel* mod = m.model();
  const mjData* d = m.data();
  double depth = 0.0;
  for (int g = 0; g < mod->ngeom; ++g) {
    if (mod->geom_bodyid[g] == 0) continue;
    const double* p = d->geom_xpos + 3 * g;
    const double h = mod->geom_size[3 * g + 1], zx = d->geom_xmat[9 * g + 2], zz = d->geom_xmat[9 * g + 8];
    depth += capsule_depth_in_box({p[0] - h * zx, p[2] - h * zz}, {p[0] + h * zx, p[2] + h * zz},
                                  mod->geom_size[3 * g], 7.0, 7.2, 0.4);
  }
  EXPECT_GT(depth, 0.05);
  EXPECT_NEAR(reward[1] - reward[0], 100.0 * depth, 1e-6);
  shift_x(*charged, 7.2 + 1.5 + 0.05, obs);
  StepResult r = charged->step(kZero, obs.data());
  EXPECT_EQ(r.info.success_count, 1);
  EXPECT_FALSE(r.info.success) << "a curb the walker reached into is no success";
}

TEST(WalkerJump, TakeoffShapingPaysAStanceInTheZoneOnceAndChargesOneTooClose) {
  // The curb starts at 7.0 (no noise). The walker stands with both ankles on the floor
  // at x - 7.0 = `at`; twin envs differ only in takeoff_bonus and close_stance_cost.
  auto step_rewards = [](double at, const std::string& shaping) {
    auto env = make_task("walker_jump", "{curb_noise: 0, push_prob: 0, init_random_steps: 0, init_noise: 0" + shaping + "}");
    std::vector<float> obs(28);
    env->reset(0, obs.data());
    auto& m = dynamic_cast<MujocoEnv&>(*env);
    const int f1 = mj_name2id(m.model(), mjOBJ_BODY, "foot"), f2 = mj_name2id(m.model(), mjOBJ_BODY, "foot_left");
    stand_before_curb(*env, at, obs);
    std::vector<double> rewards;
    for (int t = 0; t < 2; ++t) {
      rewards.push_back(env->step(kZero, obs.data()).reward);
      for (int f : {f1, f2}) {
        EXPECT_LE(m.data()->xpos[3 * f + 2], 0.08) << "both feet stand";
        EXPECT_NEAR(m.data()->xpos[3 * f] - 7.0, at, 0.05);
      }
    }
    return rewards;
  };
  const std::string shaping = ", takeoff_bonus: 100, close_stance_cost: 10, takeoff_zone: [-1.2, -0.6]";
  // In the zone: the bonus once, on the first step only (both feet there).
  auto plain = step_rewards(-0.9, ""), shaped = step_rewards(-0.9, shaping);
  EXPECT_NEAR(shaped[0] - plain[0], 100.0, 1e-6);
  EXPECT_NEAR(shaped[1] - plain[1], 0.0, 1e-6);
  // Between the zone and the curb: 10 for each foot, every step.
  plain = step_rewards(-0.4, ""), shaped = step_rewards(-0.4, shaping);
  EXPECT_NEAR(shaped[0] - plain[0], -20.0, 1e-6);
  EXPECT_NEAR(shaped[1] - plain[1], -20.0, 1e-6);
  // Farther back than the zone: nothing.
  plain = step_rewards(-2.0, ""), shaped = step_rewards(-2.0, shaping);
  EXPECT_NEAR(shaped[0] - plain[0], 0.0, 1e-6);
}

TEST(WalkerJump, PlacementBonusPaysTheFrontmostFootfallOnceWhenTheCurbIsDecided) {
  // Curb at 7.0. The walker stands with both ankles at x - 7.0 = `at` for two steps, then
  // is lifted 1 m and moved past the curb (`over`) or into it: the trailing foot passing
  // the curb's start, or the touch, pays B exp(-((at - target) / width)^2 / 2) once.
  // contact_ends false keeps the touching twin going for the "once" check.
  // Twin envs differ only in placement_bonus.
  auto rewards = [](double at, bool over, const std::string& shaping) {
    auto env = make_task("walker_jump", "{curb_noise: 0, push_prob: 0, init_random_steps: 0, init_noise: 0, "
                                        "contact_ends: false" + shaping + "}");
    std::vector<float> obs(28);
    env->reset(0, obs.data());
    auto& m = dynamic_cast<MujocoEnv&>(*env);
    const double ankle_offset = stand_before_curb(*env, at, obs);
    std::vector<double> r;
    for (int t = 0; t < 2; ++t) r.push_back(env->step(kZero, obs.data()).reward);
    if (over) {
      m.mutable_data()->qpos[1] += 1.0;  // feet 1 m up, trailing foot past the curb's end
      shift_x(*env, 7.5 - ankle_offset, obs);
    } else {
      m.mutable_data()->qpos[1] += 0.15;  // feet off the floor (no new footfall) ...
      shift_x(*env, 7.0 - 0.05 - ankle_offset, obs);  // ... and reaching into the curb
    }
    for (int t = 0; t < 2; ++t) r.push_back(env->step(kZero, obs.data()).reward);
    return r;
  };
  const std::string shaping = ", placement_bonus: 100, placement_target: -0.8, placement_width: 0.3";
  for (bool over : {true, false})
    for (double at : {-0.8, -1.1, -2.0}) {
      auto plain = rewards(at, over, ""), shaped = rewards(at, over, shaping);
      const double z = (at + 0.8) / 0.3, want = 100.0 * std::exp(-0.5 * z * z);
      EXPECT_NEAR(shaped[0] - plain[0], 0.0, 1e-6) << at;  // nothing while standing
      EXPECT_NEAR(shaped[1] - plain[1], 0.0, 1e-6) << at;
      // The standing feet settle by < 1 mm: 0.2 covers that (the slope is <= 202 a metre).
      EXPECT_NEAR(shaped[2] - plain[2], want, 0.2) << at << (over ? " over" : " touching");
      EXPECT_NEAR(shaped[3] - plain[3], 0.0, 1e-6) << at;  // once
    }
  // No footfall before the curb (the walker starts in the air past it): nothing.
  auto env = make_task("walker_jump", "{curb_noise: 0, push_prob: 0, init_random_steps: 0, placement_bonus: 100}");
  auto plain = make_task("walker_jump", "{curb_noise: 0, push_prob: 0, init_random_steps: 0}");
  std::vector<float> obs(28);
  double r[2];
  int i = 0;
  for (Env* e : {env.get(), plain.get()}) {
    e->reset(0, obs.data());
    dynamic_cast<MujocoEnv&>(*e).mutable_data()->qpos[1] += 1.0;
    shift_x(*e, 7.5, obs);
    r[i++] = e->step(kZero, obs.data()).reward;
  }
  EXPECT_NEAR(r[0] - r[1], 0.0, 1e-6);
}

TEST(WalkerJump, ApproachSpeedRampsTheSpeedTargetDownBeforeTheCurb) {
  // The walker in the air, 0.5 m up (clear of the 0.4 m curb), moving at 4 m/s: v is above
  // both 3 and the approach target t, so v' = t - (v - t), and twins differing only in
  // approach_speed (1, from 3 m to 1.5 m) differ by 2 ((2t - v) - (6 - v)) = 4 (t - 3) with
  // t = 3 - 2 clamp((3 - d) / 1.5, 0, 1), d = curb start - x after the step (obs[26]).
  auto step_at = [](double x, const std::string& extra, float* d) {
    auto env = make_task("walker_jump", "{curb_noise: 0, init_noise: 0, init_random_steps: 0, push_prob: 0" + extra + "}");
    std::vector<float> obs(28);
    env->reset(0, obs.data());
    auto& m = dynamic_cast<MujocoEnv&>(*env);
    m.mutable_data()->qpos[0] = x, m.mutable_data()->qpos[1] += 0.5, m.mutable_data()->qvel[0] = 4.0;
    m.forward(obs.data());
    const double r = env->step(kZero, obs.data()).reward;
    *d = obs[26];
    return r;
  };
  const std::string approach = ", approach_speed: 1, approach_from: 3, approach_to: 1.5";
  for (double x : {2.0, 4.5, 5.2, 6.0, 7.1, 7.6}) {
    float d = 0, d2 = 0;
    const double diff = step_at(x, approach, &d) - step_at(x, "", &d2);
    ASSERT_EQ(d, d2);
    const double w = x > 7.2 ? 0.0 : std::clamp((3.0 - d) / 1.5, 0.0, 1.0);  // past the curb: no target
    EXPECT_NEAR(diff, 4.0 * (-2.0 * w), 1e-4) << "x " << x << " d " << d;
  }
}

TEST(WalkerJump, EpisodeEndsPastX15) {
  auto env = make_task("walker_jump", "{curb_noise: 0, push_prob: 0}");
  std::vector<float> obs(28);
  env->reset(1, obs.data());
  shift_x(*env, 15.5, obs);
  StepResult r = env->step(kZero, obs.data());
  EXPECT_TRUE(r.terminated);
  EXPECT_TRUE(r.info.success);  // the curb was passed on the way
}

TEST(WalkerJump, SnapshotCarriesTheCurbPosition) {
  // Two curbs of random heights, so the snapshot must carry each curb's height too.
  const char* opts = "{push_prob: 0, curbs: 2, curb_height_min: 0.1}";
  auto a = make_task("walker_jump", opts), b = make_task("walker_jump", opts);
  std::vector<float> oa(28), ob(28), act(6);
  a->reset(3, oa.data());
  b->reset(4, ob.data());  // a different curb position
  shift_x(*a, 4.0, oa);    // within detection, so the curb shows in the observation
  std::vector<double> s, s2;
  a->save_state(s);
  b->restore_state(s, ob.data());
  EXPECT_EQ(oa, ob);
  b->save_state(s2);
  EXPECT_EQ(s, s2);
  for (int t = 0; t < 100; ++t) {
    Rng r(t);
    for (auto& x : act) x = float(r.symmetric(1));
    StepResult ra = a->step(act.data(), oa.data()), rb = b->step(act.data(), ob.data());
    ASSERT_EQ(oa, ob) << t;
    ASSERT_EQ(ra.reward, rb.reward) << t;
    if (ra.done()) break;
  }
}

TEST(WalkerJump, TrainingLayoutWithSeveralCurbs) {
  auto env = make_task("walker_jump", "{curbs: 3, curb_spacing: 8, curb_noise: 0, push_prob: 0}");
  std::vector<float> obs(28);
  env->reset(1, obs.data());
  // Curbs at 7, 15 and 23 (0.2 thick). Past the first, the observation shows the second.
  shift_x(*env, 12.0, obs);
  EXPECT_NEAR(obs[26], 3.0, 1e-6);
  EXPECT_NEAR(obs[27], 3.2, 1e-6);
  StepResult r = env->step(kZero, obs.data());
  EXPECT_EQ(r.info.success_count, 1);
  EXPECT_FALSE(r.info.success);  // success is every curb
  EXPECT_FALSE(r.terminated);    // the end moves with the layout: 15 + 2 x 8
  shift_x(*env, 30.5, obs);
  r = env->step(kZero, obs.data());
  EXPECT_EQ(r.info.success_count, 3);
  EXPECT_TRUE(r.info.success);
  EXPECT_FALSE(r.terminated);
  shift_x(*env, 31.5, obs);
  EXPECT_TRUE(env->step(kZero, obs.data()).terminated);
}

TEST(WalkerJump, ClearanceTermByHand) {
  const std::string base =
      "{curb_noise: 0, init_noise: 0, init_random_steps: 0, push_prob: 0, clearance_before: 1, clearance_weight: ";
  // The lower foot (the right, 0.24 m up) counts: w 0.24 / 0.4 from 1 m before the curb
  // (the walker's smallest x, the left foot's, is then 0.56 m before it) to its end.
  for (auto [x, expected] : {std::pair{6.72, 2.0 * (0.24 / 0.4)},
                             std::pair{3.0, 0.0},     // far from it
                             std::pair{7.55, 0.0}}) { // past its end (left foot at 7.27)
    auto place = [x = x](double* qpos) {
      qpos[0] = x;
      qpos[1] = 1.45;  // 0.2 m up: foot bottoms at 0.1 - 0.06 + 0.2 = 0.24
      qpos[6] = -0.3;  // left thigh swung: its foot 0.04 m higher, 0.28 m back
    };
    double diff = reward_after_placing("walker_jump", base + "2}", place) -
                  reward_after_placing("walker_jump", base + "0}", place);
    EXPECT_NEAR(diff, expected, 0.01) << "x " << x;  // one control step of free fall moves the feet ~0.3 mm
  }
}

TEST(WalkerJump, HeightWeightScalesTheHeightTermByHand) {
  // Left thigh swung back 0.6 rad, the walker lifted 0.2 m so no foot touches the floor.
  // The thigh (0.45) and shin (0.5) swung: the left ankle, now the higher foot, rises
  // 0.95 (1 - cos 0.6), and the torso's origin sits 0.2 above the hip, so
  // delta_h = 0.2 + 0.95 cos 0.6. Rewards at weights 2 and 0.5 differ by
  // -1.5 |1.1 - delta_h| (one control step of free fall barely moves it: 3e-3).
  const std::string base = "{curb_noise: 0, init_noise: 0, init_random_steps: 0, push_prob: 0, height_weight: ";
  auto place = [](double* qpos) { qpos[0] = 2.0, qpos[1] = 1.45, qpos[6] = -0.6; };
  const double delta_h = 0.2 + 0.95 * std::cos(0.6);
  EXPECT_NEAR(reward_after_placing("walker_jump", base + "2}", place) -
                  reward_after_placing("walker_jump", base + "0.5}", place),
              -1.5 * std::abs(1.1 - delta_h), 3e-3);
}

TEST(WalkerJump, PeakTermPaysOnlyNewHeights) {
  // peak_weight w pays each rise of the lower foot's bottom above its best so far for
  // this curb: placed 0.24 m up in the window, then the same, then 0.34 m up, then past
  // the curb: w 0.24, 0, w 0.10, 0 (each step falls the same ~0.3 mm from rest).
  const std::string base =
      "{curb_noise: 0, init_noise: 0, init_random_steps: 0, push_prob: 0, clearance_before: 1, peak_weight: ";
  auto with = make_task("walker_jump", base + "100}"), without = make_task("walker_jump", base + "0}");
  std::vector<float> obs(28);
  with->reset(0, obs.data());
  without->reset(0, obs.data());
  const std::pair<double, double> placements[] = {{6.72, 1.45}, {6.72, 1.45}, {6.72, 1.55}, {7.55, 1.55}};
  const double expected[] = {100 * 0.24, 0.0, 100 * 0.10, 0.0};
  for (int k = 0; k < 4; ++k) {
    double reward[2];
    for (int e = 0; e < 2; ++e) {
      auto& m = dynamic_cast<MujocoEnv&>(e == 0 ? *with : *without);
      double* qpos = m.mutable_data()->qpos;
      qpos[0] = placements[k].first, qpos[1] = placements[k].second, qpos[6] = -0.3;  // as above
      std::fill(m.mutable_data()->qvel, m.mutable_data()->qvel + 9, 0.0);  // each step from rest
      m.forward(obs.data());
      reward[e] = (e == 0 ? *with : *without).step(kZero, obs.data()).reward;
    }
    EXPECT_NEAR(reward[0] - reward[1], expected[k], 0.05) << "placement " << k;
  }
}

TEST(WalkerJump, MarkUpwardTermPaysTheTorsoVerticalSpeedAsItPassesAMark) {
  // The torso at x 6.99 moving at 3 m/s passes the curb's start (7.0) in one control step
  // (0.024 m); 0.5 m up, its feet (bottoms at 0.54) clear the 0.4 m curb. The term pays
  // w clip(vz, -2, 2) with vz after the step: rising 1 m/s, falling 3 m/s (clipped), and
  // nothing from 6.9, where no mark is passed.
  const std::string base =
      "{curb_noise: 0, init_noise: 0, init_random_steps: 0, push_prob: 0, mark_upward_weight: ";
  for (auto [x, vz] : {std::pair{6.99, 1.0}, std::pair{6.99, -3.0}, std::pair{6.9, 1.0}}) {
    double reward[2], vz_after = 0;
    for (int e = 0; e < 2; ++e) {
      auto env = make_task("walker_jump", base + (e == 0 ? "100}" : "0}"));
      std::vector<float> obs(28);
      env->reset(0, obs.data());
      auto& m = dynamic_cast<MujocoEnv&>(*env);
      double* qpos = m.mutable_data()->qpos;
      double* qvel = m.mutable_data()->qvel;
      qpos[0] = x, qpos[1] = 1.75;
      std::fill(qvel, qvel + 9, 0.0);
      qvel[0] = 3.0, qvel[1] = vz;
      m.forward(obs.data());
      StepResult r = env->step(kZero, obs.data());
      ASSERT_FALSE(r.terminated);
      reward[e] = r.reward;
      vz_after = m.mutable_data()->qvel[1];
    }
    const double expected = x > 6.95 ? 100 * std::clamp(vz_after, -2.0, 2.0) : 0.0;
    EXPECT_NEAR(reward[0] - reward[1], expected, 1e-6) << "x " << x << " vz " << vz;
    if (x > 6.95) EXPECT_NEAR(vz_after, vz - 9.81 * 0.008, 0.05);  // free flight for one step
  }
}

TEST(WalkerCrawl, CrouchTermByHand) {
  // Rewards differ by crouch_weight |torso z - crouch_height|, with the walker lifted to a
  // torso z of 1.45 m (x = 0, no ceiling; lifted, not lowered, so no foot is pushed into
  // the floor). One control step of free fall moves the torso ~0.3 mm.
  const std::string base = "{push_prob: 0, init_noise: 0, init_random_steps: 0, crouch_height: 0.6, crouch_weight: ";
  auto lift = [](double* qpos) { qpos[1] = 1.45; };
  double diff = reward_after_placing("walker_crawl", base + "3}", lift) -
                reward_after_placing("walker_crawl", base + "0}", lift);
  EXPECT_NEAR(diff, -3.0 * (1.45 - 0.6), 0.01);
}

TEST(WalkerCrawl, StandingUnderTheCeilingTouchesIt) {
  auto env = make_task("walker_crawl", "{push_prob: 0}");
  std::vector<float> obs(26);
  env->reset(0, obs.data());
  StepResult r = env->step(kZero, obs.data());
  EXPECT_FALSE(r.terminated);  // the ceiling starts at x = 2
  shift_x(*env, 5.0, obs);     // torso top at 1.45 m, ceiling underside at 0.9 m
  r = env->step(kZero, obs.data());
  EXPECT_TRUE(r.terminated);
  EXPECT_LT(r.reward, -5.0);
  // Crouched low (torso at 0.5 m) is not a fall for crawling (fall height 0.3).
  env->reset(1, obs.data());
  auto& m = dynamic_cast<MujocoEnv&>(*env);
  m.mutable_data()->qpos[1] = 0.5;
  m.forward(obs.data());
  r = env->step(kZero, obs.data());
  EXPECT_FALSE(r.terminated);
}

TEST(WalkerBalance, RewardAtRestAndSuccessAfterSurviving) {
  auto env = make_task("walker_balance", "{init_noise: 0, init_random_steps: 0, push_prob: 0, success_steps: 20, max_episode_steps: 20}");
  std::vector<float> obs(26);
  env->reset(0, obs.data());
  auto& w = dynamic_cast<WalkerEnv&>(*env);
  StepResult r;
  for (int t = 0; t < 20; ++t) {
    w.mutable_data()->qpos[1] = 1.25;  // hold it up
    double x0 = w.torso_x();
    r = env->step(kZero, obs.data());
    double v = (w.torso_x() - x0) / 0.008;
    // -|v| - 0.5 |1.1 - dh| + 0.1 cos(pitch) + 1 (no foot or control cost at rest)
    double want = -std::abs(v) - 0.5 * std::abs(1.1 - w.delta_h()) + 0.1 * std::cos(w.pitch()) + 1.0;
    ASSERT_NEAR(r.reward, want, 1e-9) << t;
  }
  EXPECT_TRUE(r.info.success);
  EXPECT_TRUE(r.truncated);
}

TEST(WalkerBackward, RewardsMovingInMinusX) {
  auto env = make_task("walker_backward", "{init_noise: 0, init_random_steps: 0, push_prob: 0}");
  std::vector<float> obs(26);
  env->reset(0, obs.data());
  auto& w = dynamic_cast<WalkerEnv&>(*env);
  w.mutable_data()->qvel[0] = -2.0;  // sliding backwards at 2 m/s
  StepResult back = env->step(kZero, obs.data());
  env->reset(0, obs.data());
  w.mutable_data()->qvel[0] = 2.0;
  StepResult fwd = env->step(kZero, obs.data());
  // v' = 3 - |(-v) - 3|: about 2 for v = -2 and about -2 for v = +2.
  EXPECT_GT(back.reward - fwd.reward, 3.0);
}

}  // namespace segue
