#include "hrl/switch_training.h"

#include <ATen/CPUGeneratorImpl.h>

#include <algorithm>
#include <cstring>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>

#include "core/run_dir.h"

namespace segue {

bool run_subtask(Env& env, TransitionController& after, int to, float* obs, int lookahead, int max_steps,
                 int64_t* steps) {
  std::vector<float> act(env.spec().act_dim);
  after.resume(env, to);
  int begun = 0;
  for (int step = 0; step < max_steps; ++step) {
    after.act(env, obs, act.data());
    if (after.entered() >= 0 && ++begun == lookahead) return true;  // a transition began
    StepResult sr = env.step(act.data(), obs);
    if (steps) ++*steps;
    if (sr.terminated) return sr.info.success;  // a fall, or the whole task done (the last pick)
    if (sr.truncated) return true;
  }
  return true;
}

SwitchTrainer::SwitchTrainer(const SwitchConfig& config, const CompositeRecipe& recipe, int transition,
                             StartStates starts, Policy pi_ab, std::vector<TransitionArtefacts> trained,
                             uint64_t seed, const Distributed& group)
    : cfg_(config), recipe_(recipe), tr_(recipe.meta.transitions().at(transition)), starts_(std::move(starts)),
      pi_ab_(std::move(pi_ab)), env_(recipe.make_env()),
      after_(recipe.skills, recipe.meta, std::move(trained), SwitchRule::IntervalEnd), group_(group) {
  if (starts_.size() == 0) throw Error("switch training: S_a is empty");
  train_starts_ = starts_.size() - cfg_.validation_starts;
  if (train_starts_ < 1)
    throw Error("switch training: validation_starts (" + std::to_string(cfg_.validation_starts) +
                ") leaves none of S_a's " + std::to_string(starts_.size()) + " states to train on");
  const EnvSpec& spec = env_->spec();
  const int D = spec.obs_dim, I = D + (cfg_.interval_features ? int(spec.feature_names.size()) : 0);
  full_.resize(D), next_full_.resize(D), qvals_.resize(2), in_.resize(I), next_in_.resize(I);
  features_.resize(spec.feature_names.size());
  rng_.seed(seed);
  torch::manual_seed(mix_seed(seed, 0x9));
  SwitchQSpec qs = cfg_.net;
  qs.obs_dim = I + cfg_.features.size();  // q_ab's input: normalised input, then its periodic features
  for (int k = 0; k < cfg_.ensemble; ++k) {
    q_.push_back(SwitchQNetwork(qs));
    target_.push_back(SwitchQNetwork(qs));
    copy_weights(q_[k], target_[k]);
    opt_.push_back(std::make_unique<torch::optim::Adam>(q_[k]->parameters(), torch::optim::AdamOptions(cfg_.lr)));
  }

  // Probe pi_ab through the interval from a few starts: how long the interval lasts (for
  // random attempts) and the scale of the states q_ab will see (its input normaliser).
  const Skill& b = recipe_.skills[tr_.to];
  std::vector<float> act(spec.act_dim);
  std::vector<double> sum(I, 0.0), sq(I, 0.0);
  int64_t rows = 0, steps = 0;
  const int probes = std::min(20, train_starts_);
  for (int p = 0; p < probes; ++p) {
    starts_.state(p, state_);
    env_->restore_state(state_, full_.data());
    env_->features(features_.data());
    for (int t = 0; t < 100000; ++t) {
      q_input(full_.data(), in_.data());
      for (int j = 0; j < I; ++j) sum[j] += in_[j], sq[j] += double(in_[j]) * in_[j];
      ++rows;
      pi_ab_.act(full_.data() + b.obs_begin, 1, act.data());
      StepResult sr = env_->step(act.data(), full_.data());
      env_->features(features_.data());
      ++steps;
      if (sr.done() || !tr_.running(features_.data(), t + 1)) break;
    }
  }
  interval_length_ = std::max<int>(1, int(steps / probes));
  std::vector<float> mean(I), inv_std(I);
  for (int j = 0; j < I; ++j) {
    double m = sum[j] / rows, var = std::max(sq[j] / rows - m * m, 0.0);
    mean[j] = float(m);
    inv_std[j] = float(1.0 / std::max(std::sqrt(var), 1e-2));
  }
  const float inf = std::numeric_limits<float>::infinity();
  q_ab_ = Policy(mean_network(), mean, inv_std, 5.0f, {-inf, -inf}, {inf, inf}, cfg_.features);
  if (!group_.single()) rng_.seed(mix_seed(seed, 0x5317 + uint64_t(group_.rank())));  // each rank its attempts
}

EigenMlp SwitchTrainer::mean_network() const {
  if (q_.size() == 1) return EigenMlp(q_[0]->q, Activation::Relu);
  // Side by side: the first layer stacks the members' rows, hidden layers are
  // block-diagonal, and the output layer averages the members' outputs.
  std::vector<std::vector<torch::Tensor>> w, b;  // [layer][member]
  for (const auto& net : q_) {
    int layer = 0;
    for (const auto& m : net->q->children())
      if (auto* lin = m->as<torch::nn::Linear>()) {
        w.resize(std::max<size_t>(w.size(), layer + 1)), b.resize(w.size());
        w[layer].push_back(lin->weight.detach()), b[layer].push_back(lin->bias.detach());
        ++layer;
      }
  }
  const double K = double(q_.size());
  std::vector<torch::Tensor> ws, bs;
  for (size_t l = 0; l < w.size(); ++l) {
    if (l == 0) ws.push_back(torch::cat(w[l], 0));
    else if (l + 1 < w.size()) ws.push_back(torch::block_diag(w[l]));
    else ws.push_back(torch::cat(w[l], 1) / K);
    bs.push_back(l + 1 < w.size() ? torch::cat(b[l], 0) : torch::stack(b[l]).mean(0));
  }
  return EigenMlp(ws, bs, Activation::Relu);
}

bool SwitchTrainer::hand_over(float* obs) {
  return run_subtask(*env_, after_, tr_.to, obs, cfg_.lookahead, cfg_.max_subtask_steps, &env_steps_);
}

void SwitchTrainer::q_input(const float* obs, float* in) {
  switch_input(obs, int(full_.size()), features_, cfg_.interval_features, in);
}

int SwitchTrainer::greedy(const float* in) {
  q_ab_.act(in, 1, qvals_.data());
  return qvals_[SwitchQNetworkImpl::kSwitch] > qvals_[SwitchQNetworkImpl::kStay] ? SwitchQNetworkImpl::kSwitch
                                                                                 : SwitchQNetworkImpl::kStay;
}

void SwitchTrainer::store(const float* s, int a, double r, const float* s2, bool done) {
  const size_t I = size_t(q_ab_.in_dim());
  // Normalised with q_ab's input statistics, fixed from the probe on (the same on every rank).
  pending_obs_.resize(pending_obs_.size() + I), pending_next_.resize(pending_next_.size() + I);
  q_ab_.normalize(s, 1, &pending_obs_[pending_obs_.size() - I]);
  q_ab_.normalize(s2, 1, &pending_next_[pending_next_.size() - I]);
  if (group_.single()) {
    push(&pending_obs_[0], a, float(r), &pending_next_[0], done ? 1.0f : 0.0f);
    pending_obs_.clear(), pending_next_.clear();
    ++rank0_rows_;
    return;
  }
  pending_action_.push_back(a), pending_reward_.push_back(float(r)), pending_done_.push_back(done ? 1.0f : 0.0f);
}

void SwitchTrainer::push(const float* s, int64_t a, float r, const float* s2, float done) {
  const int I = q_ab_.in_dim();
  const int64_t cap = cfg_.replay, row = stored_ % cap;
  if (stored_ < cap) {
    obs_.resize(size_t(row + 1) * I), next_obs_.resize(size_t(row + 1) * I);
    action_.push_back(0), reward_.push_back(0), done_.push_back(0);
  }
  std::copy(s, s + I, &obs_[row * I]);
  std::copy(s2, s2 + I, &next_obs_[row * I]);
  action_[row] = a, reward_[row] = r, done_[row] = done;
  ++stored_;
}

namespace {
template <class T>
void put(std::string& out, const std::vector<T>& v) {
  const int64_t n = int64_t(v.size());
  out.append(reinterpret_cast<const char*>(&n), sizeof n);
  out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}
template <class T>
std::vector<T> take(const std::string& in, size_t& at) {
  int64_t n = 0;
  std::memcpy(&n, in.data() + at, sizeof n);
  at += sizeof n;
  std::vector<T> v(static_cast<size_t>(n));
  std::memcpy(v.data(), in.data() + at, v.size() * sizeof(T));
  at += v.size() * sizeof(T);
  return v;
}
}  // namespace

void SwitchTrainer::run_round(int round, SwitchStats& s, int& updates) {
  const int rank = group_.rank(), I = q_ab_.in_dim();
  const int64_t steps_before = env_steps_;
  std::vector<double> outcome{0, 0, 0};  // attempted, success, switch step
  const double frac = std::min(1.0, (attempts_ + rank) / (cfg_.explore_fraction * std::max(cfg_.attempts, 1)));
  const double eps = cfg_.epsilon_start + frac * (cfg_.epsilon_end - cfg_.epsilon_start);
  if (rank < round) {
    Outcome o = attempt(rng_.uniform(0.0, 1.0) < eps);
    outcome = {1, double(o.success), double(o.switch_step)};
  }
  outcome.push_back(double(env_steps_ - steps_before));
  std::string mine;
  put(mine, outcome), put(mine, pending_obs_), put(mine, pending_next_), put(mine, pending_action_);
  put(mine, pending_reward_), put(mine, pending_done_);
  pending_obs_.clear(), pending_next_.clear(), pending_action_.clear(), pending_reward_.clear(), pending_done_.clear();
  env_steps_ = steps_before;
  // Every rank's transitions, in rank order, into every rank's buffer.
  const std::vector<std::string> all = group_.gather(mine);
  for (int r = 0; r < int(all.size()); ++r) {
    size_t at = 0;
    const auto o = take<double>(all[r], at);
    const auto obs = take<float>(all[r], at), next = take<float>(all[r], at);
    const auto action = take<int64_t>(all[r], at);
    const auto reward = take<float>(all[r], at), done = take<float>(all[r], at);
    for (size_t k = 0; k < action.size(); ++k)
      push(&obs[k * I], action[k], reward[k], &next[k * I], done[k]);
    if (r == 0) rank0_rows_ += int64_t(action.size());
    env_steps_ += int64_t(o[3]);
    if (o[0] > 0) s.attempts++, s.success_rate += o[1], s.switch_step += o[2];
  }
  s.epsilon = cfg_.epsilon_start +
              std::min(1.0, (attempts_ + round - 1) / (cfg_.explore_fraction * std::max(cfg_.attempts, 1))) *
                  (cfg_.epsilon_end - cfg_.epsilon_start);
  attempts_ += round;
  if (stored_ >= cfg_.warmup) {
    for (int u = 0; u < cfg_.updates_per_attempt * round; ++u, ++updates) s.loss += update();
    q_ab_ = q_function();
  }
}

SwitchTrainer::Outcome SwitchTrainer::attempt(bool random) {
  const Skill& b = recipe_.skills[tr_.to];
  std::vector<float> act(env_->spec().act_dim);
  int i = rng_.integer(0, train_starts_ - 1);
  starts_.state(i, state_);
  env_->restore_state(state_, full_.data());
  env_->features(features_.data());
  q_input(full_.data(), in_.data());
  const int switch_at = random ? rng_.integer(0, interval_length_ - 1) : -1;
  for (int t = 0;; ++t) {
    int a = random ? (t == switch_at ? SwitchQNetworkImpl::kSwitch : SwitchQNetworkImpl::kStay) : greedy(in_.data());
    if (a == SwitchQNetworkImpl::kSwitch) {
      bool ok = hand_over(full_.data());
      store(in_.data(), a, ok ? cfg_.r_success : cfg_.r_fail, in_.data(), true);
      return {ok, t};
    }
    pi_ab_.act(full_.data() + b.obs_begin, 1, act.data());
    StepResult sr = env_->step(act.data(), next_full_.data());
    ++env_steps_;
    env_->features(features_.data());
    q_input(next_full_.data(), next_in_.data());
    bool left = sr.truncated || !tr_.running(features_.data(), t + 1);
    if (sr.terminated) {  // a fall while staying
      store(in_.data(), a, cfg_.r_fail, next_in_.data(), true);
      return {false, t + 1};
    }
    if (left) {  // the interval ran out: the forced switch, valued by pi_b's outcome
      bool ok = hand_over(next_full_.data());
      store(in_.data(), a, ok ? cfg_.r_success : cfg_.r_fail, next_in_.data(), true);
      return {ok, t + 1};
    }
    store(in_.data(), a, 0.0, next_in_.data(), false);
    full_.swap(next_full_);
    in_.swap(next_in_);
  }
}

double SwitchTrainer::update() {
  const int64_t n = std::min<int64_t>(stored_, cfg_.replay), I = q_ab_.in_dim();
  double l = 0;
  for (size_t k = 0; k < q_.size(); ++k) {
    auto idx = torch::randint(n, {cfg_.batch}, torch::kLong);  // each member its own minibatch
    auto obs = torch::from_blob(obs_.data(), {n, I}).index_select(0, idx);
    auto next = torch::from_blob(next_obs_.data(), {n, I}).index_select(0, idx);
    auto action = torch::from_blob(action_.data(), {n}, torch::kLong).index_select(0, idx);
    auto reward = torch::from_blob(reward_.data(), {n}).index_select(0, idx);
    auto done = torch::from_blob(done_.data(), {n}).index_select(0, idx);
    auto loss = double_dqn_loss(q_[k], target_[k], obs, action, reward, next, done, cfg_.net.gamma);  // Eq. 4
    opt_[k]->zero_grad();
    loss.backward();
    opt_[k]->step();
    l += loss.item<double>() / double(q_.size());
  }
  if (++updates_ % cfg_.target_every == 0)
    for (size_t k = 0; k < q_.size(); ++k) copy_weights(q_[k], target_[k]);
  if (!std::isfinite(l)) throw Error("switch Q-network loss became " + std::to_string(l));
  return l;
}

SwitchStats SwitchTrainer::run(int n) {
  const auto t0 = std::chrono::steady_clock::now();
  SwitchStats s;
  int updates = 0;
  for (int k = 0; k < n && !group_.single(); k += group_.size()) run_round(std::min(group_.size(), n - k), s, updates);
  for (int k = 0; k < n && group_.single(); ++k) {
    double frac = std::min(1.0, attempts_ / (cfg_.explore_fraction * std::max(cfg_.attempts, 1)));
    double eps = cfg_.epsilon_start + frac * (cfg_.epsilon_end - cfg_.epsilon_start);
    Outcome o = attempt(rng_.uniform(0.0, 1.0) < eps);
    ++attempts_;
    s.attempts++;
    s.success_rate += o.success;
    s.switch_step += o.switch_step;
    s.epsilon = eps;
    if (stored_ >= cfg_.warmup) {
      for (int u = 0; u < cfg_.updates_per_attempt; ++u, ++updates) s.loss += update();
      q_ab_ = q_function();
    }
  }
  if (s.attempts) s.success_rate /= s.attempts, s.switch_step /= s.attempts;
  if (updates) s.loss /= updates;
  s.replay_rows = stored_, s.rank0_rows = rank0_rows_;
  wall_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

void SwitchTrainer::save(const std::string& path) const {
  torch::serialize::OutputArchive ar;
  for (size_t k = 0; k < q_.size(); ++k) {
    torch::serialize::OutputArchive q, target, opt;
    q_[k]->save(q);
    target_[k]->save(target);
    opt_[k]->save(opt);
    const std::string member = k ? std::to_string(k) : "";  // one network: the paper's names
    ar.write("q" + member, q);
    ar.write("target" + member, target);
    ar.write("optimizer" + member, opt);
  }
  const int64_t rows = std::min<int64_t>(stored_, cfg_.replay), I = q_ab_.in_dim();
  auto blob = [](const auto& v, std::vector<int64_t> shape, torch::Dtype type) {
    return torch::from_blob(const_cast<void*>(static_cast<const void*>(v.data())), shape, type);
  };
  ar.write("replay_obs", blob(obs_, {rows, I}, torch::kFloat32));
  ar.write("replay_next_obs", blob(next_obs_, {rows, I}, torch::kFloat32));
  ar.write("replay_action", blob(action_, {rows}, torch::kLong));
  ar.write("replay_reward", blob(reward_, {rows}, torch::kFloat32));
  ar.write("replay_done", blob(done_, {rows}, torch::kFloat32));
  ar.write("counters", torch::tensor(std::vector<int64_t>{stored_, attempts_, updates_, env_steps_,
                                                          int64_t(wall_seconds_ * 1000), rank0_rows_}));
  // Every rank's attempt stream, one line each (the rest is the same on every rank).
  std::string rngs;
  for (const std::string& r : group_.gather(rng_.state())) rngs += (rngs.empty() ? "" : "\n") + r;
  ar.write("rng", text_tensor(rngs));
  at::Generator gen = at::detail::getDefaultCPUGenerator();
  {
    std::lock_guard<std::mutex> lock(gen.mutex());
    ar.write("torch_rng", gen.get_state());
  }
  if (!group_.leader()) return;
  std::ostringstream bytes;
  ar.save_to(bytes);
  write_file_atomic(path, bytes.str());
}

void SwitchTrainer::load(const std::string& path) {
  torch::serialize::InputArchive ar;
  torch::Tensor obs, next, action, reward, done, counters, rng, torch_rng;
  try {
    ar.load_from(path);
    ar.read("replay_obs", obs);
    if (obs.dim() != 2 || obs.size(1) != q_ab_.in_dim())
      throw Error(path + ": the checkpoint's q_ab input width differs from the recipe's (" +
                  std::to_string(q_ab_.in_dim()) + ")");
    for (size_t k = 0; k < q_.size(); ++k) {
      torch::serialize::InputArchive q, target, opt;
      const std::string member = k ? std::to_string(k) : "";
      ar.read("q" + member, q);
      ar.read("target" + member, target);
      ar.read("optimizer" + member, opt);
      q_[k]->load(q);
      target_[k]->load(target);
      opt_[k]->load(opt);
    }
    ar.read("replay_next_obs", next);
    ar.read("replay_action", action);
    ar.read("replay_reward", reward);
    ar.read("replay_done", done);
    ar.read("counters", counters);
    ar.read("rng", rng);
    ar.read("torch_rng", torch_rng);
  } catch (const c10::Error&) {
    throw Error(path + ": not a switch-training checkpoint for this recipe's q_ab");
  }
  obs_ = to_floats(obs), next_obs_ = to_floats(next), reward_ = to_floats(reward), done_ = to_floats(done);
  action_ = to_int64s(action);
  stored_ = counters[0].item<int64_t>();
  attempts_ = int(counters[1].item<int64_t>());
  updates_ = int(counters[2].item<int64_t>());
  env_steps_ = counters[3].item<int64_t>();
  wall_seconds_ = counters[4].item<int64_t>() / 1000.0;
  rank0_rows_ = counters.numel() > 5 ? counters[5].item<int64_t>() : stored_;
  std::istringstream text(to_text(rng));
  std::vector<std::string> lines;
  for (std::string line; std::getline(text, line);) lines.push_back(line);
  if (size_t(group_.rank()) < lines.size()) rng_.set_state(lines[group_.rank()]);
  else rng_.seed(mix_seed(uint64_t(attempts_), 0x5317 + uint64_t(group_.rank())));  // saved by fewer ranks
  at::Generator gen = at::detail::getDefaultCPUGenerator();
  {
    std::lock_guard<std::mutex> lock(gen.mutex());
    gen.set_state(torch_rng);
  }
  q_ab_ = q_function();
}

Policy SwitchTrainer::q_function(double margin) const {
  std::vector<float> theta = mean_network().parameters();
  theta[theta.size() - 2 + SwitchQNetworkImpl::kStay] += float(margin);  // the last layer's bias
  return q_ab_.with_parameters(theta);
}

MarginChoice SwitchTrainer::choose_margin() {
  MarginChoice c;
  c.margins = cfg_.margins;
  std::sort(c.margins.begin(), c.margins.end());
  c.success.assign(c.margins.size(), 0.0);
  const Skill& b = recipe_.skills[tr_.to];
  std::vector<float> act(env_->spec().act_dim);
  std::vector<std::vector<double>> path;  // the full state at each step of pi_ab's run
  std::vector<float> gap;                 // Q(switch) - Q(stay) there
  const int held_out = starts_.size() - train_starts_;
  for (int i = train_starts_; i < starts_.size(); ++i) {
    starts_.state(i, state_);
    env_->restore_state(state_, full_.data());
    env_->features(features_.data());
    path.clear(), gap.clear();
    for (int t = 0;; ++t) {
      path.emplace_back();
      env_->save_state(path.back());
      q_input(full_.data(), in_.data());
      q_ab_.act(in_.data(), 1, qvals_.data());
      gap.push_back(qvals_[SwitchQNetworkImpl::kSwitch] - qvals_[SwitchQNetworkImpl::kStay]);
      pi_ab_.act(full_.data() + b.obs_begin, 1, act.data());
      StepResult sr = env_->step(act.data(), full_.data());
      ++env_steps_;
      env_->features(features_.data());
      if (sr.terminated) break;  // a fall: no hand-over point after this one
      if (sr.truncated || !tr_.running(features_.data(), t + 1)) {  // the forced switch's state
        path.emplace_back();
        env_->save_state(path.back());
        gap.push_back(std::numeric_limits<float>::infinity());
        break;
      }
    }
    std::vector<int> judged(path.size(), -1);  // pi_b's outcome from each hand-over point
    for (size_t m = 0; m < c.margins.size(); ++m) {
      size_t k = 0;
      while (k < gap.size() && !(gap[k] > c.margins[m])) ++k;
      if (k == gap.size()) continue;  // pi_ab fell before any hand-over: a failure
      if (judged[k] < 0) {
        env_->restore_state(path[k], full_.data());
        judged[k] = hand_over(full_.data());
      }
      c.success[m] += double(judged[k]) / held_out;
    }
  }
  size_t best = 0;
  for (size_t m = 1; m < c.margins.size(); ++m)
    if (c.success[m] >= c.success[best]) best = m;
  c.margin = c.margins[best];
  return c;
}

}  // namespace segue
