#pragma once
// On-policy storage for one PPO rollout, time-major [T, N, ...]. Sized once; refilled
// every iteration without allocating.
#include <cstdint>
#include <vector>

namespace segue {

struct RolloutBuffer {
  int T = 0, N = 0, obs_dim = 0, act_dim = 0;
  int in_dim = 0;               // the networks' input: obs_dim, plus any appended features
  std::vector<float> obs;       // the networks' inputs (normalised observations)  [T, N, in_dim]
  std::vector<float> raw_obs;   // the same before normalisation (for the normaliser)
  std::vector<float> next_raw_obs;  // s' before normalisation (the final one where an episode ended)
  std::vector<float> actions;   // sampled, unclipped                       [T, N, act_dim]
  std::vector<float> log_probs; // log pi_old(a|s)                          [T, N]
  std::vector<double> raw_rewards;  // as the task (or a reward hook) gives them  [T, N]
  std::vector<float> rewards;   // scaled, with truncation bootstraps folded in  [T, N]
  std::vector<uint8_t> dones;   // episode ended at this step              [T, N]
  std::vector<float> values, advantages, returns;  // [T, N]
  // Truncated steps: their index t*N+n and the final observation as network input [in_dim].
  std::vector<int> truncated_index;
  std::vector<float> truncated_obs;

  void resize(int t, int n, int od, int ad, int id) {
    T = t, N = n, obs_dim = od, act_dim = ad, in_dim = id;
    size_t steps = size_t(t) * n;
    obs.resize(steps * id);
    raw_obs.resize(steps * od);
    next_raw_obs.resize(steps * od);
    actions.resize(steps * ad);
    log_probs.resize(steps);
    raw_rewards.resize(steps);
    rewards.resize(steps);
    dones.resize(steps);
    values.resize(steps);
    advantages.resize(steps);
    returns.resize(steps);
    truncated_index.reserve(steps);
    truncated_obs.reserve(steps * id);
  }
};

}  // namespace segue
