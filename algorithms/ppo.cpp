#include "algorithms/ppo.h"

#include <algorithm>
#include <cmath>

#include "algorithms/optimizer_step.h"
#include "algorithms/ppo_loss.h"
#include "core/error.h"

namespace segue {

PpoConfig PpoConfig::read(const Section& s, PpoConfig c) {
  c.read_rollout(s);
  c.epochs = s.get("epochs", c.epochs, Range::positive());
  c.minibatch_size = s.get("minibatch_size", c.minibatch_size, Range::positive());
  c.lr = s.get("lr", c.lr, Range::positive());
  c.anneal_lr = s.get("anneal_lr", c.anneal_lr);
  c.clip = s.get("clip", c.clip, Range::positive());
  c.vf_coef = s.get("vf_coef", c.vf_coef, Range::non_negative());
  c.ent_coef = s.get("ent_coef", c.ent_coef, Range::non_negative());
  c.bound_coef = s.get("bound_coef", c.bound_coef, Range::non_negative());
  c.max_grad_norm = s.get("max_grad_norm", c.max_grad_norm, Range::positive());
  if (c.minibatch_size > int64_t(c.num_envs) * c.steps_per_env)
    throw s.error("minibatch_size", std::to_string(c.minibatch_size) + " is larger than a rollout (num_envs x steps_per_env = " +
                                        std::to_string(int64_t(c.num_envs) * c.steps_per_env) + ")");
  return c;
}

PPO::PPO(const PpoConfig& config, const ActorCriticSpec& net, VectorEnv& envs, uint64_t seed,
         const Distributed& group)
    : OnPolicyLearner("ppo", config, net, envs, seed, group), cfg_(config),
      actor_(net_->actor, net.activation), critic_(net_->critic, net.activation) {
  optimizer_ = std::make_unique<torch::optim::Adam>(net_->parameters(), torch::optim::AdamOptions(cfg_.lr).eps(1e-5));
}

double PPO::learning_rate() const {
  return static_cast<const torch::optim::AdamOptions&>(optimizer_->param_groups().front().options()).lr();
}

void PPO::update(IterationStats& stats) {
  if (cfg_.anneal_lr) {
    const double span = double(total_iterations() - schedule_start_);
    double frac = span > 0 ? 1.0 - double(iteration_ - schedule_start_) / span : 0.0;
    for (auto& group : optimizer_->param_groups())
      static_cast<torch::optim::AdamOptions&>(group.options()).lr(cfg_.lr * std::max(frac, 0.0));
  }
  const auto& spec = envs_.spec();
  const int k = buf_.act_dim;
  const PpoCoefficients coefficients{cfg_.clip, cfg_.vf_coef, cfg_.ent_coef, cfg_.bound_coef};
  const std::vector<torch::Tensor> params = net_->parameters();
  torch::Tensor log_std = net_->log_std;
  const RolloutBuffer& rollout = whole_rollout();
  // Every run draws the same permutations, whatever a reward hook drew before.
  torch::manual_seed(mix_seed(seed_, 2 * iteration_ + 2) ^ 0x9e3779b9ULL);
  int batches = 0;
  double sums[4] = {0, 0, 0, 0};  // policy, value, approx_kl, clip_fraction
  if (group_.leader())
    for (int epoch = 0; epoch < cfg_.epochs; ++epoch)
      for (const torch::Tensor& minibatch : shuffled_minibatches(cfg_.minibatch_size)) {
        const int n = int(minibatch.numel());
        gather(rollout, minibatch.data_ptr<int64_t>(), n);
        // The actor's and the critic's passes share nothing: side by side where they can.
        const MlpBackprop::RowMatrix *mu = nullptr, *value = nullptr;
        run_both([&] { mu = &actor_.forward(mb_.obs.data(), n); },
                 [&] { value = &critic_.forward(mb_.obs.data(), n); });
        dmu_.resize(n, k), dvalue_.resize(n, 1);
        const PpoMinibatch batch{n, k, mu->data(), value->data(), mb_.actions.data(), mb_.old_log_prob.data(),
                                 mb_.advantage.data(), mb_.returns.data(), log_std.data_ptr<float>(),
                                 spec.act_low.data(), spec.act_high.data()};
        if (!log_std.grad().defined()) log_std.mutable_grad() = torch::zeros_like(log_std);
        const PpoGradient gradient{dmu_.data(), dvalue_.data(), log_std.mutable_grad().data_ptr<float>()};
        const PpoLossTerms loss = ppo_loss(batch, coefficients, &gradient);
        if (!std::isfinite(loss.total))
          throw Error("PPO loss became " + std::to_string(loss.total) + " at iteration " +
                      std::to_string(iteration_ + 1) + " (task '" + envs_.spec().name +
                      "'); the last checkpoint is kept: lower ppo.lr or check the task's rewards");
        run_both([&] { actor_.backward(dmu_); }, [&] { critic_.backward(dvalue_); });
        clip_grad_norm(params, cfg_.max_grad_norm);
        adam_step(*optimizer_);
        if (cfg_.min_log_std > -20.0) {
          torch::NoGradGuard no_grad;
          log_std.clamp_min_(cfg_.min_log_std);
        }
        sums[0] += loss.policy, sums[1] += loss.value, sums[2] += loss.approx_kl, sums[3] += loss.clip_fraction;
        ++batches;
      }
  for (double& sum : sums) sum /= std::max(batches, 1);
  share_leader_update(params, sums, 4);
  stats.policy_loss = sums[0];
  stats.value_loss = sums[1];
  stats.approx_kl = sums[2];
  stats.clip_fraction = sums[3];
  stats.entropy = net_->entropy().item<double>();
}

void PPO::gather(const RolloutBuffer& rollout, const int64_t* rows, int n) {
  gather_rows(rollout.obs, rollout.in_dim, rows, n, mb_.obs);
  gather_rows(rollout.actions, rollout.act_dim, rows, n, mb_.actions);
  gather_rows(rollout.log_probs, 1, rows, n, mb_.old_log_prob);
  gather_rows(rollout.returns, 1, rows, n, mb_.returns);
  standardized_advantages(rollout.advantages, rows, n, mb_.advantage);  // over the minibatch
}

}  // namespace segue
