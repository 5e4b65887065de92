#include "algorithms/sac.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/run_dir.h"

namespace segue {

SacConfig SacConfig::read(const Section& s) {
  SacConfig c;
  c.total_steps = s.get("total_steps", c.total_steps, Range::positive());
  c.num_envs = s.get("num_envs", c.num_envs, Range::closed(1, 4096));
  c.steps_per_iteration = s.get("steps_per_iteration", c.steps_per_iteration, Range::positive());
  c.update_every = s.get("update_every", c.update_every, Range::positive());
  c.start_steps = s.get("start_steps", c.start_steps, Range::non_negative());
  c.update_after = s.get("update_after", c.update_after, Range::non_negative());
  c.buffer_size = s.get("buffer_size", c.buffer_size, Range::closed(1, 100'000'000));
  c.batch_size = s.get("batch_size", c.batch_size, Range::closed(1, 1'000'000));
  c.gamma = s.get("gamma", c.gamma, Range::open_closed(0, 1));
  c.tau = s.get("tau", c.tau, Range::open_closed(0, 1));
  c.lr = s.get("lr", c.lr, Range::positive());
  c.init_alpha = s.get("init_alpha", c.init_alpha, Range::positive());
  c.tune_alpha = s.get("tune_alpha", c.tune_alpha);
  if (c.update_every % c.num_envs != 0)
    throw s.error("update_every", "must be a multiple of num_envs (" + std::to_string(c.num_envs) + ")");
  if (c.steps_per_iteration % c.update_every != 0)
    throw s.error("steps_per_iteration", "must be a multiple of update_every (" + std::to_string(c.update_every) + ")");
  return c;
}

torch::Tensor soft_q_target(const torch::Tensor& reward, const torch::Tensor& terminal, const torch::Tensor& q1_next,
                            const torch::Tensor& q2_next, const torch::Tensor& logp_next, double alpha, double gamma) {
  return reward + gamma * (1.0 - terminal) * (torch::min(q1_next, q2_next) - alpha * logp_next);
}

namespace {

void copy_parameters(const torch::nn::Sequential& from, torch::nn::Sequential& to) {
  torch::NoGradGuard no_grad;
  auto src = from->parameters(), dst = to->parameters();
  for (size_t i = 0; i < src.size(); ++i) dst[i].copy_(src[i]);
}


// The actor's mean head as an EigenMlp: its last layer's first act_dim rows.
EigenMlp mean_head(const torch::nn::Sequential& actor, int act_dim, Activation act) {
  std::vector<torch::Tensor> ws, bs;
  for (auto& m : actor->modules(/*include_self=*/false))
    if (auto* linear = m->as<torch::nn::Linear>()) ws.push_back(linear->weight.detach()), bs.push_back(linear->bias.detach());
  ws.back() = ws.back().narrow(0, 0, act_dim);
  bs.back() = bs.back().narrow(0, 0, act_dim);
  return EigenMlp(ws, bs, act);
}

Policy squashed_policy(const torch::nn::Sequential& actor, int obs_dim, int act_dim, Activation act,
                       const std::vector<int>& ignore, std::vector<float> low, std::vector<float> high) {
  std::vector<float> mean(obs_dim, 0.0f), inv_std(obs_dim, 1.0f);
  if (!ignore.empty())
    for (int j = ignore[0]; j < ignore[1]; ++j) inv_std[j] = 0.0f;
  // Inputs go in raw (no normaliser): the clip is wide enough never to bind.
  Policy p(mean_head(actor, act_dim, act), mean, inv_std, 1e30f, std::move(low), std::move(high));
  p.set_tanh_output(true);
  return p;
}

}  // namespace

SAC::SAC(const SacConfig& config, const ActorCriticSpec& net, VectorEnv& envs, uint64_t seed)
    : cfg_(config), spec_(net), envs_(envs), seed_(seed), replay_(config.buffer_size, net.obs_dim, net.act_dim) {
  if (envs.size() != cfg_.num_envs)
    throw Error("SAC: " + std::to_string(envs.size()) + " environments, sac.num_envs is " + std::to_string(cfg_.num_envs));
  if (!net.features.empty()) throw Error("SAC: policy.fourier is not supported");
  torch::manual_seed(mix_seed(seed, 0x5ac));
  const int obs = net.obs_dim, act = net.act_dim;
  actor_ = make_mlp(obs, net.pi_hidden, 2 * act, net.activation, 0.01);
  q1_ = make_mlp(obs + act, net.vf_hidden, 1, net.activation, 1.0);
  q2_ = make_mlp(obs + act, net.vf_hidden, 1, net.activation, 1.0);
  q1_target_ = make_mlp(obs + act, net.vf_hidden, 1, net.activation, 1.0);
  q2_target_ = make_mlp(obs + act, net.vf_hidden, 1, net.activation, 1.0);
  copy_parameters(q1_, q1_target_);
  copy_parameters(q2_, q2_target_);
  log_alpha_ = torch::full({1}, std::log(cfg_.init_alpha)).requires_grad_(true);
  actor_opt_ = std::make_unique<torch::optim::Adam>(actor_->parameters(), torch::optim::AdamOptions(cfg_.lr));
  auto qs = q1_->parameters();
  for (const auto& p : q2_->parameters()) qs.push_back(p);
  q_opt_ = std::make_unique<torch::optim::Adam>(qs, torch::optim::AdamOptions(cfg_.lr));
  alpha_opt_ = std::make_unique<torch::optim::Adam>(std::vector<torch::Tensor>{log_alpha_},
                                                    torch::optim::AdamOptions(cfg_.lr));
  target_entropy_ = -double(act);
  const int n = envs.size();
  input_.resize(size_t(n) * obs), next_input_.resize(size_t(n) * obs), head_.resize(size_t(n) * 2 * act);
  actions_unit_.resize(size_t(n) * act), actions_env_.resize(size_t(n) * act);
  env_rng_.resize(n);
  ignored_.assign(obs, 0);
  if (!net.ignore_obs.empty())
    for (int j = net.ignore_obs[0]; j < net.ignore_obs[1]; ++j) ignored_[j] = 1;
  envs_.reset(mix_seed(seed, 0));
  refresh_inference_copy();
}

void SAC::masked(const float* raw, float* out) const {
  for (size_t j = 0; j < ignored_.size(); ++j) out[j] = ignored_[j] ? 0.0f : raw[j];
}

void SAC::refresh_inference_copy() { actor_copy_ = EigenMlp(actor_, spec_.activation); }

std::pair<torch::Tensor, torch::Tensor> SAC::sample(const torch::Tensor& obs) {
  const int64_t a = spec_.act_dim;
  auto out = actor_->forward(obs);
  auto mu = out.narrow(1, 0, a), log_std = out.narrow(1, a, a).clamp(-20.0, 2.0);
  auto eps = torch::randn_like(mu);
  auto u = mu + torch::exp(log_std) * eps;
  // log N(u; mu, sigma) minus log |d tanh(u)/du| = log(1 - tanh(u)^2) = 2 (log 2 - u - softplus(-2u)).
  auto logp = (-0.5 * eps.pow(2) - log_std - 0.5 * std::log(2.0 * M_PI)).sum(1) -
              (2.0 * (std::log(2.0) - u - torch::softplus(-2.0 * u))).sum(1);
  return {torch::tanh(u), logp};
}

torch::Tensor SAC::q(torch::nn::Sequential& net, const torch::Tensor& obs, const torch::Tensor& act) {
  return net->forward(torch::cat({obs, act}, 1)).squeeze(-1);
}

SAC::UpdateStats SAC::update(const ReplayBuffer::Batch& b) {
  const double alpha = this->alpha();
  torch::Tensor y;
  {
    torch::NoGradGuard no_grad;
    auto [next_act, next_logp] = sample(b.next_obs);
    y = soft_q_target(b.reward, b.terminal, q(q1_target_, b.next_obs, next_act), q(q2_target_, b.next_obs, next_act),
                      next_logp, alpha, cfg_.gamma);
  }
  auto q1v = q(q1_, b.obs, b.act), q2v = q(q2_, b.obs, b.act);
  auto q_loss = (q1v - y).pow(2).mean() + (q2v - y).pow(2).mean();
  q_opt_->zero_grad();
  q_loss.backward();
  q_opt_->step();

  // The actor's loss passes through the Q networks; gradients for their weights would be
  // cleared unused before the next Q step, so they are not computed.
  for (auto* net : {&q1_, &q2_})
    for (auto& w : (*net)->parameters()) w.requires_grad_(false);
  auto [act, logp] = sample(b.obs);
  auto pi_loss = (alpha * logp - torch::min(q(q1_, b.obs, act), q(q2_, b.obs, act))).mean();
  actor_opt_->zero_grad();
  pi_loss.backward();
  actor_opt_->step();
  for (auto* net : {&q1_, &q2_})
    for (auto& w : (*net)->parameters()) w.requires_grad_(true);

  if (cfg_.tune_alpha) {
    auto alpha_loss = -(log_alpha_ * (logp.detach() + target_entropy_)).mean();
    alpha_opt_->zero_grad();
    alpha_loss.backward();
    alpha_opt_->step();
  }
  {
    torch::NoGradGuard no_grad;
    for (auto [net, target] : {std::pair{&q1_, &q1_target_}, std::pair{&q2_, &q2_target_}}) {
      auto src = (*net)->parameters(), dst = (*target)->parameters();
      for (size_t i = 0; i < src.size(); ++i) dst[i].mul_(1.0 - cfg_.tau).add_(src[i], cfg_.tau);
    }
  }
  const double ql = q_loss.item<double>();
  if (!std::isfinite(ql))
    throw Error("SAC's Q loss became " + std::to_string(ql) + " at iteration " + std::to_string(iteration_ + 1) +
                " (task '" + envs_.spec().name + "'); the last checkpoint is kept: lower sac.lr or check the rewards");
  return {ql, pi_loss.item<double>(), -logp.mean().item<double>(), q1v.mean().item<double>()};
}

void SAC::collect(int steps_per_env) {
  const int n = envs_.size(), d = spec_.obs_dim, a = spec_.act_dim;
  const auto& low = envs_.spec().act_low;
  const auto& high = envs_.spec().act_high;
  for (int t = 0; t < steps_per_env; ++t) {
    for (int i = 0; i < n; ++i) masked(envs_.obs() + size_t(i) * d, &input_[size_t(i) * d]);
    const bool random = global_step_ < cfg_.start_steps;
    if (!random) actor_copy_.forward(input_.data(), n, head_.data());
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < a; ++j) {
        float& u = actions_unit_[size_t(i) * a + j];
        if (random) {
          u = float(env_rng_[i].uniform(-1.0, 1.0));
        } else {
          const float* h = &head_[size_t(i) * 2 * a];
          const double log_std = std::clamp(double(h[a + j]), -20.0, 2.0);
          u = float(std::tanh(h[j] + std::exp(log_std) * env_rng_[i].normal()));
        }
        actions_env_[size_t(i) * a + j] = low[j] + 0.5f * (u + 1.0f) * (high[j] - low[j]);
      }
    envs_.step(actions_env_.data());
    for (int i = 0; i < n; ++i) {
      const bool ended = envs_.terminated()[i] || envs_.truncated()[i];
      masked((ended ? envs_.final_obs() : envs_.obs()) + size_t(i) * d, &next_input_[size_t(i) * d]);
      replay_.add(&input_[size_t(i) * d], &actions_unit_[size_t(i) * a], envs_.reward()[i],
                  &next_input_[size_t(i) * d], envs_.terminated()[i]);
    }
    global_step_ += n;
  }
}

IterationStats SAC::iterate() {
  IterationStats stats;
  // Per-iteration seeds: a resumed run draws what the unbroken one does.
  const uint64_t noise_seed = mix_seed(seed_, 3 * iteration_ + 1);
  for (int i = 0; i < envs_.size(); ++i) env_rng_[i].seed(mix_seed(noise_seed, uint64_t(i)));
  torch::manual_seed(mix_seed(seed_, 3 * iteration_ + 2));
  Rng rows(mix_seed(seed_, 3 * iteration_ + 3));
  envs_.finished().clear();
  double sums[4] = {0, 0, 0, 0};
  int updates = 0;
  double rollout = 0, learn = 0;
  std::vector<int64_t> idx(cfg_.batch_size);
  for (int round = 0; round < cfg_.steps_per_iteration / cfg_.update_every; ++round) {
    auto t0 = std::chrono::steady_clock::now();
    collect(cfg_.update_every / envs_.size());
    auto t1 = std::chrono::steady_clock::now();
    if (replay_.size() >= std::max<int64_t>(cfg_.update_after, 1)) {
      for (int k = 0; k < cfg_.update_every; ++k) {
        for (auto& i : idx) i = rows.integer(0, int(replay_.size() - 1));
        const UpdateStats u = update(replay_.gather(idx));
        sums[0] += u.q_loss, sums[1] += u.pi_loss, sums[2] += u.entropy, sums[3] += u.q_mean;
        ++updates;
      }
      refresh_inference_copy();
    }
    rollout += std::chrono::duration<double>(t1 - t0).count();
    learn += std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  }
  const auto& done = envs_.finished();
  stats.episodes = int(done.size());
  if (!done.empty()) {
    double ret = 0, len = 0, succ = 0, count = 0;
    for (const auto& e : done) ret += e.ret, len += e.length, succ += e.success, count += e.success_count;
    const double k = double(done.size());
    stats.episode_return = ret / k, stats.episode_length = len / k, stats.success_rate = succ / k;
    stats.success_count = count / k;
  }
  if (updates > 0)
    stats.value_loss = sums[0] / updates, stats.policy_loss = sums[1] / updates, stats.entropy = sums[2] / updates,
    stats.q_mean = sums[3] / updates;
  stats.alpha = alpha();
  stats.rollout_seconds = rollout, stats.update_seconds = learn;
  ++iteration_;
  wall_seconds_ += rollout + learn;
  stats.iteration = iteration_, stats.global_step = global_step_;
  return stats;
}

Policy SAC::policy() const {
  const auto& spec = envs_.spec();
  return squashed_policy(actor_, spec_.obs_dim, spec_.act_dim, spec_.activation, spec_.ignore_obs, spec.act_low,
                         spec.act_high);
}

// ---- checkpoints -------------------------------------------------------------------

namespace {

void write_net(torch::serialize::OutputArchive& ar, const std::string& name, const torch::nn::Sequential& net) {
  for (const auto& p : net->named_parameters()) {
    std::string key = name + "_" + p.key();
    std::replace(key.begin(), key.end(), '.', '_');
    ar.write(key, p.value().detach());
  }
}
void read_net(torch::serialize::InputArchive& ar, const std::string& name, torch::nn::Sequential& net,
              const std::string& path) {
  torch::NoGradGuard no_grad;
  for (auto& p : net->named_parameters()) {
    std::string key = name + "_" + p.key();
    std::replace(key.begin(), key.end(), '.', '_');
    torch::Tensor t;
    ar.read(key, t);
    if (t.sizes() != p.value().sizes())
      throw Error(path + ": parameter '" + key + "' has another shape than the recipe's network");
    p.value().copy_(t);
  }
}
void write_optimizer(torch::serialize::OutputArchive& ar, const std::string& name, const torch::optim::Optimizer& o) {
  torch::serialize::OutputArchive sub;
  o.save(sub);
  ar.write(name, sub);
}
void read_optimizer(torch::serialize::InputArchive& ar, const std::string& name, torch::optim::Optimizer& o) {
  torch::serialize::InputArchive sub;
  ar.read(name, sub);
  o.load(sub);
}

}  // namespace

void SAC::write(torch::serialize::OutputArchive& ar) const {
  write_net(ar, "actor", actor_);
  write_net(ar, "q1", q1_), write_net(ar, "q2", q2_);
  write_net(ar, "q1_target", q1_target_), write_net(ar, "q2_target", q2_target_);
  ar.write("log_alpha", log_alpha_.detach());
  write_optimizer(ar, "actor_optimizer", *actor_opt_);
  write_optimizer(ar, "q_optimizer", *q_opt_);
  write_optimizer(ar, "alpha_optimizer", *alpha_opt_);
  replay_.save(ar);
  ar.write("meta_learner", text_tensor(name_));
  ar.write("meta_counters", int64_tensor({iteration_, global_step_, int64_t(wall_seconds_ * 1000)}));
  ar.write("meta_dims", int64_tensor({spec_.obs_dim, spec_.act_dim, spec_.activation == Activation::Tanh ? 0 : 1}));
  ar.write("meta_pi_hidden", int_tensor(spec_.pi_hidden));
  ar.write("meta_vf_hidden", int_tensor(spec_.vf_hidden));
  ar.write("meta_ignore_obs", int_tensor(spec_.ignore_obs));
  ar.write("meta_act_low", torch::tensor(envs_.spec().act_low));
  ar.write("meta_act_high", torch::tensor(envs_.spec().act_high));
}

void SAC::save(const std::string& path, const std::string& note) const {
  torch::serialize::OutputArchive ar;
  write(ar);
  ar.write("meta_note", text_tensor(note));
  std::vector<double> state;
  std::string rngs;
  if (envs_.save_episodes(state, rngs)) {
    ar.write("episodes_state", torch::tensor(state, torch::kFloat64));
    ar.write("episodes_rng", text_tensor(rngs));
  }
  std::ostringstream bytes;
  ar.save_to(bytes);
  write_file_atomic(path, bytes.str());
}

void SAC::load_checkpoint(const std::string& path, bool resume) {
  torch::serialize::InputArchive ar;
  torch::Tensor learner, dims, counters, alpha, state, rngs;
  try {
    ar.load_from(path);
    if (!ar.try_read("meta_dims", dims))
      throw Error(path + ": not a training checkpoint (an exported policy?)");
    const std::string saved_by = ar.try_read("meta_learner", learner) ? to_text(learner) : "ppo";
    if (saved_by != name_)
      throw Error(path + ": the run was trained with learner '" + saved_by + "', the recipe says 'sac'");
    if (dims[0].item<int64_t>() != spec_.obs_dim || dims[1].item<int64_t>() != spec_.act_dim)
      throw Error(path + ": the checkpoint's policy takes obs_dim " + std::to_string(dims[0].item<int64_t>()) +
                  " / act_dim " + std::to_string(dims[1].item<int64_t>()) + ", the task " +
                  std::to_string(spec_.obs_dim) + " / " + std::to_string(spec_.act_dim));
    read_net(ar, "actor", actor_, path);
    read_net(ar, "q1", q1_, path), read_net(ar, "q2", q2_, path);
    read_net(ar, "q1_target", q1_target_, path), read_net(ar, "q2_target", q2_target_, path);
    ar.read("log_alpha", alpha);
    {
      torch::NoGradGuard no_grad;
      log_alpha_.copy_(alpha);
    }
    read_optimizer(ar, "actor_optimizer", *actor_opt_);
    read_optimizer(ar, "q_optimizer", *q_opt_);
    read_optimizer(ar, "alpha_optimizer", *alpha_opt_);
    try {
      replay_.load(ar);
    } catch (const Error& e) {
      throw Error(std::string(e.what()) + " (sac.buffer_size)");
    }
    ar.read("meta_counters", counters);
    iteration_ = counters[0].item<int64_t>(), global_step_ = counters[1].item<int64_t>();
    wall_seconds_ = counters[2].item<int64_t>() / 1000.0;
    if (resume && ar.try_read("episodes_state", state) && ar.try_read("episodes_rng", rngs)) {
      envs_.restore_episodes(to_doubles(state), to_text(rngs));
    } else {
      envs_.reset(mix_seed(seed_, 0x10000 + iteration_));
    }
  } catch (const c10::Error& e) {
    std::string what = e.what_without_backtrace();
    throw Error(path + ": unreadable checkpoint: " + what.substr(0, what.find('\n')));
  } catch (const Error& e) {
    const std::string what = e.what();
    throw Error(what.rfind(path, 0) == 0 ? what : path + ": " + what);
  }
  refresh_inference_copy();
}

Policy SAC::policy_from_checkpoint(torch::serialize::InputArchive& ar, const std::string& path) {
  torch::Tensor dims, pi, ignore, low, high;
  ar.read("meta_dims", dims);
  ar.read("meta_pi_hidden", pi);
  ar.read("meta_ignore_obs", ignore);
  ar.read("meta_act_low", low);
  ar.read("meta_act_high", high);
  const int obs = int(dims[0].item<int64_t>()), act = int(dims[1].item<int64_t>());
  const Activation activation = dims[2].item<int64_t>() == 0 ? Activation::Tanh : Activation::Relu;
  auto actor = make_mlp(obs, to_ints(pi), 2 * act, activation, 0.01);
  read_net(ar, "actor", actor, path);
  return squashed_policy(actor, obs, act, activation, to_ints(ignore), to_floats(low), to_floats(high));
}

}  // namespace segue
