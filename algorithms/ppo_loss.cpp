#include "algorithms/ppo_loss.h"

#include <algorithm>
#include <cmath>

#include "algorithms/actor_critic.h"

namespace segue {

double value_loss(const float* value, const float* returns, int n, float* grad, double scale) {
  const double inv_n = 1.0 / std::max(n, 1);
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double error = double(value[i]) - returns[i];
    sum += 0.5 * error * error;
    if (grad) grad[i] = float(scale * error * inv_n);
  }
  return sum * inv_n;
}

PpoLossTerms ppo_loss(const PpoMinibatch& b, const PpoCoefficients& c, const PpoGradient* grad) {
  constexpr double kHalfLog2Pi = 0.91893853320467274178;
  const int n = b.rows, k = b.act_dim;
  const double per_row = 1.0 / std::max(n, 1);
  PpoLossTerms l;
  if (grad) std::fill(grad->log_std, grad->log_std + k, 0.0f);
  for (int i = 0; i < n; ++i) {
    const float* mu = b.mean + size_t(i) * k;
    const float* a = b.actions + size_t(i) * k;
    const double log_ratio = gaussian_log_prob(a, mu, b.log_std, k) - b.old_log_prob[i], r = std::exp(log_ratio), adv = b.advantage[i];
    l.policy += std::max(-adv * r, -adv * std::clamp(r, 1.0 - c.clip, 1.0 + c.clip));
    l.approx_kl += (r - 1.0) - log_ratio;
    l.clip_fraction += std::abs(r - 1.0) > c.clip ? 1.0 : 0.0;
    float* d_mu = grad ? grad->mean + size_t(i) * k : nullptr;
    if (grad) {
      // The clipped term is flat where the ratio has left the interval on the side the
      // advantage rewards; elsewhere the max is -A r, whose derivative in log pi is -A r.
      const bool flat = (adv > 0 && r > 1.0 + c.clip) || (adv < 0 && r < 1.0 - c.clip);
      gaussian_log_prob_gradient(a, mu, b.log_std, k, flat ? 0.0 : -adv * r * per_row, d_mu, grad->log_std);
    }
    for (int j = 0; j < k; ++j) {
      const double above = std::max(double(mu[j]) - b.high[j], 0.0), below = std::max(b.low[j] - double(mu[j]), 0.0);
      l.bound += above * above + below * below;
      if (d_mu) d_mu[j] += float(c.bound_coef * 2.0 * (above - below) * per_row);
    }
  }
  for (int j = 0; j < k; ++j) {
    l.entropy += b.log_std[j] + 0.5 + kHalfLog2Pi;
    if (grad) grad->log_std[j] += float(-c.ent_coef);
  }
  l.value = value_loss(b.value, b.returns, n, grad ? grad->value : nullptr, c.vf_coef);
  const double inv_n = 1.0 / std::max(n, 1);
  l.policy *= inv_n, l.bound *= inv_n, l.approx_kl *= inv_n, l.clip_fraction *= inv_n;
  l.total = l.policy + c.vf_coef * l.value - c.ent_coef * l.entropy + c.bound_coef * l.bound;
  return l;
}

}  // namespace segue
