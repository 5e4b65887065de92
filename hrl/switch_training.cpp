#include "hrl/switch_training.h"

#include <ATen/CPUGeneratorImpl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <sstream>

#include "core/run_dir.h"

namespace segue {

SwitchTrainer::SwitchTrainer(const SwitchConfig& config, SwitchInterval interval, uint64_t seed,
                             const Distributed& group)
    : cfg_(config),
      interval_(std::move(interval)),
      q_(nullptr),
      target_(nullptr),
      replay_(config.replay, interval_.obs_dim(), 1),
      group_(group) {
  if (interval_.starts() == 0) throw Error("switch training: S_a is empty");
  train_starts_ = interval_.starts() - cfg_.validation_starts;
  if (train_starts_ < 1)
    throw Error("switch training: validation_starts (" + std::to_string(cfg_.validation_starts) +
                ") leaves none of S_a's " + std::to_string(interval_.starts()) + " states to train on");
  const int D = interval_.obs_dim();
  obs_.resize(D), next_obs_.resize(D), at_switch_.resize(D), qvals_.resize(2);
  rng_.seed(seed);
  torch::manual_seed(mix_seed(seed, 0x9));
  SwitchQSpec qs = cfg_.net;
  qs.obs_dim = D;
  q_ = SwitchQNetwork(qs);
  target_ = SwitchQNetwork(qs);
  copy_weights(q_, target_);
  opt_ = std::make_unique<torch::optim::Adam>(q_->parameters(), torch::optim::AdamOptions(cfg_.lr));

  // Probe pi_ab through the interval from a few starts: how long the interval lasts (for
  // random attempts) and the scale of the states q_ab will see (its input normaliser).
  std::vector<double> sum(D, 0.0), sq(D, 0.0);
  int64_t rows = 0, steps = 0;
  const int probes = std::min(20, train_starts_);
  for (int p = 0; p < probes; ++p) {
    interval_.begin(p, obs_.data());
    for (int t = 0; t < 100000; ++t) {
      for (int j = 0; j < D; ++j) sum[j] += obs_[j], sq[j] += double(obs_[j]) * obs_[j];
      ++rows, ++steps;
      if (interval_.stay(obs_.data(), t, obs_.data()) != SwitchInterval::Stay::On) break;
    }
  }
  interval_length_ = std::max<int>(1, int(steps / probes));
  std::vector<float> mean(D), inv_std(D);
  for (int j = 0; j < D; ++j) {
    double m = sum[j] / rows, var = std::max(sq[j] / rows - m * m, 0.0);
    mean[j] = float(m);
    inv_std[j] = float(1.0 / std::max(std::sqrt(var), 1e-2));
  }
  const float inf = std::numeric_limits<float>::infinity();
  q_ab_ = Policy(EigenMlp(q_->q, Activation::Relu), mean, inv_std, 5.0f, {-inf, -inf}, {inf, inf}, {});
  if (!group_.single()) rng_.seed(mix_seed(seed, 0x5317 + uint64_t(group_.rank())));  // each rank its attempts
}

int SwitchTrainer::greedy(const float* obs) {
  q_ab_.act(obs, 1, qvals_.data());
  return qvals_[SwitchQNetworkImpl::kSwitch] > qvals_[SwitchQNetworkImpl::kStay] ? SwitchQNetworkImpl::kSwitch
                                                                                 : SwitchQNetworkImpl::kStay;
}

void SwitchTrainer::store(const float* s, int a, double r, const float* s2, bool done) {
  const size_t D = size_t(q_ab_.in_dim());
  // Normalised with q_ab's input statistics, fixed from the probe on (the same on every rank).
  pending_obs_.resize(pending_obs_.size() + D), pending_next_.resize(pending_next_.size() + D);
  q_ab_.normalize(s, 1, &pending_obs_[pending_obs_.size() - D]);
  q_ab_.normalize(s2, 1, &pending_next_[pending_next_.size() - D]);
  pending_action_.push_back(a), pending_reward_.push_back(float(r)), pending_done_.push_back(done ? 1.0f : 0.0f);
}

namespace {
template <class T>
void put(std::string& out, const std::vector<T>& v) {
  const int64_t n = int64_t(v.size());
  out.append(reinterpret_cast<const char*>(&n), sizeof n);
  if (n > 0) out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}
template <class T>
std::vector<T> take(const std::string& in, size_t& at) {
  int64_t n = 0;
  std::memcpy(&n, in.data() + at, sizeof n);
  at += sizeof n;
  std::vector<T> v(static_cast<size_t>(n));
  if (n > 0) std::memcpy(v.data(), in.data() + at, v.size() * sizeof(T));
  at += v.size() * sizeof(T);
  return v;
}
}  // namespace

void SwitchTrainer::run_round(int round, SwitchStats& s, int& updates) {
  const int rank = group_.rank(), D = q_ab_.in_dim();
  const int64_t steps_before = interval_.env_steps();
  std::vector<double> outcome{0, 0, 0};  // attempted, success, switch step
  if (rank < round) {
    Outcome o = attempt(rng_.uniform(0.0, 1.0) < cfg_.epsilon(attempts_ + rank));
    outcome = {1, double(o.success), double(o.switch_step)};
  }
  outcome.push_back(double(interval_.env_steps() - steps_before));
  std::string mine;
  put(mine, outcome), put(mine, pending_obs_), put(mine, pending_next_), put(mine, pending_action_);
  put(mine, pending_reward_), put(mine, pending_done_);
  pending_obs_.clear(), pending_next_.clear(), pending_action_.clear(), pending_reward_.clear(), pending_done_.clear();
  // Every rank's transitions, in rank order, into every rank's buffer.
  const std::vector<std::string> all = group_.gather(mine);
  for (int r = 0; r < int(all.size()); ++r) {
    size_t at = 0;
    const auto o = take<double>(all[r], at);
    const auto obs = take<float>(all[r], at), next = take<float>(all[r], at);
    const auto action = take<int64_t>(all[r], at);
    const auto reward = take<float>(all[r], at), done = take<float>(all[r], at);
    for (size_t k = 0; k < action.size(); ++k) {
      const float a = float(action[k]);
      replay_.add(&obs[k * D], &a, reward[k], &next[k * D], done[k] > 0.5f);
    }
    stored_ += int64_t(action.size());
    if (r == 0) rank0_rows_ += int64_t(action.size());
    env_steps_ += int64_t(o[3]);
    if (o[0] > 0) s.attempts++, s.success_rate += o[1], s.switch_step += o[2];
  }
  s.epsilon = cfg_.epsilon(attempts_ + round - 1);
  attempts_ += round;
  if (stored_ >= cfg_.warmup) {
    for (int u = 0; u < cfg_.updates_per_attempt * round; ++u, ++updates) s.loss += update();
    q_ab_ = q_function();
  }
}

SwitchTrainer::Outcome SwitchTrainer::attempt(bool random) {
  interval_.begin(rng_.integer(0, train_starts_ - 1), obs_.data());
  const int switch_at = random ? rng_.integer(0, interval_length_ - 1) : -1;
  for (int t = 0;; ++t) {
    int a = random ? (t == switch_at ? SwitchQNetworkImpl::kSwitch : SwitchQNetworkImpl::kStay) : greedy(obs_.data());
    if (a == SwitchQNetworkImpl::kSwitch) {
      at_switch_ = obs_;  // hand_over runs the episode on from obs_
      const bool ok = interval_.hand_over(obs_.data());
      store(at_switch_.data(), a, ok ? cfg_.r_success : cfg_.r_fail, at_switch_.data(), true);
      return {ok, t};
    }
    const SwitchInterval::Stay stay = interval_.stay(obs_.data(), t, next_obs_.data());
    if (stay == SwitchInterval::Stay::Fell) {
      store(obs_.data(), a, cfg_.r_fail, next_obs_.data(), true);
      return {false, t + 1};
    }
    if (stay == SwitchInterval::Stay::Ended) {  // the forced switch, valued by pi_b's outcome
      at_switch_ = next_obs_;
      const bool ok = interval_.hand_over(next_obs_.data());
      store(obs_.data(), a, ok ? cfg_.r_success : cfg_.r_fail, at_switch_.data(), true);
      return {ok, t + 1};
    }
    store(obs_.data(), a, 0.0, next_obs_.data(), false);
    obs_.swap(next_obs_);
  }
}

double SwitchTrainer::update() {
  auto idx = torch::randint(replay_.size(), {cfg_.batch}, torch::kLong);
  const ReplayBuffer::Batch b =
      replay_.gather(std::vector<int64_t>(idx.data_ptr<int64_t>(), idx.data_ptr<int64_t>() + idx.numel()));
  auto loss = double_dqn_loss(q_, target_, b.obs, b.act.squeeze(1).to(torch::kLong), b.reward, b.next_obs,
                              b.terminal, cfg_.net.gamma);  // Eq. 4
  opt_->zero_grad();
  loss.backward();
  opt_->step();
  const double l = loss.item<double>();
  if (++updates_ % cfg_.target_every == 0) copy_weights(q_, target_);
  if (!std::isfinite(l)) throw Error("switch Q-network loss became " + std::to_string(l));
  return l;
}

SwitchStats SwitchTrainer::run(int n) {
  const auto t0 = std::chrono::steady_clock::now();
  SwitchStats s;
  int updates = 0;
  for (int k = 0; k < n; k += group_.size()) run_round(std::min(group_.size(), n - k), s, updates);
  if (s.attempts) s.success_rate /= s.attempts, s.switch_step /= s.attempts;
  if (updates) s.loss /= updates;
  s.replay_rows = stored_, s.rank0_rows = rank0_rows_;
  wall_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

void SwitchTrainer::save(const std::string& path) const {
  torch::serialize::OutputArchive ar, q, target, opt;
  q_->save(q);
  target_->save(target);
  opt_->save(opt);
  ar.write("q", q);
  ar.write("target", target);
  ar.write("optimizer", opt);
  replay_.save(ar);
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
  torch::Tensor counters, rng, torch_rng;
  try {
    ar.load_from(path);
    torch::Tensor older;
    if (ar.try_read("replay_action", older))
      throw Error(path + ": a switch checkpoint written by an older Segue (its replay buffer is stored otherwise); "
                         "remove it to train q_ab again");
    replay_.load(ar);  // first: another recipe's q_ab input is refused by name
    torch::serialize::InputArchive q, target, opt;
    ar.read("q", q);
    ar.read("target", target);
    ar.read("optimizer", opt);
    q_->load(q);
    target_->load(target);
    opt_->load(opt);
    ar.read("counters", counters);
    ar.read("rng", rng);
    ar.read("torch_rng", torch_rng);
  } catch (const c10::Error&) {
    throw Error(path + ": not a switch-training checkpoint for this recipe's q_ab");
  } catch (const Error& e) {
    const std::string what = e.what();
    if (what.rfind(path, 0) == 0) throw;
    throw Error(path + ": " + what + " (switch.replay, or another task's q_ab)");
  }
  stored_ = counters[0].item<int64_t>();
  attempts_ = int(counters[1].item<int64_t>());
  updates_ = int(counters[2].item<int64_t>());
  env_steps_ = counters[3].item<int64_t>();
  wall_seconds_ = counters[4].item<int64_t>() / 1000.0;
  rank0_rows_ = counters[5].item<int64_t>();
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
  std::vector<float> theta = EigenMlp(q_->q, Activation::Relu).parameters();
  theta[theta.size() - 2 + SwitchQNetworkImpl::kStay] += float(margin);  // the last layer's bias
  return q_ab_.with_parameters(theta);
}

MarginChoice SwitchTrainer::choose_margin() {
  const int64_t before = interval_.env_steps();
  MarginChoice c = segue::choose_margin(interval_, q_ab_, cfg_.margins, train_starts_);
  env_steps_ += interval_.env_steps() - before;
  return c;
}

}  // namespace segue
