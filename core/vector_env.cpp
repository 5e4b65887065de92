#include "core/vector_env.h"

#include <algorithm>

#include "core/rng.h"

namespace segue {

VectorEnv::VectorEnv(const Factory& make, int num_envs, int threads) : pool_(threads) {
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
  // Built once: std::function construction per step would allocate.
  step_block_ = [this](int begin, int end) {
    for (int i = begin; i < end; ++i) {
      float* o = &obs_[size_t(i) * obs_dim_];
      StepResult r = envs_[i]->step(actions_ + size_t(i) * act_dim_, o);
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
  };
}

void VectorEnv::reset(uint64_t seed) {
  for (int i = 0; i < size(); ++i) {
    envs_[i]->reset(mix_seed(seed, i), &obs_[size_t(i) * obs_dim_]);
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

}  // namespace segue
