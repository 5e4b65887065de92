// The walker environment: shapes, determinism, exact state save/restore, reward terms.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>

#include "core/error.h"
#include "core/rng.h"
#include "core/vector_env.h"
#include "environments/registry.h"
#include "environments/walker.h"
#include "tests/task_fixture.h"

namespace segue {
namespace {

std::function<std::unique_ptr<Env>()> walker(const std::string& overrides = "{}") {
  static std::vector<Recipe> keep;  // sections refer to their recipe
  keep.push_back(Recipe::parse(overrides, "test"));
  return task_factory("walker_forward", keep.back().root().sub("env"));
}

// A fixed pseudo-random action sequence, independent of the environment's own stream.
void action(int t, float* a, int n) {
  Rng r(1000 + t);
  for (int i = 0; i < n; ++i) a[i] = static_cast<float>(r.symmetric(1.0));
}

}  // namespace

TEST(Walker, DeclaredShapesMatchTheSpec) {
  auto env = walker()();
  EXPECT_EQ(env->spec().obs_dim, 26);  // qpos[1:] 8 + qvel 9 + qacc 9
  EXPECT_EQ(env->spec().act_dim, 6);
  EXPECT_EQ(env->spec().act_low, std::vector<float>(6, -1.0f));
  auto* m = dynamic_cast<MujocoEnv*>(env.get());
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->model()->nq, 9);
  EXPECT_EQ(m->model()->opt.integrator, mjINT_RK4);
  EXPECT_DOUBLE_EQ(m->model()->opt.timestep, 0.002);
  EXPECT_EQ(m->frame_skip(), 4);
  EXPECT_DOUBLE_EQ(m->model()->actuator_gear[0], 100.0);
}

TEST(Walker, SameSeedGivesBitIdenticalTrajectories) {
  auto make = walker();
  auto a = make(), b = make();
  std::vector<float> oa(26), ob(26), act(6);
  a->reset(42, oa.data());
  b->reset(42, ob.data());
  ASSERT_EQ(oa, ob);
  for (int t = 0; t < 300; ++t) {
    action(t, act.data(), 6);
    StepResult ra = a->step(act.data(), oa.data());
    StepResult rb = b->step(act.data(), ob.data());
    ASSERT_EQ(oa, ob) << "step " << t;
    ASSERT_EQ(ra.reward, rb.reward) << "step " << t;
    if (ra.done()) {
      a->reset(oa.data());
      b->reset(ob.data());
    }
  }
  // A different seed gives a different start.
  b->reset(43, ob.data());
  a->reset(42, oa.data());
  EXPECT_NE(oa, ob);
}

TEST(Walker, SaveRestoreReproducesTheNext100StepsExactly) {
  // Pushes off: they are drawn from the environment's random stream, which is not
  // simulator state (a restored episode draws its own).
  auto make = walker("{env: {push_prob: 0.0}}");
  auto x = make(), y = make();
  std::vector<float> obs(26), obs2(26), act(6);
  const float zero[6] = {0, 0, 0, 0, 0, 0};
  x->reset(5, obs.data());
  for (int t = 0; t < 20; ++t) x->step(zero, obs.data());  // somewhere mid-episode
  std::vector<double> state;
  x->save_state(state);
  const std::vector<float> obs_at_save = obs;
  std::vector<std::vector<float>> ref;
  std::vector<double> ref_r;
  for (int t = 0; t < 100; ++t) {
    action(t, act.data(), 6);
    ref_r.push_back(x->step(act.data(), obs.data()).reward);
    ref.push_back(obs);
  }
  // Restore into another instance that has lived another life.
  y->reset(77, obs2.data());
  for (int t = 0; t < 7; ++t) y->step(zero, obs2.data());
  y->restore_state(state, obs2.data());
  ASSERT_EQ(obs2, obs_at_save);
  EXPECT_EQ(dynamic_cast<MujocoEnv*>(y.get())->episode_step(), 20);
  for (int t = 0; t < 100; ++t) {
    action(t, act.data(), 6);
    ASSERT_EQ(y->step(act.data(), obs2.data()).reward, ref_r[t]) << "step " << t;
    ASSERT_EQ(obs2, ref[t]) << "step " << t;
  }
}

TEST(Walker, SnapshotCarriesAnAppliedPush) {
  auto make = walker("{env: {push_prob: 1.0}}");
  auto x = make(), y = make();
  std::vector<float> obs(26);
  const float zero[6] = {0, 0, 0, 0, 0, 0};
  x->reset(3, obs.data());
  x->step(zero, obs.data());
  std::vector<double> state, again;
  x->save_state(state);
  y->reset(4, obs.data());
  y->restore_state(state, obs.data());
  y->save_state(again);
  EXPECT_EQ(state, again);
  EXPECT_TRUE(pushed(*dynamic_cast<MujocoEnv*>(y.get())));
}

TEST(Walker, RewardTermsAtTheStandingPose) {
  // No noise, no random actions, no pushes: the walker starts exactly at the model pose.
  auto make = walker("{env: {init_noise: 0, init_random_steps: 0, push_prob: 0}}");
  auto env = make();
  std::vector<float> obs(26);
  env->reset(0, obs.data());
  // Observation at the reference pose: qpos[1:] = (1.25, 0, ...), velocities 0.
  EXPECT_FLOAT_EQ(obs[0], 1.25f);
  for (int i = 1; i < 8; ++i) EXPECT_FLOAT_EQ(obs[i], 0.0f);
  for (int i = 8; i < 17; ++i) EXPECT_FLOAT_EQ(obs[i], 0.0f);
  auto* w = dynamic_cast<WalkerEnv*>(env.get());
  // Torso origin at 1.25, feet (ankle bodies) at 0.1: delta_h = 1.15.
  EXPECT_NEAR(w->delta_h(), 1.15, 1e-9);
  const float zero[6] = {0, 0, 0, 0, 0, 0};
  double x0 = w->torso_x();
  StepResult r = env->step(zero, obs.data());
  // Recompute the reward from the state after the step, term by term.
  const mjData* d = w->data();
  double v = (w->torso_x() - x0) / 0.008;
  double feet = std::abs(d->qvel[5]) + std::abs(d->qvel[8]);
  double want = (3 - std::abs(v - 3)) + 0.1 * std::cos(d->qpos[2]) + 1.0 -
                std::abs(1.1 - w->delta_h()) - 0.01 * feet;
  EXPECT_NEAR(r.reward, want, 1e-9);
  EXPECT_FALSE(r.terminated);
}

TEST(Walker, FallingEndsTheEpisodeAndSurvivingSucceeds) {
  auto env = walker("{env: {push_prob: 0, max_episode_steps: 30, success_steps: 30}}")();
  std::vector<float> obs(26);
  env->reset(1, obs.data());
  auto* w = dynamic_cast<WalkerEnv*>(env.get());
  // Hold the pose by hand each step (a scripted "survive"): success at step 30.
  StepResult r;
  for (int t = 0; t < 30; ++t) {
    mjData* d = w->mutable_data();
    d->qpos[1] = 1.25;
    d->qpos[2] = 0;
    r = env->step(std::vector<float>(6, 0.0f).data(), obs.data());
    if (t < 29) ASSERT_FALSE(r.done()) << t;
  }
  EXPECT_TRUE(r.truncated);
  EXPECT_TRUE(r.info.success);
  EXPECT_EQ(r.info.success_count, 1);
  // Drop the torso below 0.8 m: terminated, no success.
  env->reset(2, obs.data());
  w->mutable_data()->qpos[1] = 0.5;
  r = env->step(std::vector<float>(6, 0.0f).data(), obs.data());
  EXPECT_TRUE(r.terminated);
  EXPECT_FALSE(r.info.success);
}

TEST(VectorEnv, ResultsDoNotDependOnThreadCount) {
  auto make = walker();
  VectorEnv one(make, 6, 1), two(make, 6, 2);
  one.reset(3);
  two.reset(3);
  std::vector<float> act(6 * 6);
  for (int t = 0; t < 200; ++t) {
    for (int i = 0; i < 6; ++i) action(t * 6 + i, &act[i * 6], 6);
    one.step(act.data());
    two.step(act.data());
    ASSERT_EQ(std::vector<float>(one.obs(), one.obs() + 36), std::vector<float>(two.obs(), two.obs() + 36));
    ASSERT_EQ(one.reward(), two.reward());
  }
  ASSERT_EQ(one.finished().size(), two.finished().size());
  EXPECT_GT(one.finished().size(), 0u);  // random actions fall over within 200 steps
}

}  // namespace segue

namespace segue {

TEST(ThreadPool, EveryItemOnceEvenWhenJobsArriveBeforeWorkersStart) {
  for (int round = 0; round < 200; ++round) {
    ThreadPool pool(2);  // a job posted at once, before the worker has run
    std::vector<int> hits(37, 0);
    pool.parallel_for(37, [&](int b, int e) {
      for (int i = b; i < e; ++i) hits[i] += 1;
    });
    pool.parallel_for(5, [&](int b, int e) {
      for (int i = b; i < e; ++i) hits[i] += 10;
    });
    for (int i = 0; i < 37; ++i) ASSERT_EQ(hits[i], i < 5 ? 11 : 1) << "round " << round << " item " << i;
  }
}

// An item that throws on a worker thread reaches the caller as that exception (the
// process would otherwise end); the other items still run, and the pool stays usable.
TEST(ThreadPool, AWorkersExceptionIsRethrownToTheCaller) {
  ThreadPool pool(2);
  for (int round = 0; round < 200; ++round) {
    std::vector<std::atomic<int>> hits(16);
    try {
      pool.parallel_for(16, [&](int b, int) {
        if (b == 5 || b == 11) throw Error("item " + std::to_string(b));
        hits[b] += 1;
      });
      FAIL() << "round " << round << ": no exception reached the caller";
    } catch (const Error& e) {
      const std::string what = e.what();
      ASSERT_TRUE(what == "item 5" || what == "item 11") << what;
    }
    for (int i = 0; i < 16; ++i) ASSERT_EQ(hits[i].load(), i == 5 || i == 11 ? 0 : 1) << "round " << round;
  }
  std::atomic<int> sum{0};
  pool.parallel_for(4, [&](int, int) { sum += 1; });
  EXPECT_EQ(sum.load(), 4);
}

}  // namespace segue
