#include "hrl/switch_margin.h"

#include <algorithm>
#include <limits>

#include "algorithms/switch_q_network.h"

namespace segue {

MarginChoice choose_margin(SwitchInterval& interval, const Policy& q_ab, std::vector<double> margins,
                           int first_start) {
  MarginChoice c;
  c.margins = std::move(margins);
  std::sort(c.margins.begin(), c.margins.end());
  c.success.assign(c.margins.size(), 0.0);
  const int held_out = interval.starts() - first_start;
  std::vector<float> obs(interval.obs_dim()), q(2);
  std::vector<std::vector<double>> path;  // the full state at each step of pi_ab's run
  std::vector<float> gap;                 // Q(switch) - Q(stay) there
  for (int i = first_start; i < interval.starts(); ++i) {
    interval.begin(i, obs.data());
    path.clear(), gap.clear();
    for (int t = 0;; ++t) {
      path.emplace_back();
      interval.save_state(path.back());
      q_ab.act(obs.data(), 1, q.data());
      gap.push_back(q[SwitchQNetworkImpl::kSwitch] - q[SwitchQNetworkImpl::kStay]);
      const SwitchInterval::Stay s = interval.stay(obs.data(), t, obs.data());
      if (s == SwitchInterval::Stay::Fell) break;  // no hand-over point after this one
      if (s == SwitchInterval::Stay::Ended) {      // the forced switch's state
        path.emplace_back();
        interval.save_state(path.back());
        gap.push_back(std::numeric_limits<float>::infinity());
        break;
      }
    }
    std::vector<int> judged(path.size(), -1);  // pi_b's outcome from each hand-over point
    for (size_t m = 0; m < c.margins.size(); ++m) {
      size_t k = 0;
      while (k < gap.size() && !(gap[k] > c.margins[m])) ++k;
      if (k == gap.size()) continue;  // pi_ab fell before any hand-over: a failure
      if (judged[k] < 0) {
        interval.restore_state(path[k], obs.data());
        judged[k] = interval.hand_over(obs.data());
      }
      c.success[m] += double(judged[k]) / held_out;
    }
  }
  size_t best = 0;
  for (size_t m = 1; m < c.margins.size(); ++m)
    if (c.success[m] >= c.success[best]) best = m;
  c.margin = c.margins[best];
  return c;
}

}  // namespace segue
