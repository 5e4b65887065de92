#include "algorithms/ppo.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "algorithms/gae.h"
#include "algorithms/ppo_loss.h"
#include "core/error.h"
#include "core/run_dir.h"

namespace segue {

PpoConfig PpoConfig::read(const Section& s, PpoConfig c) {
  // Sizes are bounded before anything is allocated: a typo of 1e9 environments must not
  // exhaust memory.
  c.total_steps = s.get("total_steps", c.total_steps, Range::positive());
  c.num_envs = s.get("num_envs", c.num_envs, Range::closed(1, kMaxEnvs));
  c.steps_per_env = s.get("steps_per_env", c.steps_per_env, Range::closed(1, kMaxStepsPerEnv));
  c.epochs = s.get("epochs", c.epochs, Range::positive());
  c.minibatch_size = s.get("minibatch_size", c.minibatch_size, Range::positive());
  c.lr = s.get("lr", c.lr, Range::positive());
  c.anneal_lr = s.get("anneal_lr", c.anneal_lr);
  c.gamma = s.get("gamma", c.gamma, Range::open_closed(0, 1));
  c.lambda = s.get("lambda", c.lambda, Range::closed(0, 1));
  c.clip = s.get("clip", c.clip, Range::positive());
  c.vf_coef = s.get("vf_coef", c.vf_coef, Range::non_negative());
  c.ent_coef = s.get("ent_coef", c.ent_coef, Range::non_negative());
  c.min_log_std = s.get("min_log_std", c.min_log_std, Range::any());
  c.noise_repeat = s.get("noise_repeat", c.noise_repeat, Range::positive());
  c.bound_coef = s.get("bound_coef", c.bound_coef, Range::non_negative());
  c.max_grad_norm = s.get("max_grad_norm", c.max_grad_norm, Range::positive());
  c.normalize_reward = s.get("normalize_reward", c.normalize_reward);
  c.obs_clip = s.get("obs_clip", c.obs_clip, Range::positive());
  if (c.minibatch_size > int64_t(c.num_envs) * c.steps_per_env)
    throw s.error("minibatch_size", std::to_string(c.minibatch_size) + " is larger than a rollout (num_envs x steps_per_env = " +
                                        std::to_string(int64_t(c.num_envs) * c.steps_per_env) + ")");
  return c;
}

PPO::PPO(const PpoConfig& config, const ActorCriticSpec& net, VectorEnv& envs, uint64_t seed,
         const Distributed& group)
    : cfg_(config), envs_(envs), obs_rms_(net.obs_dim, config.obs_clip), return_rms_(1), group_(group),
      global_envs_(envs.size()), seed_(seed) {
  if (!group_.single()) {
    double n = envs.size();
    group_.sum(&n, 1);
    global_envs_ = int64_t(n);
    if (global_envs_ != cfg_.num_envs)
      throw Error("PPO: the ranks step " + std::to_string(global_envs_) + " environments in all, ppo.num_envs is " +
                  std::to_string(cfg_.num_envs));
  }
  torch::manual_seed(mix_seed(seed, 0x5e9e));
  net_ = ActorCritic(net);
  if (!net.ignore_obs.empty()) obs_rms_.ignore(net.ignore_obs.at(0), net.ignore_obs.at(1));
  optimizer_ = std::make_unique<torch::optim::Adam>(net_->parameters(),
                                                     torch::optim::AdamOptions(cfg_.lr).eps(1e-5));
  buf_.resize(cfg_.steps_per_env, envs.size(), net.obs_dim, net.act_dim, net.in_dim());
  running_return_.assign(envs.size(), 0.0);
  mean_.resize(size_t(envs.size()) * net.act_dim);
  noise_.resize(size_t(envs.size()) * net.act_dim);
  noise_age_.assign(envs.size(), 0);
  env_rng_.resize(envs.size());
  return_samples_.resize(size_t(cfg_.steps_per_env) * envs.size());
  envs_.reset(mix_seed(seed, 0));
  refresh_inference_copy();
}

int64_t PPO::total_iterations() const {
  return (cfg_.total_steps + cfg_.rollout_size() - 1) / cfg_.rollout_size();
}

double PPO::learning_rate() const {
  return static_cast<const torch::optim::AdamOptions&>(optimizer_->param_groups().front().options()).lr();
}

void PPO::set_log_std(double log_std) {
  torch::NoGradGuard no_grad;
  net_->log_std.fill_(log_std);
  refresh_inference_copy();
}

void PPO::net_input(const float* raw, float* out) const {
  obs_rms_.normalize(raw, out);
  net_->spec.features.write(raw, out + buf_.obs_dim);
}

void PPO::refresh_inference_copy() {
  actor_copy_ = EigenMlp(net_->actor, net_->spec.activation);
  log_std_ = to_floats(net_->log_std);
}

IterationStats PPO::iterate() {
  IterationStats stats;
  // Per-iteration seeds make a resumed run draw the same noise as an uninterrupted one.
  const uint64_t noise_seed = mix_seed(seed_, 2 * iteration_ + 1);
  for (int i = 0; i < envs_.size(); ++i) env_rng_[i].seed(mix_seed(noise_seed, uint64_t(envs_.first_index() + i)));
  torch::manual_seed(mix_seed(seed_, 2 * iteration_ + 2));
  auto t0 = std::chrono::steady_clock::now();
  const double comm0 = group_.comm_seconds();
  collect_rollout(stats);
  auto t1 = std::chrono::steady_clock::now();
  update(stats);
  auto t2 = std::chrono::steady_clock::now();
  stats.rollout_seconds = std::chrono::duration<double>(t1 - t0).count();
  stats.update_seconds = std::chrono::duration<double>(t2 - t1).count();
  stats.comm_seconds = group_.comm_seconds() - comm0;
  ++iteration_;
  global_step_ += int64_t(buf_.T) * global_envs_;
  wall_seconds_ += stats.rollout_seconds + stats.update_seconds;
  stats.iteration = iteration_;
  stats.global_step = global_step_;
  return stats;
}

void PPO::sample_actions(int t) {
  const int N = buf_.N, A = buf_.act_dim;
  float* obs = buf_.obs_at(t);
  float* act = buf_.actions_at(t);
  actor_copy_.forward(obs, N, mean_.data());
  for (int i = 0; i < N; ++i) {
    float* a = act + size_t(i) * A;
    const float* mu = &mean_[size_t(i) * A];
    float* eps = &noise_[size_t(i) * A];
    if (noise_age_[i]++ % cfg_.noise_repeat == 0)
      for (int j = 0; j < A; ++j) eps[j] = static_cast<float>(env_rng_[i].normal());
    for (int j = 0; j < A; ++j) a[j] = mu[j] + std::exp(log_std_[j]) * eps[j];
    buf_.log_probs[size_t(t) * N + i] = static_cast<float>(gaussian_log_prob(a, mu, log_std_.data(), A));
  }
}

void PPO::collect_rollout(IterationStats& stats) {
  const int T = buf_.T, N = buf_.N, D = buf_.obs_dim, I = buf_.in_dim;
  buf_.truncated_index.clear();
  buf_.truncated_obs.clear();
  envs_.finished().clear();
  for (int t = 0; t < T; ++t) {
    std::copy(envs_.obs(), envs_.obs() + size_t(N) * D, buf_.raw_obs_at(t));
    for (int i = 0; i < N; ++i)
      net_input(buf_.raw_obs_at(t) + size_t(i) * D, buf_.obs_at(t) + size_t(i) * I);
    sample_actions(t);
    envs_.step(buf_.actions_at(t));
    std::copy(envs_.obs(), envs_.obs() + size_t(N) * D, buf_.next_raw_obs_at(t));
    for (int i = 0; i < N; ++i) {
      size_t k = size_t(t) * N + i;
      if (envs_.terminated()[i] || envs_.truncated()[i])  // obs() already holds the next episode's start
        std::copy(envs_.final_obs() + size_t(i) * D, envs_.final_obs() + size_t(i + 1) * D,
                  buf_.next_raw_obs_at(t) + size_t(i) * D);
      buf_.raw_rewards[k] = envs_.reward()[i];
      buf_.dones[k] = envs_.terminated()[i] || envs_.truncated()[i];
      if (buf_.dones[k]) noise_age_[i] = 0;
      if (envs_.truncated()[i] && !envs_.terminated()[i]) {
        buf_.truncated_index.push_back(static_cast<int>(k));
        buf_.truncated_obs.resize(buf_.truncated_obs.size() + I);
        net_input(envs_.final_obs() + size_t(i) * D, &buf_.truncated_obs[buf_.truncated_obs.size() - I]);
      }
    }
  }
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

  if (reward_hook_) reward_hook_(buf_);
  // The scale of rewards: the std of the discounted return, tracked per environment and
  // pooled over the rollout (and the ranks).
  for (int t = 0; t < T; ++t)
    for (int i = 0; i < N; ++i) {
      size_t k = size_t(t) * N + i;
      double r = buf_.raw_rewards[k];
      buf_.rewards[k] = static_cast<float>(r);
      running_return_[i] = running_return_[i] * cfg_.gamma + r;
      return_samples_[k] = static_cast<float>(running_return_[i]);
      if (buf_.dones[k]) running_return_[i] = 0.0;
    }
  return_rms_.update(return_samples_.data(), int64_t(T) * N, &group_);
  if (cfg_.normalize_reward) {
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
      buf_.rewards[buf_.truncated_index[j]] += static_cast<float>(cfg_.gamma * tv[j].item<float>());
  }
  compute_gae(buf_.rewards, buf_.values, buf_.dones, last_values, T, N, cfg_.gamma, cfg_.lambda,
              buf_.advantages, buf_.returns);
  // The normaliser learns from this rollout only after the policy has used it.
  obs_rms_.update(buf_.raw_obs.data(), int64_t(T) * N, &group_);
}

void PPO::update(IterationStats& stats) {
  const int64_t T = buf_.T, N = buf_.N, first = envs_.first_index();
  const int64_t M = T * global_envs_;  // rows of the whole rollout, every rank's
  const int64_t mb = std::min<int64_t>(cfg_.minibatch_size, M);
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
  std::vector<torch::Tensor> minibatch, advs;  // this rank's rows of each minibatch of an epoch, their A
  std::vector<double> rows, moments;      // each minibatch's rows over every rank; sum and sum of squares of A
  for (int epoch = 0; epoch < cfg_.epochs; ++epoch) {
    auto perm = torch::randperm(M, torch::kLong);
    minibatch.clear(), advs.clear(), rows.clear(), moments.clear();
    for (int64_t start = 0; start < M; start += mb) {
      auto idx = perm.slice(0, start, std::min(start + mb, M));
      rows.push_back(double(idx.numel()));
      if (!group_.single()) {
        // Row t * global_envs + e of the whole rollout is row t * N + (e - first) here.
        auto t = idx.div(global_envs_, "floor"), e = idx.remainder(global_envs_) - first;
        idx = (t * N + e).masked_select((e >= 0) & (e < N));
      }
      auto a = adv.index_select(0, idx).to(torch::kFloat64);
      moments.push_back(a.sum().item<double>());
      moments.push_back(a.pow(2).sum().item<double>());
      minibatch.push_back(idx);
      advs.push_back(a);
    }
    // Advantages are normalised over each whole minibatch, every rank's rows: one
    // exchange per epoch.
    group_.sum(moments.data(), moments.size());
    for (size_t j = 0; j < minibatch.size(); ++j) {
      const torch::Tensor& idx = minibatch[j];
      const double n = rows[j], mean = moments[2 * j] / n;
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
  refresh_inference_copy();
}

torch::Tensor PPO::log_prob(const float* raw_obs, const float* actions, int64_t n) {
  const int D = buf_.obs_dim, I = buf_.in_dim;
  auto obs = torch::empty({n, I});
  for (int64_t i = 0; i < n; ++i) net_input(raw_obs + i * D, obs.data_ptr<float>() + i * I);
  torch::NoGradGuard no_grad;
  auto act = torch::from_blob(const_cast<float*>(actions), {n, int64_t(buf_.act_dim)});
  return net_->log_prob(net_->mean(obs), act);
}

void PPO::init_actor(const Policy& p) {
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

void PPO::set_action_bias(int dim, float bias) {
  if (dim < 0 || dim >= buf_.act_dim) throw Error("set_action_bias: no action dimension " + std::to_string(dim));
  torch::nn::LinearImpl* last = nullptr;  // the output layer: the actor's last Linear
  for (auto& m : net_->actor->modules(/*include_self=*/false))
    if (auto* linear = m->as<torch::nn::Linear>()) last = linear;
  torch::NoGradGuard no_grad;
  last->bias[dim].fill_(bias);
  refresh_inference_copy();
}

Policy PPO::policy() const {
  const auto& spec = envs_.spec();
  return Policy(actor_copy_, std::vector<float>(obs_rms_.mean().begin(), obs_rms_.mean().end()),
                obs_rms_.inv_std(), static_cast<float>(obs_rms_.clip()), spec.act_low, spec.act_high,
                net_->spec.features);
}

// ---- checkpoints -------------------------------------------------------------------

namespace {

std::string key(std::string name) {
  for (auto& c : name)
    if (c == '.') c = '_';
  return "ac_" + name;
}
torch::Tensor ints(const std::vector<int64_t>& v) { return torch::tensor(v, torch::kLong); }
std::vector<int64_t> widen(const std::vector<int>& v) { return {v.begin(), v.end()}; }
// The periodic features, if any (older checkpoints have none).
void write_features(torch::serialize::OutputArchive& ar, const ObsFeatures& f) {
  if (f.empty()) return;
  ar.write("meta_feature_inputs", ints(widen(f.inputs)));
  ar.write("meta_feature_periods", torch::tensor(f.periods, torch::kFloat64));
}
ObsFeatures read_features(torch::serialize::InputArchive& ar) {
  ObsFeatures f;
  torch::Tensor in, per;
  if (!ar.try_read("meta_feature_inputs", in)) return f;
  ar.read("meta_feature_periods", per);
  f.inputs = to_ints(in);
  f.periods = to_doubles(per);
  return f;
}

}  // namespace

// The environments' episodes in flight with the trainer's per-environment state (action
// noise, its age, the discounted return), as one rank holds them or as a checkpoint does.
struct PPO::InFlight {
  std::vector<double> state, running_return;
  std::string rngs;
  std::vector<float> noise;
  std::vector<int64_t> noise_age;

  void append(const InFlight& o) {
    state.insert(state.end(), o.state.begin(), o.state.end());
    rngs += o.rngs;
    noise.insert(noise.end(), o.noise.begin(), o.noise.end());
    noise_age.insert(noise_age.end(), o.noise_age.begin(), o.noise_age.end());
    running_return.insert(running_return.end(), o.running_return.begin(), o.running_return.end());
  }
  void write(torch::serialize::OutputArchive& ar) const {
    ar.write("episodes_state", torch::tensor(state, torch::kFloat64));
    ar.write("episodes_rng", text_tensor(rngs));
    ar.write("episodes_noise", torch::tensor(noise));
    ar.write("episodes_noise_age", torch::tensor(noise_age));
    ar.write("episodes_running_return", torch::tensor(running_return, torch::kFloat64));
  }
  bool read(torch::serialize::InputArchive& ar) {
    torch::Tensor s, r, n, a, ret;
    if (!(ar.try_read("episodes_state", s) && ar.try_read("episodes_rng", r) && ar.try_read("episodes_noise", n) &&
          ar.try_read("episodes_noise_age", a) && ar.try_read("episodes_running_return", ret)))
      return false;
    state = to_doubles(s), rngs = to_text(r), noise = to_floats(n), noise_age = to_int64s(a);
    running_return = to_doubles(ret);
    return true;
  }
  std::string bytes() const {
    torch::serialize::OutputArchive ar;
    write(ar);
    std::ostringstream out;
    ar.save_to(out);
    return out.str();
  }
  static InFlight from_bytes(const std::string& b) {
    torch::serialize::InputArchive ar;
    std::istringstream in(b);
    ar.load_from(in);
    InFlight f;
    f.read(ar);
    return f;
  }
};

void PPO::save(const std::string& path, const std::string& note, const ArchiveWriter& extra) const {
  torch::serialize::OutputArchive ar;
  if (extra) extra(ar);
  for (const auto& p : net_->named_parameters()) ar.write(key(p.key()), p.value().detach());
  torch::serialize::OutputArchive opt;
  optimizer_->save(opt);
  ar.write("optimizer", opt);
  obs_rms_.save(ar, "obs_rms_");
  return_rms_.save(ar, "return_rms_");
  const auto& s = net_->spec;
  ar.write("meta_counters", ints({iteration_, global_step_, int64_t(wall_seconds_ * 1000), schedule_start_}));
  ar.write("meta_dims", ints({s.obs_dim, s.act_dim, s.activation == Activation::Tanh ? 0 : 1}));
  ar.write("meta_pi_hidden", ints(widen(s.pi_hidden)));
  ar.write("meta_vf_hidden", ints(widen(s.vf_hidden)));
  write_features(ar, s.features);
  ar.write("meta_act_low", torch::tensor(envs_.spec().act_low));
  ar.write("meta_act_high", torch::tensor(envs_.spec().act_high));
  ar.write("meta_note", text_tensor(note));
  // The episodes in flight, every rank's, in environment order.
  InFlight mine;
  const bool saved = envs_.save_episodes(mine.state, mine.rngs);
  if (!group_.any(!saved)) {
    mine.noise = noise_;
    mine.noise_age.assign(noise_age_.begin(), noise_age_.end());
    mine.running_return = running_return_;
    InFlight all;
    for (const std::string& part : group_.gather(group_.single() ? std::string() : mine.bytes()))
      all.append(group_.single() ? mine : InFlight::from_bytes(part));
    all.write(ar);
  }
  if (!group_.leader()) return;
  std::ostringstream bytes;
  ar.save_to(bytes);
  write_file_atomic(path, bytes.str());
}

void PPO::load(const std::string& path, const ArchiveReader& extra, bool resume_episodes) {
  // Rank 0 reads the file and every rank loads its bytes (other hosts need not see it).
  const std::string kFailed = "\x01segue: unreadable\n";
  std::string bytes;
  if (group_.leader()) {
    try {
      bytes = read_file(path);
    } catch (const Error& e) {
      bytes = kFailed + e.what();
    }
  }
  bytes = group_.broadcast(bytes);
  if (bytes.rfind(kFailed, 0) == 0) throw Error(bytes.substr(kFailed.size()));
  torch::serialize::InputArchive ar;
  InFlight saved;
  bool in_flight = false;
  try {
    std::istringstream in(bytes);
    ar.load_from(in);
    if (extra) extra(ar);
    read_state(ar, path);
    in_flight = resume_episodes && saved.read(ar);
  } catch (const c10::Error& e) {
    std::string what = e.what_without_backtrace();
    throw Error(path + ": unreadable checkpoint: " + what.substr(0, what.find('\n')));
  }
  refresh_inference_copy();
  const int A = buf_.act_dim, first = envs_.first_index(), N = envs_.size();
  if (in_flight && int64_t(saved.noise.size()) == global_envs_ * A) {
    try {
      std::vector<double> state;
      std::string rngs;
      VectorEnv::slice_episodes(saved.state, saved.rngs, first, N, state, rngs);
      envs_.restore_episodes(state, rngs);
      noise_.assign(saved.noise.begin() + size_t(first) * A, saved.noise.begin() + size_t(first + N) * A);
      noise_age_.assign(saved.noise_age.begin() + first, saved.noise_age.begin() + first + N);
      running_return_.assign(saved.running_return.begin() + first, saved.running_return.begin() + first + N);
      return;
    } catch (const Error& e) {
      throw Error(path + ": " + e.what());
    }
  }
  // Episodes in flight cannot be put back (or this continues another run): start fresh
  // ones, seeded by position.
  envs_.reset(mix_seed(seed_, 0x10000 + iteration_));
  running_return_.assign(envs_.size(), 0.0);
}

void PPO::read_state(torch::serialize::InputArchive& ar, const std::string& path) {
  torch::Tensor dims;
  if (!ar.try_read("meta_dims", dims))
    throw Error(path + ": not a training checkpoint (an exported policy? a run starts from one with init_policy)");
  const int64_t obs = dims[0].item<int64_t>(), act = dims[1].item<int64_t>();
  if (obs != net_->spec.obs_dim || act != net_->spec.act_dim)
    throw Error(path + ": the checkpoint's policy takes obs_dim " + std::to_string(obs) + " / act_dim " +
                std::to_string(act) + ", the task " + std::to_string(net_->spec.obs_dim) + " / " +
                std::to_string(net_->spec.act_dim));
  if (!(read_features(ar) == net_->spec.features))
    throw Error(path + ": checkpoint's policy.fourier features differ from the recipe's");
  torch::NoGradGuard no_grad;
  for (auto& p : net_->named_parameters()) {
    torch::Tensor t;
    ar.read(key(p.key()), t);
    if (t.sizes() != p.value().sizes())
      throw Error(path + ": parameter '" + p.key() + "' has another shape than the recipe's network");
    p.value().copy_(t);
  }
  torch::serialize::InputArchive opt;
  ar.read("optimizer", opt);
  optimizer_->load(opt);
  obs_rms_.load(ar, "obs_rms_");
  return_rms_.load(ar, "return_rms_");
  torch::Tensor counters;
  ar.read("meta_counters", counters);
  iteration_ = counters[0].item<int64_t>();
  global_step_ = counters[1].item<int64_t>();
  wall_seconds_ = counters[2].item<int64_t>() / 1000.0;
  schedule_start_ = counters.numel() > 3 ? counters[3].item<int64_t>() : 0;  // older checkpoints: 0
}

Policy PPO::policy_from_checkpoint(const std::string& path) {
  torch::serialize::InputArchive ar;
  ar.load_from(path);
  torch::Tensor dims, pi, vf, low, high;
  ar.read("meta_dims", dims);
  ar.read("meta_pi_hidden", pi);
  ar.read("meta_vf_hidden", vf);
  ar.read("meta_act_low", low);
  ar.read("meta_act_high", high);
  ActorCriticSpec spec;
  spec.obs_dim = static_cast<int>(dims[0].item<int64_t>());
  spec.act_dim = static_cast<int>(dims[1].item<int64_t>());
  spec.activation = dims[2].item<int64_t>() == 0 ? Activation::Tanh : Activation::Relu;
  spec.pi_hidden = to_ints(pi);
  spec.vf_hidden = to_ints(vf);
  spec.features = read_features(ar);
  ActorCritic net(spec);
  torch::NoGradGuard no_grad;
  for (auto& p : net->named_parameters()) {
    torch::Tensor t;
    ar.read(key(p.key()), t);
    p.value().copy_(t);
  }
  RunningMeanStd rms(spec.obs_dim);
  rms.load(ar, "obs_rms_");
  return Policy(EigenMlp(net->actor, spec.activation),
                std::vector<float>(rms.mean().begin(), rms.mean().end()), rms.inv_std(),
                static_cast<float>(rms.clip()), to_floats(low), to_floats(high), spec.features);
}

}  // namespace segue
