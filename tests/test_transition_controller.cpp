// With TP and With TP + Q (hrl/transition_controller.h): pi_ab drives exactly while the
// interval holds (or for its max_steps), a q_ab that always switches is Without TP action
// for action; at a random hand-over point, pi_ab or pi_a drives to a point drawn uniformly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "algorithms/mlp.h"
#include "algorithms/policy.h"
#include "hrl/composite_recipe.h"
#include "hrl/transition_controller.h"
#include "tests/transition_fixture.h"

namespace segue {

// Lee et al.: pi_ab's actions are sampled, and it hands over when its termination output
// fires or after the policy's max_steps (3 here); a termination output that never fires
// drives exactly max_steps steps.
TEST_F(TransitionTraining, LeeHandsOverAtItsTerminationOrAfterMaxSteps) {
  CompositeRecipe r = tiny();
  const Transition& tr = r.meta.transitions()[0];
  const Policy& b = r.skills[tr.to].policy;
  auto termination_at = [&](float bias) {  // pi_ab's actions 0, termination output `bias`
    std::vector<float> out_bias(7, 0.0f);
    out_bias[6] = bias;
    Policy p(EigenMlp({torch::zeros({7, b.obs_dim()})}, {torch::tensor(out_bias)}, Activation::Tanh), b.obs_mean(),
             b.obs_inv_std(), 10.0f, std::vector<float>(7, -1.0f), std::vector<float>(7, 1.0f));
    p.set_log_std(std::vector<float>(7, -1.0f));
    p.set_max_steps(3);
    return p;
  };
  auto env = r.make_env();
  std::vector<float> obs(r.spec.obs_dim), act(6);
  auto steps_driven = [&](const Policy& pi_ab, uint64_t noise_seed) {
    std::vector<TransitionArtefacts> art(r.meta.transitions().size());
    art[0].policy = pi_ab;
    TransitionController lee(r.skills, r.meta, art, SwitchRule::TerminationHead);
    for (uint64_t seed = 0; seed < 20; ++seed) {  // an episode that starts walking forward
      env->reset(seed, obs.data());
      lee.reset(*env, obs.data(), noise_seed);
      if (lee.skill() == tr.from) break;
    }
    EXPECT_EQ(lee.skill(), tr.from);
    int driven = 0;
    for (int t = 0; t < 300; ++t) {
      lee.act(*env, obs.data(), act.data());
      driven += lee.transition() == 0;
      if (env->step(act.data(), obs.data()).done()) break;
    }
    return driven;
  };
  // Termination mean -5, std e^-1: never fires (13 standard deviations).
  EXPECT_EQ(steps_driven(termination_at(-5.0f), 0), 3);
  // Mean 0: fires at each step with probability 1/2, so over 40 episodes (noise seeds)
  // pi_ab is cut short of the cap about 7/8 of the time, each time by its own output.
  int short_of_cap = 0;
  for (uint64_t k = 0; k < 40; ++k) short_of_cap += steps_driven(termination_at(0.0f), k) < 3;
  EXPECT_GE(short_of_cap, 25);  // binomial(40, 7/8): 35 expected, sd 2.1
  EXPECT_LT(short_of_cap, 40);
}

TEST_F(TransitionTraining, ControllersHandOverWhereTheRecipeSays) {
  CompositeRecipe r = tiny();
  const Transition& tr = r.meta.transitions()[0];
  std::vector<TransitionArtefacts> art(1);
  art[0].policy = r.skills[tr.to].policy;  // any policy on balance's slice will do
  auto env = r.make_env();
  std::vector<float> obs(r.spec.obs_dim), act(6);
  std::vector<double> f(r.spec.feature_names.size());
  // With TP: pi_ab drives exactly while the interval holds, pi_b after it.
  TransitionController tp(r.skills, r.meta, art, SwitchRule::IntervalEnd);
  int driven = 0;
  for (uint64_t seed = 0; seed < 20; ++seed) {  // an episode that starts walking forward
    env->reset(seed, obs.data());
    tp.reset(*env, obs.data(), 0);
    if (tp.skill() == tr.from) break;
  }
  ASSERT_EQ(tp.skill(), tr.from);
  for (int t = 0; t < 300; ++t) {
    tp.act(*env, obs.data(), act.data());
    env->features(f.data());
    if (tp.transition() >= 0) {
      ++driven;
      ASSERT_TRUE(MetaController::holds(tr.when, f.data())) << t;
      ASSERT_EQ(tp.skill(), tr.to);
    }
    if (env->step(act.data(), obs.data()).done()) break;
  }
  EXPECT_GT(driven, 0) << "the episode never reached the interval";
  // With a cap (max_steps) shorter than the interval, pi_ab drives exactly that long.
  CompositeRecipe capped = tiny({"transitions.0.max_steps=" + std::to_string(driven / 2)});
  TransitionController tpc(capped.skills, capped.meta, art, SwitchRule::IntervalEnd);
  for (uint64_t seed = 0;; ++seed) {  // the same episode
    env->reset(seed, obs.data());
    tpc.reset(*env, obs.data(), 0);
    if (tpc.skill() == tr.from) break;
  }
  int capped_driven = 0;
  for (int t = 0; t < 300; ++t) {
    tpc.act(*env, obs.data(), act.data());
    capped_driven += tpc.transition() >= 0;
    if (env->step(act.data(), obs.data()).done()) break;
  }
  EXPECT_EQ(capped_driven, driven / 2);
  // With TP + Q where q_ab always prefers switch: pi_b from the interval's first state,
  // which is Without TP, action for action.
  EigenMlp always_switch({torch::zeros({2, r.spec.obs_dim})}, {torch::tensor({0.0f, 1.0f})}, Activation::Relu);
  art[0].q = Policy(always_switch, std::vector<float>(r.spec.obs_dim, 0.0f), std::vector<float>(r.spec.obs_dim, 1.0f),
                    5.0f, {-1e9f, -1e9f}, {1e9f, 1e9f});
  TransitionController tpq(r.skills, r.meta, art, SwitchRule::QNetwork);
  auto without = method_controllers(r, "without-tp")();
  auto e1 = r.make_env(), e2 = r.make_env();
  std::vector<float> o1(obs.size()), o2(obs.size()), a1(6), a2(6);
  e1->reset(77, o1.data());
  e2->reset(77, o2.data());
  tpq.reset(*e1, o1.data(), 0);
  without->reset(*e2, o2.data(), 0);
  for (int t = 0; t < 300; ++t) {
    tpq.act(*e1, o1.data(), a1.data());
    without->act(*e2, o2.data(), a2.data());
    ASSERT_EQ(a1, a2) << t;
    ASSERT_LT(tpq.transition(), 0);
    if (e1->step(a1.data(), o1.data()).done() | e2->step(a2.data(), o2.data()).done()) break;
  }
}

// eval.handover_point: random, the reference code's protocol. In each episode With TP's
// pi_ab, and Without TP's pi_a, drive forward->balance's interval (here steps 20 to 120 of
// the episode) up to a point drawn uniformly over it, then pi_b; Without TP acts as pi_a
// and then as pi_b, action for action. Over the episodes the points spread over the whole
// interval, and the same episode seed draws the same point.
TEST_F(TransitionTraining, ARandomHandOverPointIsDrawnUniformlyOverTheInterval) {
  std::ofstream(path("by_steps.yaml")) << tiny_patrol_by_steps();
  CompositeRecipe r = CompositeRecipe::load(path("by_steps.yaml"), {"eval.handover_point=random", "run_dir=" + path("run")});
  ASSERT_EQ(r.handover_point, HandOverPoint::Random);
  const Transition& tr = r.meta.transitions()[0];
  const Skill &a = r.skills[tr.from], &b = r.skills[tr.to];
  ASSERT_EQ(r.spec.feature_names[3], "steps");
  std::vector<TransitionArtefacts> art(1);
  art[0].policy = b.policy;  // any policy on balance's slice will do
  auto with_tp = std::make_unique<TransitionController>(r.skills, r.meta, art, SwitchRule::IntervalEnd, r.handover_point);
  auto without = method_controllers(r, "without-tp")();
  auto& without_tp = dynamic_cast<TransitionController&>(*without);
  auto env = r.make_env();
  std::vector<float> obs(r.spec.obs_dim), act(6), own(6);
  std::vector<double> f(r.spec.feature_names.size());
  // Runs an episode that starts walking forward from `seed` (false if it starts backward);
  // *point: where in the interval control passed to pi_b (NAN if it never did inside it).
  auto episode = [&](TransitionController& c, uint64_t seed, double* point, int* driven) {
    env->reset(seed, obs.data());
    c.reset(*env, obs.data(), seed);
    if (c.skill() != tr.from) return false;
    *point = NAN, *driven = 0;
    for (int t = 0; t < 300; ++t) {
      env->features(f.data());
      const bool in_interval = MetaController::holds(tr.when, f.data());
      c.act(*env, obs.data(), act.data());
      if (c.transition() >= 0) {
        ++*driven;
        EXPECT_TRUE(in_interval) << t;
        if (&c == &without_tp) {
          a.policy.act(obs.data() + a.obs_begin, 1, own.data());
          EXPECT_EQ(act, own) << "Without TP: pi_a drives until the point, step " << t;
        }
      } else if (*driven > 0) {
        if (in_interval) *point = (f[3] - 20) / 100;
        if (&c == &without_tp) {
          b.policy.act(obs.data() + b.obs_begin, 1, own.data());
          EXPECT_EQ(act, own) << "Without TP: pi_b after the point, step " << t;
        }
        return true;
      }
      if (env->step(act.data(), obs.data()).done()) break;
    }
    return true;
  };
  for (TransitionController* c : {with_tp.get(), &without_tp}) {
    std::vector<double> points;
    double point;
    int driven;
    for (uint64_t seed = 0; seed < 60; ++seed)
      if (episode(*c, seed, &point, &driven) && !std::isnan(point)) points.push_back(point);
    ASSERT_GE(points.size(), 10u) << (c == &without_tp ? "Without TP" : "With TP");
    double mean = 0;
    for (double p : points) mean += p / points.size();
    // U(0, 1): mean 1/2 with a standard error of 0.29 / sqrt(n); both ends reached.
    EXPECT_NEAR(mean, 0.5, 4 * 0.29 / std::sqrt(double(points.size()))) << points.size() << " episodes";
    EXPECT_LT(*std::min_element(points.begin(), points.end()), 0.25);
    EXPECT_GT(*std::max_element(points.begin(), points.end()), 0.75);
  }
  double first, again;
  int driven_first, driven_again;
  uint64_t seed = 0;
  while (!episode(*with_tp, seed, &first, &driven_first)) ++seed;
  episode(*with_tp, seed, &again, &driven_again);
  EXPECT_EQ(driven_first, driven_again);
  EXPECT_GT(driven_first, 0);
}

}  // namespace segue
