#include "core/vector_env.h"

#include <algorithm>
#include <sstream>

#include "core/error.h"

#include "core/rng.h"

namespace segue {

VectorEnv::VectorEnv(const Factory& make, int num_envs, int threads, int first_index)
    : pool_(threads), first_index_(first_index) {
  for (int i = 0; i < num_envs; ++i) envs_.push_back(make());
  obs_dim_ = spec().obs_dim;
  act_dim_ = spec().act_dim;
  obs_.resize(size_t(num_envs) * obs_dim_);
  final_obs_.resize(obs_.size());
  reward_.resize(num_envs);
  terminated_.resize(num_envs);
  truncated_.resize(num_envs);
  info_.resize(num_envs);
  running_.resize(num_envs);
  finished_.reserve(num_envs);
  ended_.resize(num_envs);
  // Built once: std::function construction per step would allocate.
  step_block_ = [this](int begin, int end) {
    for (int i = begin; i < end; ++i) step_one(i, actions_ + size_t(i) * act_dim_);
  };
}

void VectorEnv::step_one(int i, const float* action) {
  float* o = &obs_[size_t(i) * obs_dim_];
  StepResult r = envs_[i]->step(action, o);
  reward_[i] = r.reward;
  terminated_[i] = r.terminated;
  truncated_[i] = r.truncated;
  info_[i] = r.info;
  EpisodeStats& ep = running_[i];
  ep.ret += r.reward;
  ep.length += 1;
  for (int k = 0; k < kMaxMetrics; ++k) ep.metric_sums[k] += r.info.metrics[k];
  if (r.done()) {
    ep.success = r.info.success;
    ep.success_count = r.info.success_count;
    std::copy(o, o + obs_dim_, &final_obs_[size_t(i) * obs_dim_]);
    envs_[i]->reset(o);
  }
}

// Per environment: the snapshot's length, the snapshot, then the episode's running totals.
bool VectorEnv::save_episodes(std::vector<double>& numbers, std::string& rngs) const {
  numbers.clear();
  rngs.clear();
  std::vector<double> state;
  std::string rng;
  for (int i = 0; i < size(); ++i) {
    if (!envs_[i]->save_episode(state, rng)) return false;
    numbers.push_back(double(state.size()));
    numbers.insert(numbers.end(), state.begin(), state.end());
    const EpisodeStats& ep = running_[i];
    numbers.insert(numbers.end(), {ep.ret, double(ep.length), double(ep.success), double(ep.success_count)});
    numbers.insert(numbers.end(), ep.metric_sums.begin(), ep.metric_sums.end());
    rngs += rng + "\n";
  }
  return true;
}

void VectorEnv::restore_episodes(const std::vector<double>& numbers, const std::string& rngs) {
  std::istringstream lines(rngs);
  size_t k = 0;
  for (int i = 0; i < size(); ++i) {
    std::string rng;
    if (k >= numbers.size() || !std::getline(lines, rng))
      throw Error("saved episodes are for fewer environments than " + std::to_string(size()));
    const size_t n = size_t(numbers[k++]);
    if (k + n + 4 + kMaxMetrics > numbers.size()) throw Error("saved episodes are truncated");
    envs_[i]->restore_episode(std::vector<double>(numbers.begin() + k, numbers.begin() + k + n), rng,
                              &obs_[size_t(i) * obs_dim_]);
    k += n;
    EpisodeStats& ep = running_[i];
    ep.ret = numbers[k++];
    ep.length = int(numbers[k++]);
    ep.success = numbers[k++] != 0;
    ep.success_count = int(numbers[k++]);
    for (auto& m : ep.metric_sums) m = numbers[k++];
  }
  if (k != numbers.size()) throw Error("saved episodes are for more environments than " + std::to_string(size()));
}

void VectorEnv::slice_episodes(const std::vector<double>& numbers, const std::string& rngs, int first, int count,
                               std::vector<double>& out_numbers, std::string& out_rngs) {
  out_numbers.clear();
  out_rngs.clear();
  std::istringstream lines(rngs);
  size_t k = 0;
  for (int i = 0; i < first + count; ++i) {
    std::string rng;
    if (k >= numbers.size() || !std::getline(lines, rng))
      throw Error("saved episodes are for fewer environments than " + std::to_string(first + count));
    const size_t record = 1 + size_t(numbers[k]) + 4 + kMaxMetrics;
    if (k + record > numbers.size()) throw Error("saved episodes are truncated");
    if (i >= first) {
      out_numbers.insert(out_numbers.end(), numbers.begin() + k, numbers.begin() + k + record);
      out_rngs += rng + "\n";
    }
    k += record;
  }
}

void VectorEnv::reset(uint64_t seed) {
  for (int i = 0; i < size(); ++i) {
    envs_[i]->reset(mix_seed(seed, uint64_t(first_index_ + i)), &obs_[size_t(i) * obs_dim_]);
    running_[i] = EpisodeStats{};
  }
  finished_.clear();
}

void VectorEnv::step(const float* actions) {
  actions_ = actions;
  pool_.parallel_for(size(), step_block_);
  for (int i = 0; i < size(); ++i) {
    if (terminated_[i] || truncated_[i]) {
      finished_.push_back(running_[i]);
      running_[i] = EpisodeStats{};
    }
  }
}

void VectorEnv::run(int steps, const std::function<void(int, int)>& body) {
  pool_.parallel_for(size(), [&](int begin, int end) {
    for (int i = begin; i < end; ++i) {
      ended_[i].clear();
      for (int t = 0; t < steps; ++t) {
        body(i, t);
        if (terminated_[i] || truncated_[i]) {
          ended_[i].emplace_back(t, running_[i]);
          running_[i] = EpisodeStats{};
        }
      }
    }
  });
  // Step order: by step, then by environment, as step() appends them.
  std::vector<size_t> next(size(), 0);  // (allocates a few bytes per rollout, not per step)
  for (int t = 0; t < steps; ++t)
    for (int i = 0; i < size(); ++i)
      if (next[i] < ended_[i].size() && ended_[i][next[i]].first == t) finished_.push_back(ended_[i][next[i]++].second);
}

}  // namespace segue
