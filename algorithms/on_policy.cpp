#include "algorithms/on_policy.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <thread>

#include "algorithms/gae.h"
#include "algorithms/natural_gradient.h"
#include "core/error.h"

namespace segue {

void OnPolicyConfig::read_rollout(const Section& s) {
  // Sizes are bounded before anything is allocated: a typo of 1e9 environments must not
  // exhaust memory.
  total_steps = s.get("total_steps", total_steps, Range::positive());
  num_envs = s.get("num_envs", num_envs, Range::closed(1, kMaxEnvs));
  steps_per_env = s.get("steps_per_env", steps_per_env, Range::closed(1, kMaxStepsPerEnv));
  gamma = s.get("gamma", gamma, Range::open_closed(0, 1));
  lambda = s.get("lambda", lambda, Range::closed(0, 1));
  min_log_std = s.get("min_log_std", min_log_std, Range::any());
  normalize_reward = s.get("normalize_reward", normalize_reward);
  obs_clip = s.get("obs_clip", obs_clip, Range::positive());
  policy_lag = s.get("policy_lag", policy_lag, Range::closed(0, 1));
}

OnPolicyLearner::OnPolicyLearner(std::string name, const OnPolicyConfig& config, const ActorCriticSpec& net,
                                 VectorEnv& envs, uint64_t seed, const Distributed& group)
    : rollout_cfg_(config), envs_(envs), group_(group), seed_(seed), name_(std::move(name)),
      obs_rms_(net.obs_dim, config.obs_clip), return_rms_(1), global_envs_(envs.size()) {
  if (!group_.single()) {
    double n = envs.size();
    group_.sum(&n, 1);
    global_envs_ = int64_t(n);
    if (global_envs_ != rollout_cfg_.num_envs)
      throw Error(name_ + ": the ranks step " + std::to_string(global_envs_) + " environments in all, " + name_ +
                  ".num_envs is " + std::to_string(rollout_cfg_.num_envs));
    if (rollout_cfg_.policy_lag > 0)
      throw Error(name_ + ".policy_lag: 1 overlaps one process's rollout and update; a data-parallel run (" +
                  std::to_string(group_.size()) + " ranks) takes policy_lag 0");
    // The other ranks wait while rank 0 updates, so a core of theirs is idle: rank 0 takes
    // one more thread for the update's second network (run_both) where its pool has one.
    if (group_.leader() && envs_.pool().size() == 1) update_pool_ = std::make_unique<ThreadPool>(2);
  }
  torch::manual_seed(mix_seed(seed, 0x5e9e));
  net_ = ActorCritic(net);
  if (!net.ignore_obs.empty()) obs_rms_.ignore(net.ignore_obs.at(0), net.ignore_obs.at(1));
  buf_.resize(rollout_cfg_.steps_per_env, envs.size(), net.obs_dim, net.act_dim, net.in_dim());
  if (rollout_cfg_.policy_lag > 0) next_buf_ = buf_;
  running_return_.assign(envs.size(), 0.0);
  mean_.resize(size_t(envs.size()) * net.act_dim);
  actor_workspace_.resize(envs.size());
  cut_.resize(size_t(rollout_cfg_.steps_per_env) * envs.size());
  env_rng_.resize(envs.size());
  return_samples_.resize(size_t(rollout_cfg_.steps_per_env) * envs.size());
  envs_.reset(mix_seed(seed, 0));
  refresh_inference_copy();
}

int64_t OnPolicyLearner::total_iterations() const {
  return (rollout_cfg_.total_steps + rollout_cfg_.rollout_size() - 1) / rollout_cfg_.rollout_size();
}

std::vector<torch::Tensor> OnPolicyLearner::shuffled_minibatches(int64_t size) const {
  const int64_t M = global_rows(), mb = std::min<int64_t>(size, M);
  auto perm = torch::randperm(M, torch::kLong);
  std::vector<torch::Tensor> out;
  for (int64_t start = 0; start < M; start += mb) out.push_back(perm.slice(0, start, std::min(start + mb, M)));
  return out;
}

const RolloutBuffer& OnPolicyLearner::whole_rollout() {
  if (group_.single()) return buf_;
  const int64_t T = buf_.T, G = global_envs_, first = envs_.first_index();
  whole_.T = buf_.T, whole_.N = int(G), whole_.obs_dim = buf_.obs_dim, whole_.in_dim = buf_.in_dim,
  whole_.act_dim = buf_.act_dim;
  struct Field {
    const std::vector<float>& mine;
    int width;
    std::vector<float>& whole;
  };
  const Field fields[] = {{buf_.obs, buf_.in_dim, whole_.obs},
                          {buf_.actions, buf_.act_dim, whole_.actions},
                          {buf_.log_probs, 1, whole_.log_probs},
                          {buf_.advantages, 1, whole_.advantages},
                          {buf_.returns, 1, whole_.returns}};
  // One exchange: each rank sends its first environment's index, then each field's rows.
  std::string bytes(reinterpret_cast<const char*>(&first), sizeof(int64_t));
  int width = 0;
  for (const Field& f : fields) {
    bytes.append(reinterpret_cast<const char*>(f.mine.data()), f.mine.size() * sizeof(float));
    f.whole.resize(size_t(T * G) * f.width);
    width += f.width;
  }
  for (const std::string& part : group_.gather(bytes)) {
    int64_t at = 0;
    std::memcpy(&at, part.data(), sizeof(int64_t));
    const int64_t n = int64_t((part.size() - sizeof(int64_t)) / sizeof(float)) / (T * width);  // its environments
    const float* from = reinterpret_cast<const float*>(part.data() + sizeof(int64_t));
    for (const Field& f : fields)
      for (int64_t t = 0; t < T; ++t, from += n * f.width)
        std::memcpy(&f.whole[size_t(t * G + at) * f.width], from, size_t(n * f.width) * sizeof(float));
  }
  return whole_;
}

void OnPolicyLearner::run_both(const std::function<void()>& a, const std::function<void()>& b) {
  ThreadPool& pool = update_pool_ ? *update_pool_ : envs_.pool();
  if (rollout_cfg_.policy_lag == 0 && pool.size() > 1) {
    pool.parallel_for(2, [&](int i, int) { i == 0 ? a() : b(); });
  } else {
    a();
    b();
  }
}

void OnPolicyLearner::share_leader_update(const std::vector<torch::Tensor>& params, double* values, int n) const {
  if (group_.single()) return;
  torch::NoGradGuard no_grad;
  torch::Tensor theta = flatten(params).detach();
  std::string bytes(size_t(theta.numel()) * sizeof(float) + size_t(n) * sizeof(double), '\0');
  std::memcpy(&bytes[0], theta.data_ptr<float>(), size_t(theta.numel()) * sizeof(float));
  std::memcpy(&bytes[size_t(theta.numel()) * sizeof(float)], values, size_t(n) * sizeof(double));
  bytes = group_.broadcast(bytes);
  std::memcpy(theta.data_ptr<float>(), bytes.data(), size_t(theta.numel()) * sizeof(float));
  std::memcpy(values, &bytes[size_t(theta.numel()) * sizeof(float)], size_t(n) * sizeof(double));
  assign_flat(params, theta);
}

void OnPolicyLearner::gather_rows(const std::vector<float>& from, int width, const int64_t* rows, int n,
                                  std::vector<float>& to) {
  to.resize(size_t(n) * width);
  for (int i = 0; i < n; ++i) std::copy_n(&from[size_t(rows[i]) * width], width, &to[size_t(i) * width]);
}

void OnPolicyLearner::standardized_advantages(const std::vector<float>& advantages, const int64_t* rows, int64_t n,
                                              std::vector<float>& out) {
  auto at = [&](int64_t i) { return double(advantages[rows ? rows[i] : i]); };
  double sum = 0.0, squares = 0.0;
  for (int64_t i = 0; i < n; ++i) sum += at(i), squares += at(i) * at(i);
  const double mean = sum / n, std = std::sqrt(std::max(squares - n * mean * mean, 0.0) / std::max(n - 1.0, 1.0));
  out.resize(n);
  for (int64_t i = 0; i < n; ++i) out[i] = float((at(i) - mean) / (std + 1e-8));
}

void OnPolicyLearner::set_log_std(double log_std) {
  torch::NoGradGuard no_grad;
  net_->log_std.fill_(log_std);
  refresh_inference_copy();
}

void OnPolicyLearner::net_input(const float* raw, float* out) const {
  obs_rms_.normalize(raw, out);
  net_->spec.features.write(raw, out + buf_.obs_dim);
}

void OnPolicyLearner::refresh_inference_copy() {
  actor_copy_ = EigenMlp(net_->actor, net_->spec.activation);
  log_std_ = to_floats(net_->log_std);
}

IterationStats OnPolicyLearner::iterate() {
  using Clock = std::chrono::steady_clock;
  IterationStats stats;
  const auto t0 = Clock::now();
  const double comm0 = group_.comm_seconds();
  envs_.finished().clear();
  if (!rollout_ready_) {  // policy_lag 0, or the first rollout of a lagged run
    collect_steps(iteration_, buf_);
    finish_rollout(iteration_);
  }
  const auto t1 = Clock::now();
  stats.rollout_seconds = std::chrono::duration<double>(t1 - t0).count();
  // policy_lag 1: the next rollout is collected beside this update, by the policy that
  // collected this one; it is not collected after the last update.
  const bool ahead = rollout_cfg_.policy_lag > 0 && iteration_ + 1 < total_iterations();
  std::thread collector;
  std::exception_ptr collector_error;
  double ahead_seconds = 0.0;
  if (ahead)
    collector = std::thread([&] {
      try {
        const auto a = Clock::now();
        collect_steps(iteration_ + 1, next_buf_);
        ahead_seconds = std::chrono::duration<double>(Clock::now() - a).count();
      } catch (...) {
        collector_error = std::current_exception();
      }
    });
  try {
    update(stats);
  } catch (...) {
    if (collector.joinable()) collector.join();
    throw;
  }
  const auto t2 = Clock::now();
  if (collector.joinable()) collector.join();
  if (collector_error) std::rethrow_exception(collector_error);
  refresh_inference_copy();
  stats.update_seconds = std::chrono::duration<double>(t2 - t1).count();
  stats.rollout_seconds += ahead_seconds;
  rollout_ready_ = ahead;
  if (ahead) {
    std::swap(buf_, next_buf_);
    finish_rollout(iteration_ + 1);
  }
  episode_stats(stats);
  stats.comm_seconds = group_.comm_seconds() - comm0;
  ++iteration_;
  global_step_ += int64_t(buf_.T) * global_envs_;
  wall_seconds_ += std::chrono::duration<double>(Clock::now() - t0).count();
  stats.iteration = iteration_;
  stats.global_step = global_step_;
  return stats;
}

void OnPolicyLearner::sample_action(RolloutBuffer& buf, int t, int i) {
  const int N = buf.N, A = buf.act_dim;
  const size_t k = size_t(t) * N + i;
  float* a = &buf.actions[k * A];
  float* mu = &mean_[size_t(i) * A];
  actor_copy_.forward(&buf.obs[k * buf.in_dim], 1, mu, &actor_workspace_[i]);
  for (int j = 0; j < A; ++j) a[j] = mu[j] + std::exp(log_std_[j]) * static_cast<float>(env_rng_[i].normal());
  buf.log_probs[k] = static_cast<float>(gaussian_log_prob(a, mu, log_std_.data(), A));
}

void OnPolicyLearner::collect_rollout(IterationStats& stats) {
  envs_.finished().clear();
  collect_steps(iteration_, buf_);
  finish_rollout(iteration_);
  episode_stats(stats);
}

void OnPolicyLearner::collect_steps(int64_t iteration, RolloutBuffer& buf) {
  // Per-iteration seeds make a resumed run draw the same noise as an uninterrupted one.
  const uint64_t noise_seed = mix_seed(seed_, 2 * iteration + 1);
  for (int i = 0; i < envs_.size(); ++i) env_rng_[i].seed(mix_seed(noise_seed, uint64_t(envs_.first_index() + i)));
  const int T = buf.T, N = buf.N, D = buf.obs_dim, I = buf.in_dim;
  // Each environment's steps in order on one thread: the policy is fixed for the rollout,
  // so environment i's trajectory depends only on its own state and noise stream, and the
  // rollout is the same whatever the thread count.
  envs_.run(T, [&](int i, int t) {
    const size_t k = size_t(t) * N + i;
    float* raw = &buf.raw_obs[k * D];
    std::copy_n(envs_.obs() + size_t(i) * D, D, raw);
    net_input(raw, &buf.obs[k * I]);
    sample_action(buf, t, i);
    envs_.step_one(i, &buf.actions[k * buf.act_dim]);
    const bool terminated = envs_.terminated()[i], truncated = envs_.truncated()[i];
    // Where the episode ended, obs() already holds the next episode's start.
    std::copy_n((terminated || truncated ? envs_.final_obs() : envs_.obs()) + size_t(i) * D, D, &buf.next_raw_obs[k * D]);
    buf.raw_rewards[k] = envs_.reward()[i];
    buf.dones[k] = terminated || truncated;
    cut_[k] = truncated && !terminated;
  });
  // Truncated steps in step order, with their final observation as network input.
  buf.truncated_index.clear();
  buf.truncated_obs.clear();
  for (size_t k = 0; k < size_t(T) * N; ++k)
    if (cut_[k]) {
      buf.truncated_index.push_back(static_cast<int>(k));
      buf.truncated_obs.resize(buf.truncated_obs.size() + I);
      net_input(&buf.next_raw_obs[k * D], &buf.truncated_obs[buf.truncated_obs.size() - I]);
    }
}

void OnPolicyLearner::episode_stats(IterationStats& stats) {
  // Episode statistics over every rank, in the task's own reward units.
  double totals[5] = {double(envs_.finished().size()), 0, 0, 0, 0};
  for (const auto& e : envs_.finished())
    totals[1] += e.ret, totals[2] += e.length, totals[3] += e.success, totals[4] += e.success_count;
  group_.sum(totals, 5);
  stats.episodes = static_cast<int>(totals[0]);
  if (stats.episodes > 0) {
    stats.episode_return = totals[1] / totals[0];
    stats.episode_length = totals[2] / totals[0];
    stats.success_rate = totals[3] / totals[0];
    stats.success_count = totals[4] / totals[0];
  }
}

void OnPolicyLearner::finish_rollout(int64_t iteration) {
  const int T = buf_.T, N = buf_.N, D = buf_.obs_dim, I = buf_.in_dim;
  // A reward hook (and anything else drawing from LibTorch's generator) sees the same
  // draws whichever iteration collected the rollout.
  torch::manual_seed(mix_seed(seed_, 2 * iteration + 2));
  if (reward_hook_) reward_hook_(buf_);
  // The scale of rewards: the std of the discounted return, tracked per environment and
  // pooled over the rollout (and the ranks).
  for (int t = 0; t < T; ++t)
    for (int i = 0; i < N; ++i) {
      size_t k = size_t(t) * N + i;
      double r = buf_.raw_rewards[k];
      buf_.rewards[k] = static_cast<float>(r);
      running_return_[i] = running_return_[i] * rollout_cfg_.gamma + r;
      return_samples_[k] = static_cast<float>(running_return_[i]);
      if (buf_.dones[k]) running_return_[i] = 0.0;
    }
  return_rms_.update(return_samples_.data(), int64_t(T) * N, &group_);
  if (rollout_cfg_.normalize_reward) {
    float scale = static_cast<float>(1.0 / std::sqrt(return_rms_.var()[0] + 1e-8));
    for (auto& r : buf_.rewards) r = std::clamp(r * scale, -10.0f, 10.0f);
  }
  bool finite = true;
  for (float r : buf_.rewards) finite = finite && std::isfinite(r);
  if (group_.any(!finite)) throw Error("task '" + envs_.spec().name + "' produced a non-finite reward");

  torch::NoGradGuard no_grad;
  auto values = net_->value(torch::from_blob(buf_.obs.data(), {int64_t(T) * N, I}));
  std::copy(values.data_ptr<float>(), values.data_ptr<float>() + values.numel(), buf_.values.begin());
  std::vector<float> last_obs(size_t(N) * I), last_values(N);
  for (int i = 0; i < N; ++i) net_input(envs_.obs() + size_t(i) * D, &last_obs[size_t(i) * I]);
  auto lv = net_->value(torch::from_blob(last_obs.data(), {N, I}));
  std::copy(lv.data_ptr<float>(), lv.data_ptr<float>() + N, last_values.begin());
  // A time limit is not a real end: fold gamma V(final state) into the last reward.
  if (!buf_.truncated_index.empty()) {
    int64_t n = static_cast<int64_t>(buf_.truncated_index.size());
    auto tv = net_->value(torch::from_blob(buf_.truncated_obs.data(), {n, I}));
    for (int64_t j = 0; j < n; ++j)
      buf_.rewards[buf_.truncated_index[j]] += static_cast<float>(rollout_cfg_.gamma * tv[j].item<float>());
  }
  compute_gae(buf_.rewards, buf_.values, buf_.dones, last_values, T, N, rollout_cfg_.gamma, rollout_cfg_.lambda,
              buf_.advantages, buf_.returns);
  // The normaliser learns from this rollout only after the policy has used it.
  obs_rms_.update(buf_.raw_obs.data(), int64_t(T) * N, &group_);
}

torch::Tensor OnPolicyLearner::log_prob(const float* raw_obs, const float* actions, int64_t n) {
  const int D = buf_.obs_dim, I = buf_.in_dim;
  auto obs = torch::empty({n, I});
  for (int64_t i = 0; i < n; ++i) net_input(raw_obs + i * D, obs.data_ptr<float>() + i * I);
  torch::NoGradGuard no_grad;
  auto act = torch::from_blob(const_cast<float*>(actions), {n, int64_t(buf_.act_dim)});
  return net_->log_prob(net_->mean(obs), act);
}

void OnPolicyLearner::init_actor(const Policy& p) {
  if (p.obs_dim() > buf_.obs_dim || p.act_dim() > buf_.act_dim)
    throw Error("init_actor: the policy's sizes differ from the trainer's");
  // A policy without features starts a trainer with them at zero weight on the features;
  // one with features must have the trainer's (its columns are then the same).
  if (!p.features().empty() && (!(p.features() == net_->spec.features) || p.obs_dim() != buf_.obs_dim))
    throw Error("init_actor: the policy's periodic input features differ from the trainer's");
  const auto& ws = p.mlp().weights();
  const auto& bs = p.mlp().biases();
  torch::NoGradGuard no_grad;
  size_t layer = 0;
  for (auto& m : net_->actor->modules(/*include_self=*/false)) {
    auto* linear = m->as<torch::nn::Linear>();
    if (!linear) continue;
    const bool first = layer == 0, last = layer + 1 == ws.size();
    const int64_t rows = ws.size() > layer ? ws[layer].rows() : -1;
    const int64_t cols = ws.size() > layer ? ws[layer].cols() : -1;
    if (layer >= ws.size() || (first ? linear->weight.size(1) < cols : linear->weight.size(1) != cols) ||
        (last ? linear->weight.size(0) < rows : linear->weight.size(0) != rows))
      throw Error("init_actor: the policy's hidden layers differ from the trainer's");
    if (first && linear->weight.size(1) > cols) linear->weight.zero_();
    if (last && linear->weight.size(0) > rows) {
      linear->weight.zero_();
      linear->bias.zero_();
    }
    linear->weight.narrow(0, 0, rows).narrow(1, 0, cols).copy_(
        torch::from_blob(const_cast<float*>(ws[layer].data()), {rows, cols}));
    linear->bias.narrow(0, 0, rows).copy_(torch::from_blob(const_cast<float*>(bs[layer].data()), {rows}));
    ++layer;
  }
  if (layer != ws.size()) throw Error("init_actor: the policy's hidden layers differ from the trainer's");
  // Inputs the policy does not see (beyond its obs_dim) start unscaled: mean 0, var 1.
  std::vector<double> mean(buf_.obs_dim, 0.0), var(buf_.obs_dim, 1.0);
  for (int j = 0; j < p.obs_dim(); ++j) {
    if (p.obs_inv_std()[j] == 0.0f) obs_rms_.ignore(j, j + 1);  // inputs the policy ignores stay ignored
    mean[j] = p.obs_mean()[j];
    var[j] = std::max(1.0 / (double(p.obs_inv_std()[j]) * p.obs_inv_std()[j]) - obs_rms_.eps(), 0.0);
  }
  // Weighted as much data as pi_b's training saw, so the first rollouts barely move it.
  obs_rms_.set(mean, var, 1e6);
  refresh_inference_copy();
}

void OnPolicyLearner::set_action_bias(int dim, float bias) {
  if (dim < 0 || dim >= buf_.act_dim) throw Error("set_action_bias: no action dimension " + std::to_string(dim));
  torch::nn::LinearImpl* last = nullptr;  // the output layer: the actor's last Linear
  for (auto& m : net_->actor->modules(/*include_self=*/false))
    if (auto* linear = m->as<torch::nn::Linear>()) last = linear;
  torch::NoGradGuard no_grad;
  last->bias[dim].fill_(bias);
  refresh_inference_copy();
}

Policy OnPolicyLearner::policy() const {
  const auto& spec = envs_.spec();
  Policy p(actor_copy_, std::vector<float>(obs_rms_.mean().begin(), obs_rms_.mean().end()), obs_rms_.inv_std(),
           static_cast<float>(obs_rms_.clip()), spec.act_low, spec.act_high, net_->spec.features);
  p.set_log_std(log_std_);
  return p;
}

}  // namespace segue
