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

// A saved state restores exactly; one with another count of the jump's own numbers (another
// layout, or an older Segue's) is refused rather than misread.
TEST(WalkerJump, RestoresItsOwnStateAndRefusesAnotherLayout) {
  auto env = make_task("walker_jump", "{curbs: 3, curb_spacing: 8, curb_height_min: 0.3}");
  std::vector<float> obs(28), again(28), act(6, 0.1f);
  env->reset(4, obs.data());
  for (int t = 0; t < 20; ++t) env->step(act.data(), obs.data());
  std::vector<double> state;
  env->save_state(state);
  auto other = make_task("walker_jump", "{curbs: 3, curb_spacing: 8, curb_height_min: 0.3}");
  other->reset(9, again.data());
  other->restore_state(state, again.data());
  EXPECT_EQ(again, obs);
  std::vector<double> longer = state;
  const double own = longer.back();  // the jump's own numbers: crossed, touched, one height per curb
  EXPECT_EQ(own, 2 + 3);
  longer.insert(longer.end() - 1, {0.0, 0.0});
  longer.back() = own + 2;
  try {
    other->restore_state(longer, again.data());
    ADD_FAILURE() << "a state of another layout was restored";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("a saved state with 7 numbers of the jump's own, not 5"), std::string::npos)
        << e.what();
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
