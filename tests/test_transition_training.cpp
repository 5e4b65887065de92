// Algorithms 1 and 2 wired together: the transition policy's rewards are Eq. 3 of its own
// discriminator, pi_ab starts as pi_b, the switch Q-network exports like a policy, the
// controllers hand over where the recipe says, and `segue run`'s pipeline writes every
// artefact and resumes.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/assets.h"
#include "environments/registry.h"
#include "hrl/lee_transition.h"
#include "hrl/pipeline.h"
#include "hrl/switch_training.h"
#include "hrl/transition_env.h"
#include "hrl/transition_policy.h"
#include "temp_dir.h"
#include "tests/csv.h"
#include "tests/tiny_patrol.h"

namespace segue {
namespace {

namespace fs = std::filesystem;


class TransitionTraining : public TempDirTest {
 protected:
  TransitionTraining() : TempDirTest("transition_training") {}
  CompositeRecipe tiny(std::vector<std::string> sets = {}) {
    std::string file = path("tiny_patrol.yaml");
    std::ofstream(file) << kTinyPatrol;
    sets.push_back("run_dir=" + path("run"));
    return CompositeRecipe::load(file, sets);
  }
};

std::vector<float> random_obs(int n, int d, uint64_t seed) {
  Rng rng(seed);
  std::vector<float> v(size_t(n) * d);
  for (auto& x : v) x = float(2.0 * rng.normal());
  return v;
}

}  // namespace

TEST_F(TransitionTraining, PiAbStartsAsPiB) {
  CompositeRecipe r = tiny();
  const Policy& balance = r.skills[2].policy;
  VectorEnv envs(task_factory("walker_balance", Recipe::parse("{}", "b").root()), 2, 1);
  ActorCriticSpec net;
  net.obs_dim = balance.obs_dim(), net.act_dim = balance.act_dim();
  net.vf_hidden = {64, 64};
  PPO ppo(PpoConfig(), net, envs, 1);
  ppo.init_actor(balance);
  auto obs = random_obs(16, net.obs_dim, 5);
  std::vector<float> want(16 * 6), got(16 * 6);
  balance.act(obs.data(), 16, want.data());
  ppo.policy().act(obs.data(), 16, got.data());
  for (size_t i = 0; i < want.size(); ++i) ASSERT_NEAR(got[i], want[i], 1e-4) << i;
}

// A jump run may start as the shipped walk (recipe key init_policy): the walk sees the
// first 26 inputs, and the obstacle pair starts at zero weight and unscaled.
TEST_F(TransitionTraining, ActorStartsAsAPolicyOnAPrefixOfItsObservation) {
  Policy walk = Policy::load(repo_path("assets/policies/walker/walker_forward.pt"));
  VectorEnv envs(task_factory("walker_jump", Recipe::parse("{}", "j").root()), 2, 1);
  ActorCriticSpec net;
  net.obs_dim = envs.spec().obs_dim, net.act_dim = envs.spec().act_dim;
  ASSERT_EQ(net.obs_dim, walk.obs_dim() + 2);
  PPO ppo(PpoConfig(), net, envs, 1);
  ppo.init_actor(walk);
  auto obs = random_obs(16, net.obs_dim, 9);
  std::vector<float> prefix(16 * walk.obs_dim());
  for (int i = 0; i < 16; ++i)
    std::copy_n(&obs[i * net.obs_dim], walk.obs_dim(), &prefix[i * walk.obs_dim()]);
  std::vector<float> want(16 * 6), got(16 * 6);
  walk.act(prefix.data(), 16, want.data());
  ppo.policy().act(obs.data(), 16, got.data());
  for (size_t i = 0; i < want.size(); ++i) ASSERT_NEAR(got[i], want[i], 1e-4) << i;
  EXPECT_FLOAT_EQ(ppo.policy().obs_mean()[net.obs_dim - 1], 0.0f);
  EXPECT_NEAR(ppo.policy().obs_inv_std()[net.obs_dim - 1], 1.0f, 1e-6);
  // A policy that sees more than the task gives cannot start it.
  VectorEnv walks(task_factory("walker_forward", Recipe::parse("{}", "w").root()), 2, 1);
  ActorCriticSpec small = net;
  small.obs_dim = walks.spec().obs_dim;
  PPO narrow(PpoConfig(), small, walks, 1);
  EXPECT_THROW(narrow.init_actor(ppo.policy()), Error);
}

// pi_b with periodic input features (a jump that reads the curb's phase): pi_ab's network
// takes them when it starts as pi_b, and then acts exactly as pi_b; not otherwise.
TEST_F(TransitionTraining, TransitionNetworkTakesNextSkillsFeatures) {
  VectorEnv envs(task_factory("walker_jump", Recipe::parse("{}", "j").root()), 2, 1);
  ActorCriticSpec featured;
  featured.obs_dim = envs.spec().obs_dim, featured.act_dim = envs.spec().act_dim;
  featured.features = ObsFeatures{{26}, {1.9, 3.8}};
  PPO jump_trainer(PpoConfig(), featured, envs, 3);
  jump_trainer.iterate();
  const Policy jump = jump_trainer.policy();

  TransitionPolicyConfig tp;
  ActorCriticSpec net = tp.network(envs.spec(), jump);
  EXPECT_EQ(net.obs_dim, 28);
  EXPECT_TRUE(net.features == featured.features);
  PPO pi_ab(tp.ppo, net, envs, 4);
  pi_ab.init_actor(jump);
  auto obs = random_obs(8, 28, 5);
  std::vector<float> want(8 * 6), got(8 * 6);
  jump.act(obs.data(), 8, want.data());
  pi_ab.policy().act(obs.data(), 8, got.data());
  for (size_t i = 0; i < want.size(); ++i) ASSERT_NEAR(got[i], want[i], 1e-5) << i;

  tp.init_from_next = false;
  EXPECT_TRUE(tp.network(envs.spec(), jump).features.empty());
}

TEST_F(TransitionTraining, GeneratorRewardsAreEq3OfTheDiscriminator) {
  // The last case gives D periodic features of an input (transition.discriminator.fourier).
  const std::vector<std::pair<std::string, std::string>> cases{
      {"airl", ""}, {"airl_absorbing", ""}, {"airl_absorbing", "{inputs: [0], periods: [0.5]}"}};
  for (const auto& [mode, fourier] : cases) {
    SCOPED_TRACE(fourier);
    std::vector<std::string> sets{"transition.reward=" + mode, "transition.discriminator.steps=16"};
    if (!fourier.empty()) sets.push_back("transition.discriminator.fourier=" + fourier);
    CompositeRecipe r = tiny(sets);
    const TransitionPolicyConfig& cfg = r.pipeline.transition;
    const Transition& tr = r.meta.transitions()[0];
    const Skill& b = r.skills[tr.to];
    StartStates starts = collect_start_states(r, 0, 6, 1);
    VectorEnv envs([&] { return std::make_unique<TransitionEnv>(r.make_env(), starts, tr, b.obs_begin, b.obs_end); },
                   cfg.ppo.num_envs, 1);
    TransitionPolicyTrainer trainer(cfg, envs, collect_demonstrations(r, 0, 300, 2), b.policy, 7);
    EXPECT_EQ(trainer.discriminator()->spec.features.size(), fourier.empty() ? 0 : 2);
    std::vector<double> losses;
    for (int i = 0; i < 6; ++i) losses.push_back(trainer.iterate().disc_loss);
    // The discriminator learns to tell pi_b's steps from pi_ab's (log 2 at chance).
    EXPECT_LT(losses.back(), losses.front()) << mode;
    EXPECT_LT(losses.back(), std::log(2.0)) << mode;

    // Recompute the last rollout's rewards independently of the hook.
    const RolloutBuffer& buf = trainer.ppo().buffer();
    const int64_t M = int64_t(buf.T) * buf.N, D = buf.obs_dim, A = buf.act_dim;
    auto obs = torch::from_blob(const_cast<float*>(buf.raw_obs.data()), {M, D});
    auto next = torch::from_blob(const_cast<float*>(buf.next_raw_obs.data()), {M, D});
    auto act = torch::from_blob(const_cast<float*>(buf.actions.data()), {M, A}).clamp(-1.0, 1.0);
    auto logp = torch::from_blob(const_cast<float*>(buf.log_probs.data()), {M});
    std::vector<float> done(M, 0.0f);
    std::vector<bool> truncated(M, false);
    for (int k : buf.truncated_index) truncated[k] = true;
    int falls = 0;
    for (int64_t k = 0; k < M; ++k) done[k] = buf.dones[k] && !truncated[k], falls += done[k] > 0;
    auto reward = trainer.discriminator()->reward(obs, act, next, torch::from_blob(done.data(), {M}), logp);
    // Eq. 3 is the logit of D: log D - log(1 - D) with D = exp f / (exp f + pi).
    auto f = trainer.discriminator()->f(obs, act, next, torch::from_blob(done.data(), {M})).detach();
    auto d = torch::exp(f) / (torch::exp(f) + torch::exp(logp));
    EXPECT_TRUE(torch::allclose(reward, torch::log(d) - torch::log(1 - d), 1e-3, 1e-3)) << mode;
    double worst = reward.min().item<double>(), gamma = cfg.ppo.gamma;
    for (int64_t k = 0; k < M; ++k) {
      double want = reward[k].item<double>();
      if (mode == "airl_absorbing" && done[k]) want += gamma * std::min(worst, 0.0) / (1 - gamma);
      ASSERT_NEAR(buf.raw_rewards[k], want, 1e-3 * std::max(1.0, std::abs(want))) << mode << " row " << k;
    }
    if (mode == "airl_absorbing") EXPECT_GT(falls, 0) << "the check of the absorbing term saw no fall";
  }
}

TEST_F(TransitionTraining, SwitchQNetworkExportsAsAPolicy) {
  CompositeRecipe r = tiny();
  const Skill& b = r.skills[r.meta.transitions()[0].to];
  SwitchTrainer trainer(r.pipeline.switching, r, 0, collect_start_states(r, 0, 6, 1), b.policy, {}, 4);
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
// With switch.ensemble: K, q_ab is the members' mean: the exported network (one MLP, K
// times as wide) equals the average of the members' own LibTorch forwards.
TEST_F(TransitionTraining, SwitchEnsembleExportsTheMembersMean) {
  CompositeRecipe r = tiny({"switch.ensemble=3"});
  const Skill& b = r.skills[r.meta.transitions()[0].to];
  SwitchTrainer trainer(r.pipeline.switching, r, 0, collect_start_states(r, 0, 6, 1), b.policy, {}, 4);
  EXPECT_GT(trainer.run(24).loss, 0.0);
  ASSERT_EQ(trainer.networks().size(), 3u);
  Policy q = trainer.q_function(0.25);
  q.export_torchscript(path("q3.pt"));
  Policy back = Policy::load(path("q3.pt"));
  auto obs = random_obs(8, q.obs_dim(), 11);
  std::vector<float> in(size_t(8) * q.in_dim()), got(16), got_back(16);
  q.normalize(obs.data(), 8, in.data());
  q.act(obs.data(), 8, got.data());
  back.act(obs.data(), 8, got_back.data());
  torch::NoGradGuard no_grad;
  auto x = torch::from_blob(in.data(), {8, q.in_dim()});
  torch::Tensor mean = torch::zeros({8, 2});
  for (SwitchQNetwork net : trainer.networks()) mean += net->forward(x) / 3.0;  // holders share the member
  mean.select(1, 0) += 0.25;  // the margin, on Q(stay)
  SwitchQNetwork member = trainer.networks()[0];
  torch::Tensor first = member->forward(x);
  first.select(1, 0) += 0.25;
  double spread = 0;
  for (int n = 0; n < 8; ++n)
    for (int j = 0; j < 2; ++j) {
      EXPECT_NEAR(got[2 * n + j], mean[n][j].item<float>(), 1e-5) << n << "," << j;
      EXPECT_NEAR(got_back[2 * n + j], got[2 * n + j], 1e-5);
      spread += std::abs(first[n][j].item<float>() - mean[n][j].item<float>());
    }
  EXPECT_GT(spread, 1e-3) << "the members are not distinct networks";
  try {
    tiny({"switch.ensemble=0"});
    ADD_FAILURE() << "an empty ensemble was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("key 'switch.ensemble' must be in [1, 64], got 0"), std::string::npos) << e.what();
  }
}

TEST_F(TransitionTraining, SwitchTrainingResumesExactlyFromItsCheckpoint) {
  for (std::string ensemble : {"1", "3"}) {
  SCOPED_TRACE("ensemble " + ensemble);
  CompositeRecipe r = tiny({"switch.ensemble=" + ensemble});
  const Skill& b = r.skills[r.meta.transitions()[0].to];
  StartStates starts = collect_start_states(r, 0, 6, 1);
  auto make = [&] { return std::make_unique<SwitchTrainer>(r.pipeline.switching, r, 0, starts, b.policy,
                                                           std::vector<TransitionArtefacts>{}, 4); };
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
  // Another q_ab's checkpoint (other input width) is refused, naming the file.
  CompositeRecipe wide = tiny({"switch.fourier={inputs: [0], periods: [1]}"});
  SwitchTrainer other(wide.pipeline.switching, wide, 0, starts, b.policy, {}, 4);
  try {
    other.load(path("switch_checkpoint.pt"));
    ADD_FAILURE() << "a checkpoint of another width was loaded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("switch_checkpoint.pt: the checkpoint's q_ab input width differs"),
              std::string::npos)
        << e.what();
  }
  }
}

// switch.fourier: q_ab reads periodic features of chosen observations after its normalised
// input, as a policy does; the exported q_ab computes exactly that input (by hand here).
TEST_F(TransitionTraining, SwitchQNetworkReadsPeriodicFeatures) {
  CompositeRecipe r = tiny({"switch.fourier={inputs: [0, 3], periods: [0.5, 2]}"});
  const int D = r.spec.obs_dim;
  const Skill& b = r.skills[r.meta.transitions()[0].to];
  SwitchTrainer trainer(r.pipeline.switching, r, 0, collect_start_states(r, 0, 6, 1), b.policy, {}, 4);
  trainer.run(24);
  Policy q = trainer.q_function();
  ASSERT_EQ(q.features(), (ObsFeatures{{0, 3}, {0.5, 2}}));
  ASSERT_EQ(q.mlp().in_dim(), D + 8);
  auto obs = random_obs(5, D, 7);
  std::vector<float> got(10), back_got(10), in(D + 8), want(2);
  q.act(obs.data(), 5, got.data());
  const double kTwoPi = 6.283185307179586;
  for (int n = 0; n < 5; ++n) {
    const float* x = &obs[size_t(n) * D];
    for (int j = 0; j < D; ++j) in[j] = std::clamp((x[j] - q.obs_mean()[j]) * q.obs_inv_std()[j], -5.0f, 5.0f);
    int k = D;
    for (int i : {0, 3})
      for (double period : {0.5, 2.0}) {
        in[k++] = float(std::sin(kTwoPi * x[i] / period));
        in[k++] = float(std::cos(kTwoPi * x[i] / period));
      }
    q.mlp().forward(in.data(), 1, want.data());
    EXPECT_NEAR(got[2 * n], want[0], 1e-5);
    EXPECT_NEAR(got[2 * n + 1], want[1], 1e-5);
  }
  q.export_torchscript(path("qf.pt"));
  Policy back = Policy::load(path("qf.pt"));
  EXPECT_EQ(back.features(), q.features());
  back.act(obs.data(), 5, back_got.data());
  for (int i = 0; i < 10; ++i) EXPECT_NEAR(back_got[i], got[i], 1e-5);
}

// Both recipe keys for periodic features of the task's observation, q_ab's and D's, are
// read the same way and refuse an input past the observation, naming the key.
TEST_F(TransitionTraining, PeriodicFeatureKeysAreReadAgainstTheObservation) {
  const int D = tiny().spec.obs_dim;
  for (std::string key : {"switch.fourier", "transition.discriminator.fourier"}) {
    SCOPED_TRACE(key);
    CompositeRecipe r = tiny({key + "={inputs: [0, 3], periods: [0.5, 2]}"});
    const ObsFeatures& read =
        key == "switch.fourier" ? r.pipeline.switching.features : r.pipeline.transition.discriminator.features;
    EXPECT_EQ(read, (ObsFeatures{{0, 3}, {0.5, 2}}));
    try {
      tiny({key + "={inputs: [" + std::to_string(D) + "], periods: [1]}"});
      ADD_FAILURE() << "an input past the observation was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("key '" + key + ".inputs': must be observation indices in [0, " +
                                           std::to_string(D) + ")"),
                std::string::npos)
          << e.what();
    }
  }
}

// The switch margin is chosen on held-out S_a states: each margin's success rate equals a
// by-hand replay with the exported q_ab (margin folded into Q(stay)) from those states.
// With switch.fourier or switch.interval_features as well: the trainer's own input (its
// choice) and the exported q_ab's (the replay) must then agree on those inputs too.
TEST_F(TransitionTraining, SwitchMarginIsChosenOnHeldOutStarts) {
  for (std::string fourier :
       {"", "switch.fourier={inputs: [0, 3], periods: [0.5, 2]}", "switch.interval_features=true"}) {
    SCOPED_TRACE(fourier);
    std::vector<std::string> sets{"switch.validation_starts=4", "switch.margins=[10, -10, 0.05]"};
    if (!fourier.empty()) sets.push_back(fourier);
    CompositeRecipe r = tiny(sets);
    const Transition& tr = r.meta.transitions()[0];
    const Skill& b = r.skills[tr.to];
    StartStates starts = collect_start_states(r, 0, 10, 1);
    // The shipped pi_ab: balance itself falls from the walk's states, so every margin would fail.
    Policy pi_ab = Policy::load(repo_path("assets/policies/walker/patrol/forward-balance/policy.pt"));
    SwitchTrainer trainer(r.pipeline.switching, r, 0, starts, pi_ab, {}, 4);
    trainer.run(24);
    MarginChoice c = trainer.choose_margin();
    ASSERT_EQ(c.margins, (std::vector<double>{-10, 0.05, 10}));
    // -10 hands over at once (Without TP), 10 at the interval's end (With TP): these differ.
    EXPECT_LT(c.success.front(), c.success.back());
    auto env = r.make_env();
    TransitionController after(r.skills, r.meta, {}, SwitchRule::IntervalEnd);
    std::vector<float> obs(r.spec.obs_dim), act(r.spec.act_dim), q(2);
    std::vector<double> f(r.spec.feature_names.size()), state;
    const Policy plain = trainer.q_function();
    const int features = fourier == "switch.interval_features=true" ? int(f.size()) : 0;
    ASSERT_EQ(plain.obs_dim(), r.spec.obs_dim + features);
    const std::vector<float> x(plain.obs_dim(), 0.3f);
    for (size_t m = 0; m < c.margins.size(); ++m) {
      Policy q_ab = trainer.q_function(c.margins[m]);
      std::vector<float> q0(2);
      q_ab.act(x.data(), 1, q.data());
      plain.act(x.data(), 1, q0.data());
      EXPECT_NEAR(q[0] - q0[0], c.margins[m], 1e-4);
      EXPECT_EQ(q[1], q0[1]);
      int succeeded = 0;
      for (int i = 6; i < 10; ++i) {
        starts.state(i, state);
        env->restore_state(state, obs.data());
        env->features(f.data());
        bool fell = false;
        for (;;) {
          std::vector<float> in(obs);
          if (q_ab.obs_dim() > int(obs.size())) in.insert(in.end(), f.begin(), f.end());
          ASSERT_EQ(q_ab.obs_dim(), int(in.size()));
          q_ab.act(in.data(), 1, q.data());
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
    if (!fourier.empty()) continue;
    // (Once.) Holding out all of S_a leaves nothing to train on.
    CompositeRecipe all = tiny({"switch.validation_starts=10"});
    try {
      SwitchTrainer(all.pipeline.switching, all, 0, starts, b.policy, {}, 4);
      ADD_FAILURE() << "validation_starts = |S_a| was accepted";
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()),
                "switch training: validation_starts (10) leaves none of S_a's 10 states to train on");
    }
  }
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
    tp.reset(*env, obs.data());
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
    tpc.reset(*env, obs.data());
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
  tpq.reset(*e1, o1.data());
  without->reset(*e2, o2.data());
  for (int t = 0; t < 300; ++t) {
    tpq.act(*e1, o1.data(), a1.data());
    without->act(*e2, o2.data(), a2.data());
    ASSERT_EQ(a1, a2) << t;
    ASSERT_LT(tpq.transition(), 0);
    if (e1->step(a1.data(), o1.data()).done() | e2->step(a2.data(), o2.data()).done()) break;
  }
  // switch.interval_features: a q_ab wider than the observation reads the task's features
  // after it. This one, Q(stay) = 0.2 and Q(switch) = 0.01 since_turn, hands over at the
  // interval's first state with since_turn > 20, where With TP's pi_ab drove on.
  const int D = r.spec.obs_dim, F = int(f.size());
  ASSERT_EQ(r.spec.feature_names[1], "since_turn");
  ASSERT_GT(driven, 25) << "With TP's pi_ab must drive past since_turn 20 for this check";
  torch::Tensor w = torch::zeros({2, D + F});
  w[1][D + 1] = 1.0f;
  std::vector<float> inv_std(D + F, 1.0f);
  inv_std[D + 1] = 0.01f;
  art[0].q = Policy(EigenMlp({w}, {torch::tensor({0.2f, 0.0f})}, Activation::Relu), std::vector<float>(D + F, 0.0f),
                    inv_std, 5.0f, {-1e9f, -1e9f}, {1e9f, 1e9f});
  TransitionController by_time(r.skills, r.meta, art, SwitchRule::QNetwork);
  for (uint64_t seed = 0;; ++seed) {  // With TP's episode
    env->reset(seed, obs.data());
    by_time.reset(*env, obs.data());
    if (by_time.skill() == tr.from) break;
  }
  int handed_at = -1;
  bool begun = false;
  for (int t = 0; t < 300 && handed_at < 0; ++t) {
    by_time.act(*env, obs.data(), act.data());
    env->features(f.data());
    if (by_time.transition() >= 0) begun = true;
    else if (begun) handed_at = int(f[1]);
    if (env->step(act.data(), obs.data()).done()) break;
  }
  EXPECT_EQ(handed_at, 21);
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

// A resumed Lee stage keeps the proximity predictor's labelled states (T_b's and every
// finished episode's), not only its weights.
TEST_F(TransitionTraining, LeeCheckpointKeepsThePredictorsLabelledStates) {
  CompositeRecipe r = tiny();
  const Skill& b = r.skills[r.meta.transitions()[0].to];
  StartStates starts = collect_start_states(r, 0, 6, 1);
  Demonstrations expert = collect_demonstrations(r, 0, 300, 2);
  auto envs = [&] {
    return std::make_unique<VectorEnv>([&] { return std::make_unique<LeeTransitionEnv>(r, 0, starts, 500); },
                                       r.pipeline.transition.ppo.num_envs, 1);
  };
  auto first_envs = envs();
  LeeTrainer first(r.pipeline.transition, r.pipeline.lee, *first_envs, expert, b.policy, 5);
  EXPECT_EQ(first.positives_seen(), expert.size());
  EXPECT_EQ(first.negatives_seen(), 0);
  first.iterate(), first.iterate();
  ASSERT_GT(first.positives_seen() + first.negatives_seen(), expert.size()) << "no episode was labelled";
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
    VectorEnv envs([&] { return std::make_unique<LeeTransitionEnv>(r, 0, starts, 500); }, 2, 1);
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
  LeeTransitionEnv env(r, 0, starts, 500);
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

TEST_F(TransitionTraining, ATransitionsOwnStartStatesOverrideTheCollectSize) {
  EXPECT_EQ(tiny().start_state_count(0), 12);  // collect.start_states
  EXPECT_EQ(tiny({"transitions.0.start_states=5"}).start_state_count(0), 5);
  try {
    tiny({"transitions.0.start_states=0"});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("key 'transitions.0.start_states' must be > 0, got 0"), std::string::npos)
        << e.what();
  }
}

// S_a or T_b copied in from another task's run is refused, naming the file.
TEST_F(TransitionTraining, PipelineRefusesStartStatesAndDemonstrationsOfAnotherTransitionOrWidth) {
  CompositeRecipe r = tiny();
  PipelineOptions o;
  o.command = "test";
  const std::string t = path("run/forward-balance/");
  fs::create_directories(t);
  StartStates s = collect_start_states(r, 0, r.pipeline.collect.start_states, 1);
  Demonstrations d = collect_demonstrations(r, 0, 50, 2);
  StartStates narrow = s;
  narrow.obs_dim = s.obs_dim - 1;
  narrow.obs.resize(size_t(narrow.size()) * narrow.obs_dim);
  save(narrow, t + "start_states.pt");
  save(d, t + "demonstrations.pt");
  auto message = [&] {
    try {
      run_pipeline(r, o);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(), t + "start_states.pt: S_a of observations " + std::to_string(s.obs_dim - 1) +
                           " wide, but task 'patrol' has " + std::to_string(s.obs_dim));
  save(s, t + "start_states.pt");
  Demonstrations wide = d;
  wide.act_dim = d.act_dim + 1;
  wide.act.resize(size_t(wide.size()) * wide.act_dim);
  save(wide, t + "demonstrations.pt");
  EXPECT_NE(message().find(t + "demonstrations.pt: T_b of (s, a) "), std::string::npos) << message();
  std::ofstream(t + "demonstrations.pt") << "garbage";
  EXPECT_EQ(message().rfind(t + "demonstrations.pt: not a file of demonstrations (T_b) (", 0), 0u) << message();
  // Files of the right widths collected for another transition (copied between folders).
  ASSERT_EQ(s.source, "patrol forward-balance");
  ASSERT_EQ(r.transition_source(0), s.source);
  ASSERT_EQ(d.source, s.source);
  save(d, t + "demonstrations.pt");
  // Saves `data` relabelled as collected for `source` in place of `file`, expects the run
  // refused, and puts the right file back.
  auto refused = [&](auto data, const std::string& file, const std::string& what, const std::string& source) {
    const auto right = data;
    data.source = source;
    save(data, t + file);
    EXPECT_EQ(message(), t + file + ": " + what + " collected for '" + source +
                             "', but this folder is 'patrol forward-balance'");
    save(right, t + file);
  };
  refused(s, "start_states.pt", "S_a", "patrol backward-balance");
  refused(d, "demonstrations.pt", "T_b", "hurdle walk-jump");
}

TEST_F(TransitionTraining, PipelineWritesEveryArtefactAndResumes) {
  CompositeRecipe r = tiny();
  PipelineOptions o;
  o.command = "test";
  // Stopped at once: the collection keeps nothing and the run returns the signal.
  std::atomic<int> stop{15};
  o.stop = &stop;
  EXPECT_EQ(run_pipeline(r, o), 15);
  const std::string t = path("run/forward-balance/");
  EXPECT_FALSE(fs::exists(t + "start_states.pt"));
  // With S_a and T_b in place, the transition stage checkpoints after one iteration.
  save(collect_start_states(r, 0, r.pipeline.collect.start_states, 1), t + "start_states.pt");
  save(collect_demonstrations(r, 0, r.pipeline.collect.demonstrations, 2), t + "demonstrations.pt");
  EXPECT_EQ(run_pipeline(r, o), 15);
  EXPECT_TRUE(fs::exists(t + "transition_checkpoint.pt"));
  EXPECT_FALSE(fs::exists(t + "policy.pt"));
  // Each rerun while stopped goes one iteration on; the one that finishes pi_ab goes on
  // to the switch stage, which checkpoints after its first report (a tenth of the attempts).
  for (int run = 0; run < 10 && !fs::exists(t + "policy.pt"); ++run) EXPECT_EQ(run_pipeline(r, o), 15);
  ASSERT_TRUE(fs::exists(t + "policy.pt"));
  EXPECT_TRUE(fs::exists(t + "switch_checkpoint.pt"));
  EXPECT_FALSE(fs::exists(t + "q.pt"));
  auto lines_of = [](const std::string& file) {
    std::ifstream in(file);
    int n = 0;
    for (std::string line; std::getline(in, line);) ++n;
    return n;
  };
  EXPECT_EQ(lines_of(t + "switch.csv"), 1 + 1);
  // The stage resumes from the checkpoint it finds: one written after 20 attempts leaves
  // 4 to run (2 reports after the stopped run's one).
  {
    SwitchTrainer later(r.pipeline.switching, r, 0, load_start_states(t + "start_states.pt"),
                        Policy::load(t + "policy.pt"), {}, 4);
    later.run(20);
    later.save(t + "switch_checkpoint.pt");
  }
  // Resumed: every stage finishes, each iteration logged once.
  stop = 0;
  EXPECT_EQ(run_pipeline(r, o), 0);
  for (const char* f : {"start_states.pt", "demonstrations.pt", "policy.pt", "q.pt", "lee.pt", "transition.csv",
                        "switch.csv", "lee.csv", "actions.csv"})
    EXPECT_TRUE(fs::exists(t + f)) << f;
  EXPECT_EQ(lines_of(t + "transition.csv"), 1 + 4);  // header + 2048 / (4 x 128) iterations
  EXPECT_EQ(lines_of(t + "switch.csv"), 1 + 1 + 2);
  EXPECT_FALSE(fs::exists(t + "switch_checkpoint.pt")) << "kept after q.pt was written";
  std::ifstream json(path("run/patrol.json"));
  std::string text((std::istreambuf_iterator<char>(json)), {});
  for (const char* m : {"\"without-tp\"", "\"tp\"", "\"tp+q\"", "\"lee\""}) EXPECT_NE(text.find(m), std::string::npos) << m;
  // A finished run skips every stage: their outputs are left as they were.
  std::vector<std::string> outputs{t + "policy.pt", t + "q.pt", t + "lee.pt", t + "actions.csv", path("run/patrol.json")};
  std::vector<fs::file_time_type> before;
  for (const auto& f : outputs) before.push_back(fs::last_write_time(f));
  EXPECT_EQ(run_pipeline(r, o), 0);
  for (size_t i = 0; i < outputs.size(); ++i) EXPECT_EQ(fs::last_write_time(outputs[i]), before[i]) << outputs[i];
  // Each exported file says what it is for, and one made for another transition is refused.
  for (const char* f : {"policy.pt", "q.pt", "lee.pt"})
    EXPECT_EQ(Policy::load(t + f).source(), std::string("patrol forward-balance ") + f);
  Policy other = Policy::load(t + "policy.pt");
  other.set_source("patrol backward-balance policy.pt");
  other.export_torchscript(t + "policy.pt");
  try {
    load_transition_artefacts(r, path("run"), "policy.pt", /*with_q=*/true);
    ADD_FAILURE() << "a policy.pt made for another transition was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), t + "policy.pt: made for 'patrol backward-balance policy.pt', but this is "
                                         "'patrol forward-balance policy.pt'");
  }
}

// The transition stage and Lee's, stopped after every iteration and resumed, write the rows
// and the policies of the unbroken run: their checkpoints carry the episodes in flight
// (TransitionEnv and LeeTransitionEnv save theirs), not only the networks.
TEST_F(TransitionTraining, StoppedPpoStagesResumeToTheUnbrokenRun) {
  tiny();  // writes the recipe file
  auto prepared = [&](const std::string& run) {
    CompositeRecipe r = CompositeRecipe::load(path("tiny_patrol.yaml"), {"lee.enabled=true", "run_dir=" + path(run)});
    const std::string t = path(run + "/forward-balance/");
    fs::create_directories(t);
    save(collect_start_states(r, 0, r.pipeline.collect.start_states, 1), t + "start_states.pt");
    save(collect_demonstrations(r, 0, r.pipeline.collect.demonstrations, 2), t + "demonstrations.pt");
    return r;
  };
  PipelineOptions o;
  o.command = "test";
  const CompositeRecipe unbroken = prepared("unbroken");
  ASSERT_EQ(run_pipeline(unbroken, o), 0);
  const CompositeRecipe stopped = prepared("stopped");
  std::atomic<int> stop{15};
  o.stop = &stop;
  const std::string t = path("stopped/forward-balance/"), u = path("unbroken/forward-balance/");
  for (int run = 0; run < 60 && !fs::exists(t + "lee.pt"); ++run) {
    const int rc = run_pipeline(stopped, o);  // stopped, but for the run that finishes the last stage
    EXPECT_TRUE(rc == 15 || fs::exists(t + "lee.pt")) << rc;
  }
  ASSERT_TRUE(fs::exists(t + "lee.pt"));
  auto rows = [](const std::string& file) {
    std::ifstream in(file);
    std::vector<std::string> out;
    for (std::string line; std::getline(in, line);) out.push_back(line.substr(0, line.rfind(',')));  // less wall_seconds
    return out;
  };
  for (const char* csv : {"transition.csv", "lee.csv"}) {
    ASSERT_EQ(rows(t + csv).size(), 1u + 2048 / 512) << csv;
    EXPECT_EQ(rows(t + csv), rows(u + csv)) << csv;
  }
  const std::vector<float> obs = random_obs(8, unbroken.skills[2].policy.obs_dim(), 4);
  for (const char* f : {"policy.pt", "lee.pt"}) {
    Policy a = Policy::load(t + f), b = Policy::load(u + f);
    std::vector<float> ya(8 * a.act_dim()), yb(8 * b.act_dim());
    a.act(obs.data(), 8, ya.data());
    b.act(obs.data(), 8, yb.data());
    EXPECT_EQ(ya, yb) << f;
  }
}

// Lee's policy trains with pi_ab's settings, but for its own budget when lee.total_steps
// is given: here 1024 steps (two iterations of 4 x 128) against pi_ab's 2048 (four).
TEST_F(TransitionTraining, LeeTrainsForItsOwnBudgetWhenGiven) {
  tiny();  // writes the recipe file
  CompositeRecipe r = CompositeRecipe::load(path("tiny_patrol.yaml"),
                                            {"lee.enabled=true", "lee.total_steps=1024", "run_dir=" + path("run")});
  EXPECT_EQ(r.pipeline.lee.transition(r.pipeline.transition).ppo.total_steps, 1024);
  EXPECT_EQ(r.pipeline.lee.transition(r.pipeline.transition).ppo.gamma, r.pipeline.transition.ppo.gamma);
  const std::string t = path("run/forward-balance/");
  fs::create_directories(t);
  save(collect_start_states(r, 0, r.pipeline.collect.start_states, 1), t + "start_states.pt");
  save(collect_demonstrations(r, 0, r.pipeline.collect.demonstrations, 2), t + "demonstrations.pt");
  PipelineOptions o;
  o.command = "test";
  ASSERT_EQ(run_pipeline(r, o), 0);
  auto steps = [](const std::string& file) {  // iterations, and the last row's global_step
    const auto rows = csv(file);
    return std::make_pair(int(rows.size()) - 1, std::stod(rows.back()[1]));
  };
  EXPECT_EQ(steps(t + "transition.csv"), std::make_pair(4, 2048.0));
  EXPECT_EQ(steps(t + "lee.csv"), std::make_pair(2, 1024.0));
}

}  // namespace segue
