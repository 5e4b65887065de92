#include "algorithms/trpo.h"

#include <algorithm>
#include <cmath>

#include "algorithms/natural_gradient.h"
#include "algorithms/optimizer_step.h"
#include "algorithms/ppo_loss.h"
#include "core/error.h"

namespace segue {

TrpoConfig TrpoConfig::read(const Section& s) {
  TrpoConfig c;
  c.read_rollout(s);
  c.max_kl = s.get("max_kl", c.max_kl, Range::positive());
  c.cg_iters = s.get("cg_iters", c.cg_iters, Range::positive());
  c.cg_damping = s.get("cg_damping", c.cg_damping, Range::non_negative());
  c.fisher_stride = s.get("fisher_stride", c.fisher_stride, Range::positive());
  c.line_search_steps = s.get("line_search_steps", c.line_search_steps, Range::positive());
  c.vf_lr = s.get("vf_lr", c.vf_lr, Range::positive());
  c.vf_epochs = s.get("vf_epochs", c.vf_epochs, Range::positive());
  c.vf_minibatch = s.get("vf_minibatch", c.vf_minibatch, Range::positive());
  if (c.vf_minibatch > c.rollout_size())
    throw s.error("vf_minibatch", std::to_string(c.vf_minibatch) + " is larger than a rollout (num_envs x steps_per_env = " +
                                      std::to_string(c.rollout_size()) + ")");
  return c;
}

TRPO::TRPO(const TrpoConfig& config, const ActorCriticSpec& net, VectorEnv& envs, uint64_t seed,
           const Distributed& group)
    : OnPolicyLearner("trpo", config, net, envs, seed, group), cfg_(config), actor_(net_->actor, net.activation),
      critic_(net_->critic, net.activation) {
  // The optimiser fits the value network only: the policy moves by the natural step.
  optimizer_ = std::make_unique<torch::optim::Adam>(net_->critic->parameters(), torch::optim::AdamOptions(cfg_.vf_lr));
}

void TRPO::update(IterationStats& stats) {
  // With several ranks, rank 0 updates on every rank's rollout (OnPolicyLearner::
  // whole_rollout()) and sends the networks to the others.
  const RolloutBuffer& rollout = whole_rollout();
  // The same minibatches in every run, whatever a reward hook drew before.
  torch::manual_seed(mix_seed(seed_, 2 * iteration_ + 2) ^ 0x9e3779b9ULL);
  if (group_.leader())  // the two networks' parts share nothing: side by side where they can
    run_both([&] { policy_step(rollout, stats); }, [&] { fit_value(rollout, stats); });
  double values[4] = {stats.policy_loss, stats.approx_kl, stats.step_size, stats.value_loss};
  share_leader_update(net_->parameters(), values, 4);
  stats.policy_loss = values[0], stats.approx_kl = values[1], stats.step_size = values[2], stats.value_loss = values[3];
  stats.entropy = net_->entropy().item<double>();
}

namespace {

// The surrogate mean_t exp(log pi(a_t|s_t) - log pi_old(a_t|s_t)) A_t over m rows at the
// means `mu` [m, act_dim] and log standard deviations `log_std`; with `d_mu`, its gradient
// with respect to mu (overwritten) and to log sigma (added to `d_log_std`), d/d log pi
// being r A / m.
double surrogate(const float* mu, const float* actions, const float* old_log_prob, const float* adv, const float* log_std,
                 int64_t m, int k, float* d_mu = nullptr, float* d_log_std = nullptr) {
  double sum = 0.0;
  for (int64_t i = 0; i < m; ++i) {
    const float* mean = mu + i * k;
    const float* a = actions + i * k;
    const double ra = std::exp(gaussian_log_prob(a, mean, log_std, k) - old_log_prob[i]) * adv[i];
    sum += ra;
    if (d_mu) gaussian_log_prob_gradient(a, mean, log_std, k, ra / double(m), d_mu + i * k, d_log_std);
  }
  return sum / double(m);
}

}  // namespace

void TRPO::policy_step(const RolloutBuffer& rollout, IterationStats& stats) {
  const int64_t M = int64_t(rollout.T) * rollout.N;
  const int k = rollout.act_dim;
  const float* obs = rollout.obs.data();
  const float* actions = rollout.actions.data();
  const float* old_log_prob = rollout.log_probs.data();
  standardized_advantages(rollout.advantages, nullptr, M, adv_);  // over the rollout

  std::vector<torch::Tensor> params = net_->actor->parameters();
  params.push_back(net_->log_std);
  const int64_t p = actor_.parameter_count();
  const std::vector<float> old_log_std = to_floats(net_->log_std);
  // The surrogate and its gradient at theta_old.
  old_mean_ = actor_.forward(obs, int(M));
  dmu_.resize(M, k);
  torch::Tensor g = torch::zeros({p + k});
  const double surrogate_old = surrogate(old_mean_.data(), actions, old_log_prob, adv_.data(), old_log_std.data(), M, k,
                                         dmu_.data(), g.data_ptr<float>() + p);
  actor_.backward(dmu_, g.data_ptr<float>());
  if (!std::isfinite(surrogate_old) || !torch::isfinite(g).all().item<bool>())
    throw Error("TRPO's surrogate became non-finite at iteration " + std::to_string(iteration_ + 1) + " (task '" +
                envs_.spec().name + "'); the last checkpoint is kept: check the task's rewards");
  stats.policy_loss = -surrogate_old, stats.approx_kl = 0, stats.step_size = 0;
  if (g.abs().max().item<double>() == 0.0) return;  // all advantages zero: nothing to improve

  // The Fisher-vector product on every fisher_stride-th row.
  std::vector<int64_t> fisher_rows;
  for (int64_t i = 0; i < M; i += cfg_.fisher_stride) fisher_rows.push_back(i);
  gather_rows(rollout.obs, rollout.in_dim, fisher_rows.data(), int(fisher_rows.size()), fisher_obs_);
  actor_.forward(fisher_obs_.data(), int(fisher_rows.size()));
  GaussianFisher fisher(actor_, old_log_std, 1.0 / double(fisher_rows.size()));
  auto fisher_vector = [&](const torch::Tensor& v) { return fisher.product(v) + cfg_.cg_damping * v; };
  auto x = conjugate_gradient(fisher_vector, g, cfg_.cg_iters);
  // The step to the trust region's edge under the quadratic model: 0.5 s'Fs = max_kl.
  const double shs = 0.5 * x.dot(fisher_vector(x)).item<double>();
  if (!(shs > 0.0) || !std::isfinite(shs)) return;
  auto full_step = x * std::sqrt(cfg_.max_kl / shs);
  auto theta_old = flatten(params).detach().clone();
  torch::NoGradGuard no_grad;
  for (int step = 0; step < cfg_.line_search_steps; ++step) {
    const double fraction = std::pow(0.5, step);
    assign_flat(params, theta_old + fraction * full_step);
    const float* log_std = net_->log_std.data_ptr<float>();
    const auto& mu = actor_.forward(obs, int(M));
    const double now = surrogate(mu.data(), actions, old_log_prob, adv_.data(), log_std, M, k);
    const double kl = gaussian_kl_sum(old_mean_.data(), old_log_std.data(), mu.data(), log_std, M, k) / double(M);
    if (std::isfinite(now) && std::isfinite(kl) && kl <= 1.5 * cfg_.max_kl && now > surrogate_old) {
      stats.policy_loss = -now, stats.approx_kl = kl, stats.step_size = fraction;
      if (rollout_cfg_.min_log_std > -20.0) net_->log_std.clamp_min_(rollout_cfg_.min_log_std);
      return;
    }
  }
  assign_flat(params, theta_old);  // no step kept the surrogate improving inside the region
}

void TRPO::fit_value(const RolloutBuffer& rollout, IterationStats& stats) {
  double loss_sum = 0.0;
  int batches = 0;
  for (int epoch = 0; epoch < cfg_.vf_epochs; ++epoch)
    for (const torch::Tensor& minibatch : shuffled_minibatches(cfg_.vf_minibatch)) {
      const int n = int(minibatch.numel());
      const int64_t* rows = minibatch.data_ptr<int64_t>();
      gather_rows(rollout.obs, rollout.in_dim, rows, n, vf_obs_);
      gather_rows(rollout.returns, 1, rows, n, vf_returns_);
      const auto& value = critic_.forward(vf_obs_.data(), n);
      dvalue_.resize(n, 1);
      const double loss = value_loss(value.data(), vf_returns_.data(), n, dvalue_.data());
      if (!std::isfinite(loss))
        throw Error("TRPO's value loss became " + std::to_string(loss) + " at iteration " +
                    std::to_string(iteration_ + 1) + " (task '" + envs_.spec().name +
                    "'); the last checkpoint is kept: lower trpo.vf_lr or check the task's rewards");
      critic_.backward(dvalue_);
      adam_step(*optimizer_);
      loss_sum += loss, ++batches;
    }
  stats.value_loss = loss_sum / std::max(batches, 1);
}

}  // namespace segue
