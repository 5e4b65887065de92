#include "hrl/transition_policy.h"

#include <algorithm>

namespace segue {

namespace {

torch::Tensor rows(const std::vector<float>& v, int64_t n) {
  return torch::from_blob(const_cast<float*>(v.data()), {n, int64_t(v.size()) / std::max<int64_t>(n, 1)}).clone();
}

}  // namespace

TransitionPolicyTrainer::TransitionPolicyTrainer(const TransitionPolicyConfig& config, VectorEnv& envs,
                                                 Demonstrations expert, const Policy& next, uint64_t seed,
                                                 const Distributed& group)
    : cfg_(config), ppo_(config.ppo, config.network(envs.spec(), next), envs, seed, group), expert_(std::move(expert)),
      act_low_(envs.spec().act_low), act_high_(envs.spec().act_high) {
  const EnvSpec& spec = envs.spec();
  if (expert_.obs_dim != spec.obs_dim || expert_.act_dim != spec.act_dim)
    throw Error("transition policy: T_b has obs/act sizes " + std::to_string(expert_.obs_dim) + "/" +
                std::to_string(expert_.act_dim) + " but pi_ab's environment has " + std::to_string(spec.obs_dim) +
                "/" + std::to_string(spec.act_dim));
  if (expert_.size() == 0) throw Error("transition policy: T_b is empty");
  if (cfg_.init_from_next) ppo_.init_actor(next);
  DiscriminatorSpec ds = cfg_.discriminator;
  ds.obs_dim = spec.obs_dim;
  ds.act_dim = spec.act_dim;
  ds.gamma = cfg_.ppo.gamma;
  torch::manual_seed(mix_seed(seed, 0xd15c));
  disc_ = Discriminator(ds);
  const int64_t m = expert_.size();
  expert_obs_ = rows(expert_.obs, m);
  expert_act_ = rows(expert_.act, m);
  expert_next_ = rows(expert_.next_obs, m);
  expert_done_ = torch::from_blob(expert_.done.data(), {m}, torch::kUInt8).to(torch::kFloat32);
  // The reference normalises D's inputs with the expert data's statistics.
  disc_->set_normalizer(expert_obs_.mean(0), expert_obs_.std(0), expert_act_.mean(0), expert_act_.std(0));
  disc_opt_ = std::make_unique<torch::optim::Adam>(disc_->parameters(), torch::optim::AdamOptions(cfg_.disc_lr));
  ppo_.set_reward_hook([this](RolloutBuffer& buf) { discriminate(buf); });
}

void TransitionPolicyTrainer::discriminate(RolloutBuffer& buf) {
  const int64_t M = int64_t(buf.T) * buf.N, D = buf.obs_dim, A = buf.act_dim;
  auto obs = torch::from_blob(buf.raw_obs.data(), {M, D});
  auto next = torch::from_blob(buf.next_raw_obs.data(), {M, D});
  // D compares the actions the environment applied: pi_b's are within bounds, and a
  // sampled action outside them would be told apart without saying anything about the
  // state distribution.
  auto low = torch::tensor(act_low_), high = torch::tensor(act_high_);
  auto act = torch::max(torch::min(torch::from_blob(buf.actions.data(), {M, A}), high), low);
  auto log_pi = torch::from_blob(buf.log_probs.data(), {M});
  // h(s') is dropped only at a true end; an episode cut at the interval's end goes on.
  auto done = torch::from_blob(buf.dones.data(), {M}, torch::kUInt8).to(torch::kFloat32);
  for (int k : buf.truncated_index) done[k] = 0.0f;

  last_ = TransitionIterationStats();
  const Distributed& group = ppo_.group();
  const int64_t E = expert_obs_.size(0), B = cfg_.disc_batch, W = group.size();
  double stats[4] = {0, 0, 0, 0};  // D's cross-entropy, expert and generator accuracy, over the ranks
  for (int step = 0; step < cfg_.disc_steps; ++step) {
    // The same draws on every rank (LibTorch's stream is seeded alike): generator rows
    // index this rank's rollout, expert rows take this rank's slice of W batches.
    auto gi = torch::randint(M, {std::min(B, M)}, torch::kLong);
    auto ei = torch::randint(E, {W * std::min(B, E)}, torch::kLong).slice(0, group.rank() * std::min(B, E),
                                                                           (group.rank() + 1) * std::min(B, E));
    auto eo = expert_obs_.index_select(0, ei), ea = expert_act_.index_select(0, ei);
    auto en = expert_next_.index_select(0, ei), ed = expert_done_.index_select(0, ei);
    auto e_logpi = ppo_.log_prob(eo.data_ptr<float>(), ea.data_ptr<float>(), eo.size(0));
    auto e_logit = disc_->logit(eo, ea, en, ed, e_logpi);
    auto g_logit = disc_->logit(obs.index_select(0, gi), act.index_select(0, gi), next.index_select(0, gi),
                                done.index_select(0, gi), log_pi.index_select(0, gi));
    auto loss = disc_->loss(e_logit, g_logit);
    disc_opt_->zero_grad();
    (loss / double(W)).backward();
    const double l = group.sum_gradients(disc_->parameters(), loss.item<double>() / W);  // the mean over ranks
    if (!std::isfinite(l)) throw Error("discriminator loss became " + std::to_string(l));
    disc_opt_->step();
    stats[0] += loss.item<double>();
    stats[1] += (e_logit > 0).to(torch::kFloat32).mean().item<double>();
    stats[2] += (g_logit < 0).to(torch::kFloat32).mean().item<double>();
  }
  group.sum(stats, 3);
  last_.disc_loss = stats[0] / (W * cfg_.disc_steps);
  last_.expert_accuracy = stats[1] / (W * cfg_.disc_steps);
  last_.generator_accuracy = stats[2] / (W * cfg_.disc_steps);
  auto r = disc_->reward(obs, act, next, done, log_pi);  // Eq. 3
  if (cfg_.reward == "airl_nonnegative") r = torch::nn::functional::softplus(r);  // -log(1 - D)
  if (cfg_.reward == "airl_absorbing") {
    auto lowest = r.min().reshape({1}).to(torch::kFloat64);
    group.min(lowest);  // the worst reward over every rank's rows
    const double gamma = cfg_.ppo.gamma, worst = lowest.item<double>();
    r = r + done * (gamma * std::min(worst, 0.0) / (1.0 - gamma));
  }
  double mean_reward[2] = {r.sum().item<double>(), double(M)};
  group.sum(mean_reward, 2);
  last_.airl_reward = mean_reward[0] / mean_reward[1];
  auto rc = r.to(torch::kFloat64).contiguous();
  std::copy(rc.data_ptr<double>(), rc.data_ptr<double>() + M, buf.raw_rewards.begin());
}

TransitionIterationStats TransitionPolicyTrainer::iterate() {
  IterationStats ppo = ppo_.iterate();
  TransitionIterationStats s = last_;
  s.ppo = ppo;
  return s;
}

void TransitionPolicyTrainer::save(const std::string& path, const std::string& note) const {
  ppo_.save(path, note, [this](torch::serialize::OutputArchive& ar) {
    torch::serialize::OutputArchive d, o;
    disc_->save(d);
    disc_opt_->save(o);
    ar.write("discriminator", d);
    ar.write("discriminator_optimizer", o);
  });
}

void TransitionPolicyTrainer::load(const std::string& path) {
  ppo_.load(path, [this](torch::serialize::InputArchive& ar) {
    torch::serialize::InputArchive d, o;
    ar.read("discriminator", d);
    ar.read("discriminator_optimizer", o);
    disc_->load(d);
    disc_opt_->load(o);
  });
}

}  // namespace segue
