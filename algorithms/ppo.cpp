#include "algorithms/ppo.h"

#include <cmath>

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
    : OnPolicyLearner("ppo", config, net, envs, seed, group), cfg_(config) {
  optimizer_ = std::make_unique<torch::optim::Adam>(net_->parameters(),
                                                     torch::optim::AdamOptions(cfg_.lr).eps(1e-5));
}

double PPO::learning_rate() const {
  return static_cast<const torch::optim::AdamOptions&>(optimizer_->param_groups().front().options()).lr();
}

void PPO::update(IterationStats& stats) {
  const int64_t T = buf_.T, N = buf_.N;
  if (cfg_.anneal_lr) {
    const double span = double(total_iterations() - schedule_start_);
    double frac = span > 0 ? 1.0 - double(iteration_ - schedule_start_) / span : 0.0;
    for (auto& group : optimizer_->param_groups())
      static_cast<torch::optim::AdamOptions&>(group.options()).lr(cfg_.lr * std::max(frac, 0.0));
  }
  auto obs = torch::from_blob(buf_.obs.data(), {T * N, buf_.in_dim});
  auto act = torch::from_blob(buf_.actions.data(), {T * N, buf_.act_dim});
  auto old_logp = torch::from_blob(buf_.log_probs.data(), {T * N});
  auto adv = torch::from_blob(buf_.advantages.data(), {T * N});
  auto ret = torch::from_blob(buf_.returns.data(), {T * N});
  const auto& spec = envs_.spec();
  auto low = torch::tensor(spec.act_low), high = torch::tensor(spec.act_high);
  // Every rank draws the same permutations, whatever a reward hook drew before.
  torch::manual_seed(mix_seed(seed_, 2 * iteration_ + 2) ^ 0x9e3779b9ULL);
  int batches = 0;
  double sums[4] = {0, 0, 0, 0};  // policy, value, approx_kl, clip_fraction, weighted by rows
  std::vector<torch::Tensor> advs;  // A at this rank's rows of each minibatch of an epoch
  std::vector<double> moments;      // each minibatch's sum and sum of squares of A, every rank's
  for (int epoch = 0; epoch < cfg_.epochs; ++epoch) {
    const std::vector<Minibatch> minibatch = shuffled_minibatches(cfg_.minibatch_size);
    advs.clear(), moments.clear();
    for (const Minibatch& m : minibatch) {
      auto a = adv.index_select(0, m.rows).to(torch::kFloat64);
      moments.push_back(a.sum().item<double>());
      moments.push_back(a.pow(2).sum().item<double>());
      advs.push_back(a);
    }
    // Advantages are normalised over each whole minibatch, every rank's rows: one
    // exchange per epoch.
    group_.sum(moments.data(), moments.size());
    for (size_t j = 0; j < minibatch.size(); ++j) {
      const torch::Tensor& idx = minibatch[j].rows;
      const double n = minibatch[j].global_rows, mean = moments[2 * j] / n;
      const double std = std::sqrt(std::max(moments[2 * j + 1] - n * mean * mean, 0.0) / std::max(n - 1.0, 1.0));
      const double share = double(idx.numel()) / n;  // this rank's part of the minibatch
      const torch::Tensor& a = advs[j];
      optimizer_->zero_grad();
      double local = 0.0;
      if (idx.numel() > 0) {
        auto o = obs.index_select(0, idx);
        auto an = ((a - mean) / (std + 1e-8)).to(torch::kFloat32);
        auto mean_action = net_->mean(o);
        auto logp = net_->log_prob(mean_action, act.index_select(0, idx));
        auto value = net_->value(o);
        PpoLoss loss = ppo_loss(logp, old_logp.index_select(0, idx), an, value, ret.index_select(0, idx),
                                net_->entropy(), cfg_.clip, cfg_.vf_coef, cfg_.ent_coef);
        if (cfg_.bound_coef > 0)
          loss.total = loss.total + cfg_.bound_coef * action_bound_loss(mean_action, low, high);
        (loss.total * share).backward();
        local = loss.total.item<double>() * share;
        sums[0] += loss.policy.item<double>() * share;
        sums[1] += loss.value.item<double>() * share;
        sums[2] += loss.approx_kl.item<double>() * share;
        sums[3] += loss.clip_fraction.item<double>() * share;
      }
      const double total = group_.sum_gradients(net_->parameters(), local);
      if (!std::isfinite(total))
        throw Error("PPO loss became " + std::to_string(total) + " at iteration " +
                    std::to_string(iteration_ + 1) + " (task '" + envs_.spec().name +
                    "'); the last checkpoint is kept: lower ppo.lr or check the task's rewards");
      torch::nn::utils::clip_grad_norm_(net_->parameters(), cfg_.max_grad_norm);
      optimizer_->step();
      if (cfg_.min_log_std > -20.0) {
        torch::NoGradGuard no_grad;
        net_->log_std.clamp_min_(cfg_.min_log_std);
      }
      ++batches;
    }
  }
  group_.sum(sums, 4);
  stats.policy_loss = sums[0] / batches;
  stats.value_loss = sums[1] / batches;
  stats.approx_kl = sums[2] / batches;
  stats.clip_fraction = sums[3] / batches;
  stats.entropy = net_->entropy().item<double>();
}

}  // namespace segue
