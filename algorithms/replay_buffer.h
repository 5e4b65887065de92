#pragma once
// The replay buffer of an off-policy learner (SAC, the switch's double DQN): the last
// `capacity` transitions (s, a, r, s', terminal), a ring overwritten oldest first. s' of a
// time limit is the episode's final observation, and `terminal` is false there: a time
// limit is not an end (the target bootstraps through it). Storage grows with the rows
// stored, up to `capacity` (a million rows are seldom all used), then never again.
#include <torch/torch.h>

#include <cstdint>
#include <string>
#include <vector>

namespace segue {

class ReplayBuffer {
 public:
  ReplayBuffer(int64_t capacity, int obs_dim, int act_dim);
  void add(const float* obs, const float* act, double reward, const float* next_obs, bool terminal);
  int64_t size() const { return size_; }
  int64_t capacity() const { return capacity_; }

  // Rows `idx` as tensors [B, ...] (copies).
  struct Batch {
    torch::Tensor obs, act, reward, next_obs, terminal;
  };
  Batch gather(const std::vector<int64_t>& idx) const;

  // The filled rows, in their slots, with the write position: a checkpoint holds the whole
  // buffer, so a resumed run samples what the unbroken one does. load() refuses a buffer
  // of another capacity or row width.
  void save(torch::serialize::OutputArchive& ar) const;
  void load(torch::serialize::InputArchive& ar);

 private:
  void resize(int64_t rows);
  int64_t capacity_, size_ = 0, next_ = 0;
  int obs_dim_, act_dim_;
  std::vector<float> obs_, act_, reward_, next_obs_, terminal_;
};

}  // namespace segue
