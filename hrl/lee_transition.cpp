#include "hrl/lee_transition.h"

#include <algorithm>

#include "hrl/switch_interval.h"

namespace segue {

LeeTransitionEnv::LeeTransitionEnv(const EnvFactory& make_env, const std::vector<Skill>& skills,
                                   const MetaController& meta, int transition, StartStates starts, int max_steps,
                                   int max_subtask_steps)
    : to_(meta.transitions().at(transition).to),
      inner_(make_env(), std::move(starts), meta.transitions()[transition], skills[to_].obs_begin,
             skills[to_].obs_end),
      max_steps_(max_steps), max_subtask_steps_(max_subtask_steps),
      pi_b_(skills, meta, {}, SwitchRule::IntervalEnd) {
  spec_ = inner_.spec();
  spec_.name = inner_.task().spec().name + " (Lee transition)";
  spec_.act_dim += 1;  // the termination output
  spec_.act_low.push_back(-1.0f);
  spec_.act_high.push_back(1.0f);
}

void LeeTransitionEnv::reset(uint64_t seed, float* obs) {
  inner_.reset(seed, obs);
  current_.states.assign(obs, obs + spec_.obs_dim);
}

void LeeTransitionEnv::reset(float* obs) {
  inner_.reset(obs);
  current_.states.assign(obs, obs + spec_.obs_dim);
}

void LeeTransitionEnv::restore_state(const std::vector<double>& state, float* obs) {
  inner_.restore_state(state, obs);
}

bool LeeTransitionEnv::save_episode(std::vector<double>& state, std::string& rng) const {
  if (!inner_.save_episode(state, rng)) return false;
  state.insert(state.end(), current_.states.begin(), current_.states.end());
  state.push_back(double(current_.states.size()));
  return true;
}

void LeeTransitionEnv::restore_episode(const std::vector<double>& state, const std::string& rng, float* obs) {
  const size_t n = state.empty() ? 0 : size_t(state.back());
  if (state.empty() || n + 1 > state.size()) throw Error(spec_.name + ": a saved episode of another kind");
  const auto states_begin = state.end() - 1 - long(n);
  current_.states.assign(states_begin, state.end() - 1);
  inner_.restore_episode(std::vector<double>(state.begin(), states_begin), rng, obs);
}

StepResult LeeTransitionEnv::step(const float* action, float* obs) {
  const int D = spec_.obs_dim;
  StepResult r;
  bool hand_over = action[spec_.act_dim - 1] > 0.0f;
  if (hand_over) {
    std::copy(current_.states.end() - D, current_.states.end(), obs);  // s_T: where pi_ab chose to end
  } else {
    r = inner_.step(action, obs);
    current_.states.insert(current_.states.end(), obs, obs + D);
    const int steps = int(current_.states.size()) / D - 1;
    // The interval ended, or pi_ab's steps are spent: pi_b takes over.
    hand_over = !r.terminated && (r.truncated || (max_steps_ > 0 && steps >= max_steps_));
  }
  bool success = false;
  if (hand_over) {
    after_ = inner_.task_obs();  // pi_b runs on from here; obs keeps s_T
    success = run_subtask(inner_.task(), pi_b_, to_, after_.data(), /*lookahead=*/1, max_subtask_steps_);
  }
  if (hand_over || r.terminated) {
    r.terminated = true, r.truncated = false;
    finished_.push_back({std::move(current_.states), success});
    current_.states.clear();
  }
  r.info.success = success;
  r.info.success_count = success;
  r.reward = 0.0;  // replaced by the proximity reward
  return r;
}

LeeTrainer::LeeTrainer(const TransitionPolicyConfig& tp, const LeeConfig& c, VectorEnv& envs,
                       const Demonstrations& expert, const Policy& next, uint64_t seed,
                       const Distributed& group)
    : cfg_(c), envs_(envs),
      ppo_(tp.ppo, tp.network(envs.spec(), next), envs, seed, group),
      obs_dim_(envs.spec().obs_dim), rms_(obs_dim_, 5.0, 1e-4) {
  if (expert.obs_dim != obs_dim_) throw Error("Lee transition policy: T_b's observation size differs from pi_b's");
  if (expert.size() == 0) throw Error("Lee transition policy: T_b is empty (no state of pi_b to label 1)");
  if (tp.init_from_next) ppo_.init_actor(next);
  // The termination head starts rarely firing either way: at ~0 (random weights) it would end
  // about half the episodes at their first step, each then costing a whole run of pi_b.
  ppo_.set_action_bias(envs.spec().act_dim - 1, c.termination_bias);
  torch::manual_seed(mix_seed(seed, 0x1ee));
  ProximitySpec ps;
  ps.obs_dim = obs_dim_;
  ps.hidden = c.hidden;
  ps.decay = c.decay;
  p_ = ProximityPredictor(ps);
  opt_ = std::make_unique<torch::optim::Adam>(p_->parameters(), torch::optim::AdamOptions(c.lr));
  // T_b, pi_b's own states, stay label-1 data for good: half of every positive batch.
  tb_ = expert.obs;
  rms_.update(tb_.data(), expert.size());
  ppo_.set_reward_hook([this](RolloutBuffer& buf) { reward(buf); });
}

torch::Tensor LeeTrainer::normalize(const torch::Tensor& obs) const {
  auto mean = torch::tensor(std::vector<float>(rms_.mean().begin(), rms_.mean().end()));
  auto inv_std = torch::tensor(rms_.inv_std());
  return ((obs - mean) * inv_std).clamp(-rms_.clip(), rms_.clip());
}

void LeeTrainer::add(const float* s, float label) {
  const int64_t cap = cfg_.max_rows;
  const bool positive = label > 0.0f;
  auto& rows = positive ? pos_ : neg_;
  int64_t& n = positive ? pos_n_ : neg_n_;
  const int64_t row = n % cap;
  if (n < cap) {
    rows.resize(size_t(row + 1) * obs_dim_);
    if (positive) pos_label_.push_back(0.0f);
  }
  std::copy(s, s + obs_dim_, rows.begin() + row * obs_dim_);
  if (positive) pos_label_[row] = label;
  ++n;
}

void LeeTrainer::reward(RolloutBuffer& buf) {
  // 1. Label the finished episodes and fit P_b by least squares on both classes.
  int episodes = 0, successes = 0;
  labelled_.clear();
  for (int i = 0; i < envs_.size(); ++i)
    for (auto& e : static_cast<LeeTransitionEnv&>(envs_.env(i)).take_finished()) {
      const int T = int(e.states.size()) / obs_dim_;
      std::vector<float> labels = proximity_labels(T, e.success, cfg_.decay);
      for (int t = 0; t < T; ++t) add(&e.states[size_t(t) * obs_dim_], labels[t]);
      labelled_.insert(labelled_.end(), e.states.begin(), e.states.end());
      ++episodes, successes += e.success;
    }
  const Distributed& group = ppo_.group();
  // P_b's inputs are normalised by the statistics of every state it has been fitted on.
  rms_.update(labelled_.data(), int64_t(labelled_.size()) / obs_dim_, &group);
  double counts[2] = {double(episodes), double(successes)};
  group.sum(counts, 2);
  last_ = Stats();
  if (counts[0] > 0) last_.handover_success = counts[1] / counts[0];
  const int64_t np = std::min<int64_t>(pos_n_, cfg_.max_rows), nn = std::min<int64_t>(neg_n_, cfg_.max_rows);
  auto pos = torch::from_blob(pos_.data(), {np, int64_t(obs_dim_)});
  auto pos_y = torch::from_blob(pos_label_.data(), {np});
  auto neg = torch::from_blob(neg_.data(), {nn, int64_t(obs_dim_)});
  const int64_t tb_n = int64_t(tb_.size()) / obs_dim_;
  auto tb = torch::from_blob(tb_.data(), {tb_n, int64_t(obs_dim_)});
  // Positives: half T_b, half successful transitions' states (all T_b before there are any).
  const int64_t from_tb = np > 0 ? cfg_.batch / 2 : cfg_.batch;
  for (int step = 0; step < cfg_.steps; ++step) {
    auto ti = torch::randint(tb_n, {from_tb}, torch::kLong);
    torch::Tensor x = tb.index_select(0, ti), y = torch::ones({from_tb});
    if (np > 0) {
      auto pi = torch::randint(np, {cfg_.batch - from_tb}, torch::kLong);
      x = torch::cat({x, pos.index_select(0, pi)});
      y = torch::cat({y, pos_y.index_select(0, pi)});
    }
    x = normalize(x);
    if (nn > 0) {
      auto ni = torch::randint(nn, {cfg_.batch}, torch::kLong);
      x = torch::cat({x, normalize(neg.index_select(0, ni))});
      y = torch::cat({y, torch::zeros({cfg_.batch})});
    }
    auto loss = p_->loss(x, y);
    opt_->zero_grad();
    (loss / double(group.size())).backward();
    last_.predictor_loss += group.sum_gradients(p_->parameters(), loss.item<double>() / group.size()) / cfg_.steps;
    opt_->step();
  }
  // 2. Rewards P(s_{t+1}) - P(s_t), plus P(s_T) where the episode ends.
  torch::NoGradGuard no_grad;
  const int64_t M = int64_t(buf.T) * buf.N;
  auto p0 = p_->forward(normalize(torch::from_blob(buf.raw_obs.data(), {M, int64_t(obs_dim_)})));
  auto p1 = p_->forward(normalize(torch::from_blob(buf.next_raw_obs.data(), {M, int64_t(obs_dim_)})));
  auto done = torch::from_blob(buf.dones.data(), {M}, torch::kUInt8).to(torch::kFloat32);
  auto r = (p1 - p0 + done * p1).to(torch::kFloat64).contiguous();
  std::copy(r.data_ptr<double>(), r.data_ptr<double>() + M, buf.raw_rewards.begin());
}

Policy LeeTrainer::policy() const {
  Policy p = ppo_.policy();
  p.set_max_steps(cfg_.max_steps);
  return p;
}

LeeTrainer::Stats LeeTrainer::iterate() {
  IterationStats s = ppo_.iterate();
  Stats out = last_;
  out.ppo = s;
  return out;
}

namespace {

torch::Tensor rows_of(const std::vector<float>& v, int64_t width) {
  return torch::tensor(v).reshape({-1, width});
}

}  // namespace

void LeeTrainer::save(const std::string& path, const std::string& note) const {
  ppo_.save(path, note, [this](torch::serialize::OutputArchive& ar) {
    torch::serialize::OutputArchive p, o;
    p_->save(p);
    opt_->save(o);
    ar.write("proximity_predictor", p);
    ar.write("proximity_optimizer", o);
    ar.write("proximity_positive", rows_of(pos_, obs_dim_));
    ar.write("proximity_positive_label", rows_of(pos_label_, 1));
    ar.write("proximity_negative", rows_of(neg_, obs_dim_));
    ar.write("proximity_seen", torch::tensor(std::vector<int64_t>{pos_n_, neg_n_}));
    rms_.save(ar, "proximity_obs_rms_");
  });
}

void LeeTrainer::load(const std::string& path) {
  ppo_.load(path, [this, &path](torch::serialize::InputArchive& ar) {
    torch::serialize::InputArchive p, o;
    ar.read("proximity_predictor", p);
    ar.read("proximity_optimizer", o);
    p_->load(p);
    opt_->load(o);
    torch::Tensor seen, pos, label, neg, count;
    if (!ar.try_read("proximity_seen", seen) || !ar.try_read("proximity_obs_rms_count", count))
      throw Error(path + ": a Lee checkpoint of an older layout (T_b in the labelled ring, no input normaliser); "
                  "remove it to train this stage afresh");
    ar.read("proximity_positive", pos);
    ar.read("proximity_positive_label", label);
    ar.read("proximity_negative", neg);
    if (pos.size(1) != obs_dim_ || neg.size(1) != obs_dim_)
      throw Error(path + ": the proximity predictor's states have another width than pi_b's observation");
    pos_ = to_floats(pos), pos_label_ = to_floats(label), neg_ = to_floats(neg);
    pos_n_ = seen[0].item<int64_t>(), neg_n_ = seen[1].item<int64_t>();
    rms_.load(ar, "proximity_obs_rms_");
  });
}

}  // namespace segue
