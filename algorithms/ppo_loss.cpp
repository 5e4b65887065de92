#include "algorithms/ppo_loss.h"

namespace segue {

torch::Tensor clipped_surrogate(const torch::Tensor& logp, const torch::Tensor& old_logp,
                                const torch::Tensor& adv, double clip) {
  auto ratio = torch::exp(logp - old_logp);
  auto unclipped = -adv * ratio;
  auto clipped = -adv * torch::clamp(ratio, 1.0 - clip, 1.0 + clip);
  return torch::max(unclipped, clipped).mean();
}

torch::Tensor value_loss(const torch::Tensor& value, const torch::Tensor& returns) {
  return 0.5 * (value - returns).pow(2).mean();
}

torch::Tensor action_bound_loss(const torch::Tensor& mean, const torch::Tensor& low,
                                const torch::Tensor& high) {
  auto above = torch::relu(mean - high), below = torch::relu(low - mean);
  return (above.pow(2) + below.pow(2)).sum(-1).mean();
}

PpoLoss ppo_loss(const torch::Tensor& logp, const torch::Tensor& old_logp, const torch::Tensor& adv,
                 const torch::Tensor& value, const torch::Tensor& returns,
                 const torch::Tensor& entropy, double clip, double vf_coef, double ent_coef) {
  PpoLoss l;
  l.policy = clipped_surrogate(logp, old_logp, adv, clip);
  l.value = value_loss(value, returns);
  l.entropy = entropy;
  l.total = l.policy + vf_coef * l.value - ent_coef * entropy;
  torch::NoGradGuard no_grad;
  auto log_ratio = logp - old_logp;
  // k3 estimator of KL(old || new): mean((r - 1) - log r), unbiased and >= 0.
  l.approx_kl = ((torch::exp(log_ratio) - 1) - log_ratio).mean();
  l.clip_fraction = ((torch::exp(log_ratio) - 1).abs() > clip).to(torch::kFloat32).mean();
  return l;
}

}  // namespace segue
