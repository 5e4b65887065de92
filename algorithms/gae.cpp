#include "algorithms/gae.h"

namespace segue {

void compute_gae(const std::vector<float>& rewards, const std::vector<float>& values,
                 const std::vector<uint8_t>& dones, const std::vector<float>& last_values,
                 int T, int N, double gamma, double lambda, std::vector<float>& adv,
                 std::vector<float>& ret) {
  adv.assign(size_t(T) * N, 0.0f);
  ret.assign(size_t(T) * N, 0.0f);
  for (int n = 0; n < N; ++n) {
    double next_value = last_values[n], next_adv = 0.0;
    for (int t = T - 1; t >= 0; --t) {
      size_t i = size_t(t) * N + n;
      double keep = dones[i] ? 0.0 : 1.0;
      double delta = rewards[i] + gamma * next_value * keep - values[i];
      next_adv = delta + gamma * lambda * keep * next_adv;
      adv[i] = static_cast<float>(next_adv);
      ret[i] = static_cast<float>(next_adv + values[i]);
      next_value = values[i];
    }
  }
}

}  // namespace segue
