#pragma once
// Generalised advantage estimation (Schulman et al. 2016):
//   delta_t = r_t + gamma V(s_{t+1}) (1 - done_t) - V(s_t)
//   A_t     = delta_t + gamma lambda (1 - done_t) A_{t+1}
// on a rollout laid out [T, N] (time-major, N environments). done_t marks the last step
// of an episode; a truncated step has the value of its final state folded into r_t by
// the caller, so here every done cuts the bootstrap.
#include <cstdint>
#include <vector>

namespace segue {

// values: [T, N]; last_values: V(s_T) [N]. Writes advantages and returns (A + V), [T, N].
void compute_gae(const std::vector<float>& rewards, const std::vector<float>& values,
                 const std::vector<uint8_t>& dones, const std::vector<float>& last_values,
                 int T, int N, double gamma, double lambda, std::vector<float>& advantages,
                 std::vector<float>& returns);

}  // namespace segue
