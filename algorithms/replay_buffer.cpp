#include "algorithms/replay_buffer.h"

#include <algorithm>

#include "core/error.h"

namespace segue {

ReplayBuffer::ReplayBuffer(int64_t capacity, int obs_dim, int act_dim)
    : capacity_(capacity), obs_dim_(obs_dim), act_dim_(act_dim) {}

void ReplayBuffer::resize(int64_t rows) {
  if (obs_.capacity() < size_t(rows) * obs_dim_) {  // grow by doubling, never past the capacity
    const size_t room = size_t(std::min(capacity_, std::max<int64_t>(2 * rows, 1024)));
    obs_.reserve(room * obs_dim_), next_obs_.reserve(room * obs_dim_), act_.reserve(room * act_dim_);
    reward_.reserve(room), terminal_.reserve(room);
  }
  obs_.resize(size_t(rows) * obs_dim_);
  next_obs_.resize(size_t(rows) * obs_dim_);
  act_.resize(size_t(rows) * act_dim_);
  reward_.resize(size_t(rows));
  terminal_.resize(size_t(rows));
}

void ReplayBuffer::add(const float* obs, const float* act, double reward, const float* next_obs, bool terminal) {
  const size_t k = size_t(next_);
  if (size_ < capacity_) resize(size_ + 1);  // amortised: std::vector grows geometrically
  std::copy(obs, obs + obs_dim_, &obs_[k * obs_dim_]);
  std::copy(next_obs, next_obs + obs_dim_, &next_obs_[k * obs_dim_]);
  std::copy(act, act + act_dim_, &act_[k * act_dim_]);
  reward_[k] = float(reward);
  terminal_[k] = terminal ? 1.0f : 0.0f;
  next_ = (next_ + 1) % capacity_;
  size_ = std::min(size_ + 1, capacity_);
}

ReplayBuffer::Batch ReplayBuffer::gather(const std::vector<int64_t>& idx) const {
  const int64_t b = int64_t(idx.size());
  Batch out{torch::empty({b, obs_dim_}), torch::empty({b, act_dim_}), torch::empty({b}),
            torch::empty({b, obs_dim_}), torch::empty({b})};
  float *o = out.obs.data_ptr<float>(), *a = out.act.data_ptr<float>(), *r = out.reward.data_ptr<float>(),
        *n = out.next_obs.data_ptr<float>(), *t = out.terminal.data_ptr<float>();
  for (int64_t i = 0; i < b; ++i) {
    const size_t k = size_t(idx[i]);
    std::copy(&obs_[k * obs_dim_], &obs_[(k + 1) * obs_dim_], o + i * obs_dim_);
    std::copy(&next_obs_[k * obs_dim_], &next_obs_[(k + 1) * obs_dim_], n + i * obs_dim_);
    std::copy(&act_[k * act_dim_], &act_[(k + 1) * act_dim_], a + i * act_dim_);
    r[i] = reward_[k], t[i] = terminal_[k];
  }
  return out;
}

namespace {
torch::Tensor rows(const std::vector<float>& v, int64_t n, int64_t width) {
  return torch::from_blob(const_cast<float*>(v.data()), {n * width}).clone();
}
void restore(std::vector<float>& v, const torch::Tensor& t) {
  const auto c = t.contiguous();
  std::copy(c.data_ptr<float>(), c.data_ptr<float>() + c.numel(), v.begin());
}
}  // namespace

void ReplayBuffer::save(torch::serialize::OutputArchive& ar) const {
  ar.write("replay_counters", torch::tensor({capacity_, size_, next_, int64_t(obs_dim_), int64_t(act_dim_)}));
  ar.write("replay_obs", rows(obs_, size_, obs_dim_));
  ar.write("replay_next_obs", rows(next_obs_, size_, obs_dim_));
  ar.write("replay_act", rows(act_, size_, act_dim_));
  ar.write("replay_reward", rows(reward_, size_, 1));
  ar.write("replay_terminal", rows(terminal_, size_, 1));
}

void ReplayBuffer::load(torch::serialize::InputArchive& ar) {
  torch::Tensor c, o, n, a, r, t;
  ar.read("replay_counters", c);
  if (c[0].item<int64_t>() != capacity_ || c[3].item<int64_t>() != obs_dim_ || c[4].item<int64_t>() != act_dim_)
    throw Error("the checkpoint's replay buffer holds " + std::to_string(c[0].item<int64_t>()) + " rows of " +
                std::to_string(c[3].item<int64_t>()) + " + " + std::to_string(c[4].item<int64_t>()) +
                " numbers, the recipe's " + std::to_string(capacity_) + " of " + std::to_string(obs_dim_) + " + " +
                std::to_string(act_dim_) + ": another capacity or row width");
  const int64_t size = c[1].item<int64_t>(), next = c[2].item<int64_t>();
  ar.read("replay_obs", o), ar.read("replay_next_obs", n), ar.read("replay_act", a);
  ar.read("replay_reward", r), ar.read("replay_terminal", t);
  // The counters and the rows must agree: the ring's write position is past the rows until
  // it is full.
  if (size < 0 || size > capacity_ || next < 0 || next >= capacity_ || (size < capacity_ && next != size) ||
      o.numel() != size * obs_dim_ || n.numel() != size * obs_dim_ || a.numel() != size * act_dim_ ||
      r.numel() != size || t.numel() != size)
    throw Error("the checkpoint's replay buffer is inconsistent (" + std::to_string(size) + " rows, next " +
                std::to_string(next) + ")");
  size_ = size, next_ = next;
  resize(size_);
  restore(obs_, o), restore(next_obs_, n), restore(act_, a), restore(reward_, r), restore(terminal_, t);
}

}  // namespace segue
