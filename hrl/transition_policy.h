#pragma once
// Algorithm 1: a transition policy pi_ab trained with AIRL. Each iteration
//   1. pi_ab (the generator) runs episodes that start from states of S_a (TransitionEnv),
//   2. the discriminator D learns by logistic regression to tell pi_b's own transitions
//      T_b (label 1) from the generator's (label 0),
//   3. every generator step is rewarded with Eq. 3, log D - log(1 - D) = f - log pi_ab,
//   4. PPO updates pi_ab on those rewards.
// Steps 2-3 run inside PPO's reward hook, between the rollout and the advantages.
#include <memory>
#include <string>

#include "algorithms/discriminator.h"
#include "algorithms/ppo.h"
#include "hrl/collection.h"
#include "hrl/pipeline_config.h"

namespace segue {

struct TransitionIterationStats {
  IterationStats ppo;
  double disc_loss = 0, expert_accuracy = 0, generator_accuracy = 0;  // D on its training batches
  double airl_reward = 0;                                               // mean Eq. 3 reward
};

class TransitionPolicyTrainer {
 public:
  // `envs` are TransitionEnvs; `expert` is T_b in pi_b's observation slice; `next` is pi_b
  // (used to initialise pi_ab when config.init_from_next). With `group`, PPO is
  // data-parallel (ppo.h) and D learns from every rank's generator rows: each rank draws
  // its own minibatch of generator and expert rows, and D's gradients are averaged.
  TransitionPolicyTrainer(const TransitionPolicyConfig& config, VectorEnv& envs, Demonstrations expert,
                          const Policy& next, uint64_t seed, const Distributed& group = Distributed::alone());

  TransitionIterationStats iterate();
  Policy policy() const { return ppo_.policy(); }
  const PPO& ppo() const { return ppo_; }
  Discriminator& discriminator() { return disc_; }

  // One file: generator, discriminator and both optimisers.
  void save(const std::string& path, const std::string& note) const;
  void load(const std::string& path);

 private:
  // PPO's reward hook: train D on this rollout against T_b, then write Eq. 3 rewards.
  void discriminate(RolloutBuffer& buf);

  TransitionPolicyConfig cfg_;
  PPO ppo_;
  Demonstrations expert_;
  Discriminator disc_{nullptr};
  std::unique_ptr<torch::optim::Adam> disc_opt_;
  torch::Tensor expert_obs_, expert_act_, expert_next_, expert_done_;
  std::vector<float> act_low_, act_high_;
  TransitionIterationStats last_;
};

}  // namespace segue
