#include "algorithms/trpo.h"

#include <algorithm>
#include <cmath>
#include <cstring>

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
  // Every rank draws the same minibatches, whatever a reward hook drew before.
  torch::manual_seed(mix_seed(seed_, 2 * iteration_ + 2) ^ 0x9e3779b9ULL);
  policy_step(stats);
  fit_value(stats);
  stats.entropy = net_->entropy().item<double>();
}

namespace {

// Each rank's part of the surrogate sum_t exp(log pi(a_t|s_t) - log pi_old(a_t|s_t)) A_t /
// rows at the means `mu` [M, act_dim] and log standard deviations `log_std`; with
// `d_mu`, its gradient with respect to mu (overwritten) and to log sigma (added to
// `d_log_std`), d/d log pi being r A / rows.
double surrogate(const float* mu, const float* actions, const float* old_log_prob, const float* adv, const float* log_std,
                 int64_t m, int k, double rows, float* d_mu = nullptr, float* d_log_std = nullptr) {
  double sum = 0.0;
  for (int64_t i = 0; i < m; ++i) {
    const float* mean = mu + i * k;
    const float* a = actions + i * k;
    const double ra = std::exp(gaussian_log_prob(a, mean, log_std, k) - old_log_prob[i]) * adv[i];
    sum += ra;
    if (d_mu) gaussian_log_prob_gradient(a, mean, log_std, k, ra / rows, d_mu + i * k, d_log_std);
  }
  return sum / rows;
}

}  // namespace

void TRPO::policy_step(IterationStats& stats) {
  const int64_t T = buf_.T, N = buf_.N, M = T * N;
  const int k = buf_.act_dim;
  const double rows = double(global_rows());  // the whole rollout's, every rank's
  // Advantages standardised over the whole rollout.
  double moments[2] = {0.0, 0.0};
  for (int64_t i = 0; i < M; ++i) moments[0] += buf_.advantages[i], moments[1] += double(buf_.advantages[i]) * buf_.advantages[i];
  group_.sum(moments, 2);
  const double mean = moments[0] / rows;
  const double std = std::sqrt(std::max(moments[1] - rows * mean * mean, 0.0) / std::max(rows - 1.0, 1.0));
  adv_.resize(M);
  for (int64_t i = 0; i < M; ++i) adv_[i] = float((double(buf_.advantages[i]) - mean) / (std + 1e-8));

  std::vector<torch::Tensor> params = net_->actor->parameters();
  params.push_back(net_->log_std);
  const int64_t p = actor_.parameter_count();
  const std::vector<float> old_log_std = to_floats(net_->log_std);
  // The surrogate and its gradient at theta_old. Each rank sums its rows and divides by
  // the whole rollout's: summed over ranks, a mean.
  old_mean_ = actor_.forward(buf_.obs.data(), int(M));
  dmu_.resize(M, k);
  torch::Tensor g = torch::zeros({p + k});
  double surrogate_old = surrogate(old_mean_.data(), buf_.actions.data(), buf_.log_probs.data(), adv_.data(),
                                   old_log_std.data(), M, k, rows, dmu_.data(), g.data_ptr<float>() + p);
  actor_.backward(dmu_, g.data_ptr<float>());
  group_.sum(g);
  group_.sum(&surrogate_old, 1);
  if (!std::isfinite(surrogate_old) || !torch::isfinite(g).all().item<bool>())
    throw Error("TRPO's surrogate became non-finite at iteration " + std::to_string(iteration_ + 1) + " (task '" +
                envs_.spec().name + "'); the last checkpoint is kept: check the task's rewards");
  stats.policy_loss = -surrogate_old, stats.approx_kl = 0, stats.step_size = 0;
  if (g.abs().max().item<double>() == 0.0) return;  // all advantages zero: nothing to improve

  // The Fisher-vector product's rows: every fisher_stride-th row of the whole rollout
  // (row t * envs + e over every rank), so any rank layout uses the same ones.
  const int64_t envs = global_rows() / T, first = envs_.first_index(), stride = cfg_.fisher_stride;
  std::vector<int64_t> fisher_rows;
  for (int64_t t = 0; t < T; ++t)
    for (int64_t i = 0; i < N; ++i)
      if ((t * envs + first + i) % stride == 0) fisher_rows.push_back(t * N + i);
  const double fisher_count = double((global_rows() + stride - 1) / stride);
  gather_rows(buf_.obs, buf_.in_dim, fisher_rows.data(), int(fisher_rows.size()), fisher_obs_);
  actor_.forward(fisher_obs_.data(), int(fisher_rows.size()));
  GaussianFisher fisher(actor_, old_log_std, 1.0 / fisher_count);
  // F v + damping v, F summed over ranks (each rank's rows weighted by the whole count).
  auto fisher_vector = [&](const torch::Tensor& v) {
    auto fv = fisher.product(v);
    group_.sum(fv);
    return fv + cfg_.cg_damping * v;
  };
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
    const auto& mu = actor_.forward(buf_.obs.data(), int(M));
    double now[2] = {surrogate(mu.data(), buf_.actions.data(), buf_.log_probs.data(), adv_.data(), log_std, M, k, rows),
                     gaussian_kl_sum(old_mean_.data(), old_log_std.data(), mu.data(), log_std, M, k) / rows};
    group_.sum(now, 2);
    if (std::isfinite(now[0]) && std::isfinite(now[1]) && now[1] <= 1.5 * cfg_.max_kl && now[0] > surrogate_old) {
      stats.policy_loss = -now[0], stats.approx_kl = now[1], stats.step_size = fraction;
      if (rollout_cfg_.min_log_std > -20.0) net_->log_std.clamp_min_(rollout_cfg_.min_log_std);
      return;
    }
  }
  assign_flat(params, theta_old);  // no step kept the surrogate improving inside the region
}

void TRPO::fit_value(IterationStats& stats) {
  // With several ranks, rank 0 fits on the whole rollout and sends the critic to the
  // others: the fit is hundreds of small Adam steps (the reference's minibatches of 64),
  // and summing each step's gradient over the ranks costs far more than the step itself
  // (docs/distributed.md). Rank 0's fit is the one a single process makes.
  const bool alone = group_.single();
  std::vector<float> gathered_obs, gathered_returns;
  if (!alone) gathered_obs = gather_rollout(buf_.obs, buf_.in_dim), gathered_returns = gather_rollout(buf_.returns, 1);
  const std::vector<float>& obs = alone ? buf_.obs : gathered_obs;
  const std::vector<float>& returns = alone ? buf_.returns : gathered_returns;
  const std::vector<torch::Tensor> params = net_->critic->parameters();
  double total = 0.0;
  int batches = 0;
  if (group_.leader())
    for (int epoch = 0; epoch < cfg_.vf_epochs; ++epoch)
      for (const Minibatch& m : shuffled_minibatches(cfg_.vf_minibatch, /*whole=*/true)) {
        const int n = int(m.rows.numel());
        const int64_t* rows = m.rows.data_ptr<int64_t>();
        gather_rows(obs, buf_.in_dim, rows, n, vf_obs_);
        gather_rows(returns, 1, rows, n, vf_returns_);
        const auto& value = critic_.forward(vf_obs_.data(), n);
        dvalue_.resize(n, 1);
        const double loss = value_loss(value.data(), vf_returns_.data(), n, dvalue_.data());
        if (!std::isfinite(loss))
          throw Error("TRPO's value loss became " + std::to_string(loss) + " at iteration " +
                      std::to_string(iteration_ + 1) + " (task '" + envs_.spec().name +
                      "'); the last checkpoint is kept: lower trpo.vf_lr or check the task's rewards");
        critic_.backward(dvalue_);
        adam_step(*optimizer_);
        total += loss, ++batches;
      }
  stats.value_loss = total / std::max(batches, 1);
  if (alone) return;
  // Rank 0's critic and loss, on every rank.
  torch::Tensor theta = torch::cat({flatten(params).detach(), torch::tensor({float(stats.value_loss)})});
  std::string bytes(size_t(theta.numel()) * sizeof(float), '\0');
  std::memcpy(&bytes[0], theta.data_ptr<float>(), bytes.size());
  bytes = group_.broadcast(bytes);
  std::memcpy(theta.data_ptr<float>(), bytes.data(), bytes.size());
  assign_flat(params, theta.slice(0, 0, theta.numel() - 1));
  stats.value_loss = theta[theta.numel() - 1].item<double>();
}

}  // namespace segue
