#include "hrl/switch_margin.h"

#include <algorithm>

namespace segue {

MarginChoice choose_margin(SwitchInterval& interval, const Policy& q_ab, std::vector<double> margins,
                           int first_start) {
  MarginChoice c;
  c.margins = std::move(margins);
  std::sort(c.margins.begin(), c.margins.end());
  c.success.assign(c.margins.size(), 0.0);
  const int held_out = interval.starts() - first_start;
  SwitchInterval::Path path;
  for (int i = first_start; i < interval.starts(); ++i) {
    interval.walk(i, &q_ab, path);
    std::vector<int> judged(path.states.size(), -1);  // pi_b's outcome from each hand-over point
    for (size_t m = 0; m < c.margins.size(); ++m) {
      size_t k = 0;
      while (k < path.gap.size() && !(path.gap[k] > c.margins[m])) ++k;
      if (k == path.gap.size()) continue;  // pi_ab fell before any hand-over: a failure
      if (judged[k] < 0) judged[k] = interval.hand_over_at(path, k);
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
