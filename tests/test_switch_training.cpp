// Algorithm 2 (hrl/switch_training.h): q_ab exports like a policy, training resumes exactly
// from its checkpoint, the margin is chosen on held-out starts (hrl/switch_margin.h), and
// run_subtask's lookahead ends at the task's own events (hrl/switch_interval.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "core/assets.h"
#include "hrl/collection.h"
#include "hrl/composite_recipe.h"
#include "hrl/switch_training.h"
#include "hrl/transition_controller.h"
#include "tests/transition_fixture.h"

namespace segue {

TEST_F(TransitionTraining, SwitchQNetworkExportsAsAPolicy) {
  CompositeRecipe r = tiny();
  const Skill& b = r.skills[r.meta.transitions()[0].to];
  SwitchTrainer trainer = switch_trainer(r, 0, collect_start_states(r, 0, 6, 1), b.policy, 4);
  SwitchStats s = trainer.run(24);
  EXPECT_EQ(s.attempts, 24);
  // The rate is over the 24 attempts: a whole number of them.
  EXPECT_NEAR(s.success_rate * 24, std::round(s.success_rate * 24), 1e-9);
  EXPECT_GT(s.loss, 0.0);  // updates ran (warmup 16 rows)
  Policy q = trainer.q_function();
  ASSERT_EQ(q.obs_dim(), r.spec.obs_dim);
  ASSERT_EQ(q.act_dim(), 2);
  q.export_torchscript(path("q.pt"));
  Policy back = Policy::load(path("q.pt"));
  auto obs = random_obs(8, q.obs_dim(), 3);
  std::vector<float> a(16), c(16);
  q.act(obs.data(), 8, a.data());
  back.act(obs.data(), 8, c.data());
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(a[i], c[i], 1e-5);
}

// A switch stage stopped and resumed from its checkpoint trains exactly the q_ab an
// unbroken one does: same attempts, same minibatches, same weights.
TEST_F(TransitionTraining, SwitchTrainingResumesExactlyFromItsCheckpoint) {
  CompositeRecipe r = tiny();
  const Skill& b = r.skills[r.meta.transitions()[0].to];
  StartStates starts = collect_start_states(r, 0, 6, 1);
  auto make = [&] { return std::make_unique<SwitchTrainer>(switch_trainer(r, 0, starts, b.policy, 4)); };
  auto whole = make();
  whole->run(12);
  whole->run(12);
  auto first = make();
  ASSERT_GT(first->run(12).loss, 0.0);  // updates ran before the checkpoint (warmup 16 rows)
  first->save(path("switch_checkpoint.pt"));
  first.reset();
  torch::rand({7});  // LibTorch's stream moves on in between, as other stages move it
  auto resumed = make();
  resumed->load(path("switch_checkpoint.pt"));
  EXPECT_EQ(resumed->attempts_done(), 12);
  resumed->run(12);
  EXPECT_EQ(resumed->attempts_done(), whole->attempts_done());
  EXPECT_EQ(resumed->env_steps(), whole->env_steps());
  std::vector<float> want = whole->q_function().mlp().parameters(), got = resumed->q_function().mlp().parameters();
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) ASSERT_EQ(got[i], want[i]) << "parameter " << i;
  // A checkpoint whose replay buffer the recipe cannot hold is refused, naming the file and key.
  CompositeRecipe other_replay = tiny({"switch.replay=5000"});
  SwitchTrainer other = switch_trainer(other_replay, 0, starts, b.policy, 4);
  try {
    other.load(path("switch_checkpoint.pt"));
    ADD_FAILURE() << "a checkpoint of another replay capacity was loaded";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("switch_checkpoint.pt: the checkpoint's replay buffer holds 1000000 rows"), std::string::npos)
        << what;
    EXPECT_NE(what.find("the recipe's 5000 of"), std::string::npos) << what;
    EXPECT_NE(what.find("another capacity or row width (switch.replay"), std::string::npos) << what;
  }
}

// The switch margin is chosen on held-out S_a states: each margin's success rate equals a
// by-hand replay with the exported q_ab (margin folded into Q(stay)) from those states.
TEST_F(TransitionTraining, SwitchMarginIsChosenOnHeldOutStarts) {
  CompositeRecipe r = tiny({"switch.validation_starts=4", "switch.margins=[10, -10, 0.05]"});
  const Transition& tr = r.meta.transitions()[0];
  const Skill& b = r.skills[tr.to];
  StartStates starts = collect_start_states(r, 0, 10, 1);
  // The shipped pi_ab: balance itself falls from the walk's states, so every margin would fail.
  Policy pi_ab = Policy::load(repo_path("assets/policies/walker/patrol/forward-balance/policy.pt"));
  SwitchTrainer trainer = switch_trainer(r, 0, starts, pi_ab, 4);
  trainer.run(24);
  const int64_t trained_steps = trainer.env_steps();
  MarginChoice c = trainer.choose_margin();
  EXPECT_GT(trainer.env_steps(), trained_steps) << "the held-out runs' steps are the stage's too";
  ASSERT_EQ(c.margins, (std::vector<double>{-10, 0.05, 10}));
  // -10 hands over at once (Without TP), 10 at the interval's end (With TP): these differ.
  EXPECT_LT(c.success.front(), c.success.back());
  auto env = r.make_env();
  TransitionController after(r.skills, r.meta, {}, SwitchRule::IntervalEnd);
  std::vector<float> obs(r.spec.obs_dim), act(r.spec.act_dim), q(2), q0(2);
  std::vector<double> f(r.spec.feature_names.size()), state;
  const Policy plain = trainer.q_function();
  ASSERT_EQ(plain.obs_dim(), r.spec.obs_dim);
  const std::vector<float> x(plain.obs_dim(), 0.3f);
  for (size_t m = 0; m < c.margins.size(); ++m) {
    Policy q_ab = trainer.q_function(c.margins[m]);
    q_ab.act(x.data(), 1, q.data());
    plain.act(x.data(), 1, q0.data());
    EXPECT_NEAR(q[0] - q0[0], c.margins[m], 1e-4);
    EXPECT_EQ(q[1], q0[1]);
    int succeeded = 0;
    for (int i = 6; i < 10; ++i) {
      starts.state(i, state);
      env->restore_state(state, obs.data());
      bool fell = false;
      for (;;) {
        q_ab.act(obs.data(), 1, q.data());
        if (q[1] > q[0]) break;  // switch
        pi_ab.act(obs.data() + b.obs_begin, 1, act.data());
        StepResult sr = env->step(act.data(), obs.data());
        env->features(f.data());
        if ((fell = sr.terminated)) break;
        if (sr.truncated || !MetaController::holds(tr.when, f.data())) break;  // the forced switch
      }
      if (!fell) succeeded += run_subtask(*env, after, tr.to, obs.data(), 1, r.pipeline.switching.max_subtask_steps);
    }
    EXPECT_DOUBLE_EQ(c.success[m], succeeded / 4.0) << "margin " << c.margins[m];
  }
  // The best held-out success, the larger margin on ties.
  double best = *std::max_element(c.success.begin(), c.success.end());
  size_t k = c.margins.size() - 1;
  while (c.success[k] < best) --k;
  EXPECT_EQ(c.margin, c.margins[k]);
  // Holding out all of S_a leaves nothing to train on.
  CompositeRecipe all = tiny({"switch.validation_starts=10"});
  try {
    switch_trainer(all, 0, starts, b.policy, 4);
    ADD_FAILURE() << "validation_starts = |S_a| was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "switch training: validation_starts (10) leaves none of S_a's 10 states to train on");
  }
}

TEST_F(TransitionTraining, SubtaskLookaheadEndsAtTheTasksOwnEvents) {
  // All four Patrol transitions, the shipped transition policies, long episodes. After
  // pi_{forward,balance} has run its interval, balance's own subtask is over at once
  // (lookahead 1: 0 steps); with lookahead 2 the episode runs on through balance -> walk and the walk
  // until the walker passes the next stone (since_turn = 0); with 3, until the
  // walk -> balance interval after that turn has ended (since_turn = 101).
  std::string file = path("patrol4.yaml");
  std::string text = kTinyPatrol;
  text.replace(text.find("seed: 3"), 0,
               "  - {from: backward, to: balance, when: {since_turn: [0, 100]}}\n"
               "  - {from: balance, to: forward, when: {direction: 1, since_turn: [100, 1.0e+6], progress: [-1.0e+6, 4]}}\n"
               "  - {from: balance, to: backward, when: {direction: -1, since_turn: [100, 1.0e+6], progress: [-1.0e+6, 4]}}\n");
  std::ofstream(file) << text;
  CompositeRecipe r = CompositeRecipe::load(file, {"env.max_episode_steps=5000", "run_dir=" + path("run4")});
  ASSERT_EQ(r.meta.transitions().size(), 4u);
  auto shipped = load_transition_artefacts(r, repo_path("assets/policies/walker/patrol"), "policy.pt", false);
  TransitionController after(r.skills, r.meta, shipped, SwitchRule::IntervalEnd);
  const Transition& fb = r.meta.transitions()[0];
  const Skill& balance = r.skills[fb.to];
  StartStates starts = collect_start_states(r, 0, 6, 2);
  auto env = r.make_env();
  std::vector<float> obs(r.spec.obs_dim), act(r.spec.act_dim);
  std::vector<double> f(r.spec.feature_names.size()), x, state;
  int reached[4] = {};
  for (int i = 0; i < starts.size(); ++i) {
    starts.state(i, state);
    env->restore_state(state, obs.data());
    bool fell = false;
    for (env->features(f.data()); MetaController::holds(fb.when, f.data()) && !fell; env->features(f.data())) {
      shipped[0].policy->act(obs.data() + balance.obs_begin, 1, act.data());
      fell = env->step(act.data(), obs.data()).terminated;
    }
    if (fell) continue;
    env->save_state(x);
    const int since_x = int(f[1]);
    for (int lookahead : {1, 2, 3}) {
      env->restore_state(x, obs.data());
      int64_t steps = 0;
      bool ok = run_subtask(*env, after, fb.to, obs.data(), lookahead, 5000, &steps);
      env->features(f.data());
      if (lookahead == 1) {  // balance -> walk's interval holds already (since_turn >= 100)
        EXPECT_TRUE(ok);
        EXPECT_EQ(steps, 0) << i;
        EXPECT_EQ(int(f[1]), since_x);
      }
      if (!ok) break;  // a fall: later lookaheads fail too
      if (lookahead == 2) EXPECT_EQ(f[1], 0.0) << i << ": ended at the next turn";
      // The walk -> balance interval [0, 100] runs to its end before balance hands over.
      if (lookahead == 3) EXPECT_EQ(f[1], 101.0) << i << ": ended when walk -> balance's interval did";
      ++reached[lookahead];
    }
  }
  EXPECT_GT(reached[3], 0) << "no episode got through a whole walk: lookahead 2 and 3 were not checked";
}

}  // namespace segue
