#pragma once
// Soft Actor-Critic (Haarnoja et al. 2018, "SAC: Algorithms and Applications"): off-policy,
// maximum entropy. A tanh-squashed Gaussian actor, twin Q networks with Polyak-averaged
// targets, and an entropy temperature alpha tuned so the policy's entropy tracks a target
// (-|A|). Each iteration steps the environments steps_per_iteration times in all, making
// one gradient update per environment step in rounds of update_every:
//   y      = r + gamma (1 - terminal) (min_i Q'_i(s', a') - alpha log pi(a'|s')),  a' ~ pi(.|s')
//   L_Q    = sum_i mean (Q_i(s, a) - y)^2
//   L_pi   = mean (alpha log pi(a~|s) - min_i Q_i(s, a~)),  a~ ~ pi(.|s) (reparameterised)
//   L_alpha = -mean log(alpha) (log pi(a~|s) + target_entropy)
// The first start_steps steps take uniform random actions. Runs on one process: the
// updates are sequential in the data, so ranks would not share them.
#include <torch/torch.h>

#include <string>
#include <vector>

#include "algorithms/actor_critic.h"
#include "algorithms/learner.h"
#include "algorithms/replay_buffer.h"
#include "core/recipe.h"
#include "core/rng.h"
#include "core/vector_env.h"

namespace segue {

struct SacConfig {
  int64_t total_steps = 1'000'000;
  int num_envs = 1;
  int steps_per_iteration = 1000;  // environment steps in all per iteration (a metrics row)
  int update_every = 50;           // steps between rounds of as many updates
  int64_t start_steps = 10'000;    // uniform random actions first
  int64_t update_after = 1'000;    // no update before this many steps are stored
  int64_t buffer_size = 1'000'000;
  int batch_size = 256;
  double gamma = 0.99;
  double tau = 0.005;              // target <- tau Q + (1 - tau) target after each update
  double lr = 3e-4;                // Adam, for the actor, the critics and alpha
  double init_alpha = 0.2;
  bool tune_alpha = true;          // false: alpha stays init_alpha (the reference's fixed 0.2)

  static SacConfig read(const Section& s);
};

// The soft Bellman target y = r + gamma (1 - terminal) (min(q1', q2') - alpha logp'),
// row by row; each argument is [B].
torch::Tensor soft_q_target(const torch::Tensor& reward, const torch::Tensor& terminal, const torch::Tensor& q1_next,
                            const torch::Tensor& q2_next, const torch::Tensor& logp_next, double alpha, double gamma);

class SAC : public Learner {
 public:
  // `net`: the actor's and the critics' hidden layers (pi_hidden, vf_hidden), activation
  // and ignored inputs (ignore_obs: fed as 0).
  SAC(const SacConfig& config, const ActorCriticSpec& net, VectorEnv& envs, uint64_t seed);

  const std::string& name() const override { return name_; }
  IterationStats iterate() override;
  std::vector<std::string> update_columns() const override {
    return {"policy_loss", "value_loss", "entropy", "alpha", "q_mean"};
  }
  std::vector<double> update_values(const IterationStats& s) const override {
    return {s.policy_loss, s.value_loss, s.entropy, s.alpha, s.q_mean};
  }
  Policy policy() const override;
  int64_t iteration() const override { return iteration_; }
  int64_t global_step() const override { return global_step_; }
  double wall_seconds() const override { return wall_seconds_; }
  // The checkpoint holds the networks, the targets, alpha, the three optimisers, the whole
  // replay buffer (so it grows with it: 4 bytes x (2 obs + act + 2) per stored step), the
  // counters and the episodes in flight.
  void save(const std::string& path, const std::string& note) const override;
  void load_checkpoint(const std::string& path, bool resume) override;
  // The deterministic policy of a checkpoint already read (`path` names it in errors).
  static Policy policy_from_checkpoint(torch::serialize::InputArchive& ar, const std::string& path);

  // One gradient update on a batch (public for tests): returns Q loss, policy loss,
  // entropy estimate and mean Q.
  struct UpdateStats {
    double q_loss, pi_loss, entropy, q_mean;
  };
  UpdateStats update(const ReplayBuffer::Batch& batch);
  double alpha() const { return std::exp(log_alpha_.item<double>()); }
  ReplayBuffer& replay() { return replay_; }
  double target_entropy() const { return target_entropy_; }

 private:
  // a = tanh(u), u ~ N(mu, sigma): the action in [-1, 1]^A and log pi(a|s).
  std::pair<torch::Tensor, torch::Tensor> sample(const torch::Tensor& obs);
  torch::Tensor q(torch::nn::Sequential& net, const torch::Tensor& obs, const torch::Tensor& act);
  void collect(int steps_per_env);  // steps every environment, storing each transition
  void masked(const float* raw, float* out) const;  // the networks' input: ignored inputs 0
  void refresh_inference_copy();
  void write(torch::serialize::OutputArchive& ar) const;

  std::string name_ = "sac";
  SacConfig cfg_;
  ActorCriticSpec spec_;
  VectorEnv& envs_;
  uint64_t seed_;
  torch::nn::Sequential actor_{nullptr}, q1_{nullptr}, q2_{nullptr}, q1_target_{nullptr}, q2_target_{nullptr};
  torch::Tensor log_alpha_;
  std::unique_ptr<torch::optim::Adam> actor_opt_, q_opt_, alpha_opt_;
  double target_entropy_;
  ReplayBuffer replay_;
  EigenMlp actor_copy_;
  std::vector<float> input_, next_input_, head_, actions_unit_, actions_env_;
  std::vector<Rng> env_rng_;  // exploration noise, one stream per environment
  std::vector<uint8_t> ignored_;
  int64_t iteration_ = 0, global_step_ = 0;
  double wall_seconds_ = 0.0;
};

}  // namespace segue
