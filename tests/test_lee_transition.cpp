// Lee et al.'s baseline (hrl/lee_transition.h): episodes end at the termination output
// with pi_b's outcome, the termination head starts at its bias, and a checkpoint keeps the
// proximity predictor's labelled states.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "core/vector_env.h"
#include "hrl/collection.h"
#include "hrl/lee_transition.h"
#include "hrl/switch_training.h"
#include "hrl/transition_controller.h"
#include "tests/transition_fixture.h"

namespace segue {

// A resumed Lee stage keeps the proximity predictor's labelled states (every finished
// episode's; T_b's are the recipe's), not only its weights.
TEST_F(TransitionTraining, LeeCheckpointKeepsThePredictorsLabelledStates) {
  CompositeRecipe r = tiny();
  const Skill& b = r.skills[r.meta.transitions()[0].to];
  StartStates starts = collect_start_states(r, 0, 6, 1);
  Demonstrations expert = collect_demonstrations(r, 0, 300, 2);
  auto envs = [&] {
    return std::make_unique<VectorEnv>([&] { return std::make_unique<LeeTransitionEnv>(r.make_env, r.skills, r.meta, 0, starts, 0, 500); },
                                       r.pipeline.transition.ppo.num_envs, 1);
  };
  auto first_envs = envs();
  LeeTrainer first(r.pipeline.transition, r.pipeline.lee, *first_envs, expert, b.policy, 5);
  EXPECT_EQ(first.positives_seen(), 0);  // T_b is kept apart
  EXPECT_EQ(first.negatives_seen(), 0);
  first.iterate(), first.iterate();
  ASSERT_GT(first.positives_seen() + first.negatives_seen(), 0) << "no episode was labelled";
  first.save(path("lee_checkpoint.pt"), "test");
  auto again_envs = envs();
  LeeTrainer again(r.pipeline.transition, r.pipeline.lee, *again_envs, expert, b.policy, 5);
  again.load(path("lee_checkpoint.pt"));
  EXPECT_EQ(again.positives_seen(), first.positives_seen());
  EXPECT_EQ(again.negatives_seen(), first.negatives_seen());
  EXPECT_EQ(again.ppo().iteration(), 2);
}

// Lee et al.'s termination head starts at lee.termination_bias also when the policy starts
// from random weights (transition.init_from_next: false), not at ~0, where sampling would end
// half the episodes at their first step.
TEST_F(TransitionTraining, LeeTerminationHeadStartsAtItsBiasFromRandomWeights) {
  for (const char* init : {"true", "false"}) {
    CompositeRecipe r = tiny({std::string("transition.init_from_next=") + init, "lee.termination_bias=-0.6"});
    const Skill& b = r.skills[r.meta.transitions()[0].to];
    StartStates starts = collect_start_states(r, 0, 4, 1);
    Demonstrations expert = collect_demonstrations(r, 0, 100, 2);
    VectorEnv envs([&] { return std::make_unique<LeeTransitionEnv>(r.make_env, r.skills, r.meta, 0, starts, 0, 500); }, 2, 1);
    LeeTrainer lee(r.pipeline.transition, r.pipeline.lee, envs, expert, b.policy, 5);
    const int D = envs.spec().obs_dim, A = envs.spec().act_dim;
    auto obs = random_obs(16, D, 3);
    std::vector<float> act(16 * A);
    lee.policy().act(obs.data(), 16, act.data());
    // The output layer's weights start at gain 0.01 (from random) or 0 (from pi_b) on it.
    for (int i = 0; i < 16; ++i) EXPECT_NEAR(act[i * A + A - 1], -0.6, 0.1) << init << " " << i;
  }
}

TEST_F(TransitionTraining, LeeEpisodesEndAtTheTerminationOutputWithPiBsOutcome) {
  CompositeRecipe r = tiny();
  StartStates starts = collect_start_states(r, 0, 4, 1);
  LeeTransitionEnv env(r.make_env, r.skills, r.meta, 0, starts, 0, 500);
  ASSERT_EQ(env.spec().act_dim, 7);  // pi_b's 6 and the termination output
  std::vector<float> obs(env.spec().obs_dim), act(7, 0.0f);
  for (uint64_t seed = 0; seed < 4; ++seed) {
    env.reset(seed, obs.data());
    std::vector<double> state;
    env.save_state(state);
    // Two steps of pi_ab, then its termination output fires.
    act[6] = -1.0f;
    ASSERT_FALSE(env.step(act.data(), obs.data()).done());
    ASSERT_FALSE(env.step(act.data(), obs.data()).done());
    std::vector<double> at_end;
    env.save_state(at_end);
    act[6] = 1.0f;
    StepResult sr = env.step(act.data(), obs.data());
    EXPECT_TRUE(sr.terminated);
    // The outcome is pi_b's, run from the state where pi_ab stopped.
    auto task = r.make_env();
    std::vector<float> full(r.spec.obs_dim);
    task->restore_state(at_end, full.data());
    TransitionController pi_b(r.skills, r.meta, {}, SwitchRule::IntervalEnd);
    EXPECT_EQ(sr.info.success, run_subtask(*task, pi_b, r.meta.transitions()[0].to, full.data(), 1, 500)) << seed;
    auto episodes = env.take_finished();
    ASSERT_EQ(episodes.size(), 1u);
    EXPECT_EQ(episodes[0].states.size(), 3u * obs.size());  // s_0, s_1, s_2 = s_T
    EXPECT_EQ(episodes[0].success, sr.info.success);
  }
}

// lee.max_steps: pi_ab hands over to pi_b after that many steps even if its termination
// output never fires, as the reference caps a transition (at evaluation:
// test_transition_controller.cpp).
TEST_F(TransitionTraining, LeeHandsOverAfterMaxSteps) {
  CompositeRecipe r = tiny();
  StartStates starts = collect_start_states(r, 0, 4, 1);
  LeeTransitionEnv env(r.make_env, r.skills, r.meta, 0, starts, 3, 500);
  std::vector<float> obs(env.spec().obs_dim), act(7, 0.0f);
  act[6] = -1.0f;  // never terminates by itself
  env.reset(0, obs.data());
  ASSERT_FALSE(env.step(act.data(), obs.data()).done());
  ASSERT_FALSE(env.step(act.data(), obs.data()).done());
  EXPECT_TRUE(env.step(act.data(), obs.data()).terminated);
  auto episodes = env.take_finished();
  ASSERT_EQ(episodes.size(), 1u);
  EXPECT_EQ(episodes[0].states.size(), 4u * obs.size());  // s_0 .. s_3
}

}  // namespace segue
