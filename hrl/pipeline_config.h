#pragma once
// The settings of `segue run`'s stages, read from a composite recipe (every key has a
// default: where docs/reference/learners.md records one, the paper's text or its code's):
//
//   run_dir: runs/hurdle
//   seed: 1
//   threads: 0
//   collect: {start_states: 1000, demonstrations: 100000}     # |S_a|, |T_b| per transition
//   transition: {ppo: {...}, policy: {...}, init_from_next: true,
//                discriminator: {hidden: [100, 100], lr: 3.0e-4, batch: 256, steps: 16}}
//   switch: {attempts: 2000, lr: 1.0e-4, ...}
#include <string>
#include <vector>

#include "algorithms/discriminator.h"
#include "algorithms/ppo.h"
#include "algorithms/switch_q_network.h"
#include "core/recipe.h"

namespace segue {

struct CollectConfig {
  int start_states = 1000;      // S_a per transition (reference 10,000)
  int demonstrations = 100000;  // T_b rows per transition (reference 1,000,000)
  static CollectConfig read(const Section& s);
};

struct TransitionPolicyConfig {
  PpoConfig ppo;                 // the generator's PPO
  ActorCriticSpec net;           // 2 x 32 tanh, as the skills (the paper's text)
  bool init_from_next = true;    // start pi_ab as a copy of pi_b (false: random, as the paper)
  // The generator's reward from D.
  //   "airl": Eq. 3, log D - log(1 - D) = f - log pi.
  //   "airl_absorbing": Eq. 3, and a fall leads to an absorbing state that keeps paying
  //       the rollout's worst Eq. 3 reward for ever: gamma min(r) / (1 - gamma) at the fall.
  //   "airl_nonnegative": -log(1 - D) = softplus(Eq. 3).
  // Eq. 3 is negative wherever D is confident, so a generator whose episodes can end by
  // falling is paid to fall early (the survival bias of adversarial imitation; Kostrikov
  // et al. 2019 fix it with absorbing states). Transition episodes start far from pi_b's
  // states and fall often, so this matters here. softplus removes the bias but flattens
  // the reward to ~0 once D is confident, which it is at first.
  std::string reward = "airl_absorbing";
  DiscriminatorSpec discriminator;
  double disc_lr = 3e-4;         // Adam (paper and code)
  int disc_batch = 256;          // expert and generator rows per discriminator step, each
  int disc_steps = 16;           // discriminator steps per PPO iteration

  // Reads the recipe's `transition:` section (every key has a default).
  static TransitionPolicyConfig read(const Section& s);
  // pi_ab's network on its environment: sized to it and, when pi_ab starts as pi_b
  // (init_from_next), with pi_b's periodic input features, so it can start as exactly pi_b.
  ActorCriticSpec network(const EnvSpec& env, const Policy& next) const;
};

// Network and learning as the reference's (docs/reference/learners.md#switch-network).
struct SwitchConfig {
  SwitchQSpec net;               // 2 x 128 ReLU
  double lr = 1e-4;              // Adam
  int batch = 64;                // minibatch
  int replay = 1'000'000;        // replay capacity
  int target_every = 500;        // updates between hard target copies
  double r_success = 1.0, r_fail = -1.0;
  int attempts = 2000;           // transition attempts (episodes of Alg. 2)
  int updates_per_attempt = 8;
  int warmup = 500;              // stored transitions before the first update
  // Epsilon is drawn once per attempt; a random attempt switches at a uniform point of
  // the interval (reference). It decays linearly to epsilon_end over explore_fraction.
  double epsilon_start = 1.0, epsilon_end = 0.1, explore_fraction = 0.5;
  double epsilon(int attempt) const;  // before attempt `attempt` (0-based)
  int max_subtask_steps = 3000;  // pi_b's run is cut (and counted a success) after this
  // How many transition intervals must begin after a hand-over for it to count as r_s
  // (run_subtask): 1 is the paper's (pi_b reaches its own end); 2 also asks that the
  // episode, carried on With TP, gets through the next skill.
  int lookahead = 1;
  // The switch margin m: q_ab switches where Q(switch) > Q(stay) + m (the paper: m = 0).
  // With validation_starts > 0, the last that many states of S_a are held out of training
  // and m is the one of `margins` whose hand-overs succeed most often from them (ties: the
  // larger m). A large m (2 > r_s - r_f) never switches before the interval's end: With TP.
  // Where pi_ab already hands over near the best point, a learnt q_ab's estimation noise
  // makes it switch early for nothing; the held-out check keeps that from costing.
  int validation_starts = 0;
  std::vector<double> margins{0.0, 0.25, 0.5, 1.0, 2.0};

  static SwitchConfig read(const Section& s);
};

// Lee et al. 2019's transition policy: the generator's PPO and network are `transition:`'s;
// these are its proximity predictor's and termination head's settings.
struct LeeConfig {
  bool enabled = true;         // train the baseline in `segue run`
  std::vector<int> hidden{96, 96};  // P: 2 x 96 ReLU, the reference's
  double lr = 3e-4;            // Adam, least squares
  int batch = 64;
  int steps = 32;              // predictor steps per PPO iteration
  double decay = 0.95;         // label 0.95^k, k steps before a successful hand-over
  int max_rows = 200000;       // labelled states kept per class (a ring)
  float termination_bias = -1.0f;  // initial termination output (mean): rarely at first
  int max_steps = 100;         // pi_ab hands over after at most this many steps (Lee et al.'s; 0: the interval only)
  // Lee's policy trains with pi_ab's `transition:` settings (network, PPO, start); only its
  // budget may differ: 0 takes transition.ppo.total_steps.
  int64_t total_steps = 0;
  static LeeConfig read(const Section& s);
  // pi_ab's settings with Lee's budget.
  TransitionPolicyConfig transition(const TransitionPolicyConfig& tp) const;
};

struct PipelineConfig {
  std::string run_dir;
  uint64_t seed = 1;
  int threads = 0;
  CollectConfig collect;
  TransitionPolicyConfig transition;
  SwitchConfig switching;
  LeeConfig lee;
  static PipelineConfig read(const Section& root, const std::string& task);
};

}  // namespace segue
