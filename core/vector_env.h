#pragma once
// N environments stepped on a thread pool: together, one step at a time (step(), for a
// policy run once on the whole batch), or each through a whole rollout on one thread
// (run(), for a policy fixed for the rollout). Buffers are laid out row-major
// ([N, obs_dim]). An environment that
// finishes an episode is reset at once; the observation it ended on is kept in
// final_obs() (a truncated episode is bootstrapped from it) and the episode's totals
// are queued for the caller.
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "core/env.h"
#include "core/thread_pool.h"

namespace segue {

struct EpisodeStats {
  double ret = 0.0;
  int length = 0;
  bool success = false;
  int success_count = 0;
  std::array<double, kMaxMetrics> metric_sums{};  // per-step metrics summed over the episode
};

class VectorEnv {
 public:
  using Factory = std::function<std::unique_ptr<Env>()>;
  // `first_index`: where these environments sit among every rank's (data parallelism):
  // environment i is seeded as environment first_index + i of one big vector would be.
  VectorEnv(const Factory& make, int num_envs, int threads, int first_index = 0);

  int size() const { return static_cast<int>(envs_.size()); }
  int first_index() const { return first_index_; }
  const EnvSpec& spec() const { return envs_[0]->spec(); }
  Env& env(int i) { return *envs_[i]; }
  // Seeds environment i from mix_seed(seed, first_index + i) and resets all of them.
  void reset(uint64_t seed);
  // Applies actions [N, act_dim]; afterwards obs(), reward(), terminated(), truncated()
  // describe the step and finished episodes are appended to finished().
  void step(const float* actions);
  // Steps every environment `steps` times with actions chosen one environment at a time,
  // for a collector whose policy is fixed for the whole call: body(i, t) decides
  // environment i's t-th action from obs() row i and calls step_one(i, action) once. Each
  // environment runs all its steps on one thread, the environments spread over the pool:
  // one hand-off per call instead of one per step, and the policy's work runs in parallel
  // too. finished() then holds the episodes in the order `steps` calls of step() give.
  void run(int steps, const std::function<void(int, int)>& body);
  // Environment i's step inside run(); afterwards row i of obs(), reward() ... describes it.
  void step_one(int i, const float* action);

  const float* obs() const { return obs_.data(); }
  const float* final_obs() const { return final_obs_.data(); }
  const std::vector<double>& reward() const { return reward_; }
  const std::vector<uint8_t>& terminated() const { return terminated_; }
  const std::vector<uint8_t>& truncated() const { return truncated_; }
  const std::vector<StepInfo>& info() const { return info_; }
  std::vector<EpisodeStats>& finished() { return finished_; }
  // Every environment's episode in flight (Env::save_episode) with its running totals, as
  // numbers and one line of text per environment; false if any environment cannot.
  bool save_episodes(std::vector<double>& numbers, std::string& rngs) const;
  // Puts them back (same number of environments); throws segue::Error on a mismatch.
  void restore_episodes(const std::vector<double>& numbers, const std::string& rngs);
  // Environments [first, first + count) of what save_episodes wrote for a larger vector
  // (one rank's share of a checkpoint written for all of them).
  static void slice_episodes(const std::vector<double>& numbers, const std::string& rngs, int first, int count,
                             std::vector<double>& out_numbers, std::string& out_rngs);
  ThreadPool& pool() { return pool_; }

 private:
  std::vector<std::unique_ptr<Env>> envs_;
  ThreadPool pool_;
  int obs_dim_, act_dim_, first_index_;
  std::vector<float> obs_, final_obs_;
  std::vector<double> reward_;
  std::vector<uint8_t> terminated_, truncated_;
  std::vector<StepInfo> info_;
  std::vector<EpisodeStats> running_, finished_;
  // run(): each environment's finished episodes with the step they ended at, merged into
  // finished_ in step order once every environment is done.
  std::vector<std::vector<std::pair<int, EpisodeStats>>> ended_;
  std::function<void(int, int)> step_block_;
  const float* actions_ = nullptr;
};

}  // namespace segue
