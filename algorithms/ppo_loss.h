#pragma once
// The pieces of the PPO objective (Schulman et al. 2017), kept apart so each can be
// checked against hand-computed values.
#include <torch/torch.h>

namespace segue {

struct PpoLoss {
  torch::Tensor policy, value, entropy, total;
  torch::Tensor approx_kl, clip_fraction;  // diagnostics, no gradient
};

// L^CLIP: mean over the batch of max(-A r, -A clip(r, 1-eps, 1+eps)), r = exp(logp - old).
torch::Tensor clipped_surrogate(const torch::Tensor& logp, const torch::Tensor& old_logp,
                                const torch::Tensor& adv, double clip);
// 0.5 mean (V - R)^2.
torch::Tensor value_loss(const torch::Tensor& value, const torch::Tensor& returns);
// The mean's excursion outside the action bounds: mean over the batch of
// sum_j relu(mu_j - high_j)^2 + relu(low_j - mu_j)^2. Actions are clamped to the bounds,
// so a mean far outside them makes exploration noise a no-op in that dimension, and PPO
// can try nothing there (stage 3's jump: its mean is outside [-1, 1] in 41-81% of its
// steps, per dimension; experiments/primitives/walker_jump.yaml, stage `bounded`). Penalising the
// excursion (the "bounds loss" of rl_games-style PPO) keeps the deterministic action the
// same while the noise stays live.
torch::Tensor action_bound_loss(const torch::Tensor& mean, const torch::Tensor& low,
                                const torch::Tensor& high);
// total = policy + vf_coef value - ent_coef entropy.
PpoLoss ppo_loss(const torch::Tensor& logp, const torch::Tensor& old_logp, const torch::Tensor& adv,
                 const torch::Tensor& value, const torch::Tensor& returns,
                 const torch::Tensor& entropy, double clip, double vf_coef, double ent_coef);

}  // namespace segue
