#pragma once
// The PPO objective on one minibatch (Schulman et al. 2017, Eq. 9: L^CLIP + c1 L^VF - c2 S)
// and its gradient with respect to the networks' outputs, written out by hand: the update
// (algorithms/ppo.cpp) backpropagates it through the networks with MlpBackprop. Checked
// against hand-computed values and against autograd in tests.
#include <cstdint>

namespace segue {

struct PpoCoefficients {
  double clip = 0.2;      // epsilon of L^CLIP
  double vf_coef = 0.5;   // c1
  double ent_coef = 0.0;  // c2
  // Weight of the action-bound loss: mean over rows of sum_j relu(mu_j - high_j)^2 +
  // relu(low_j - mu_j)^2. Actions are clamped to the bounds, so a mean far outside them
  // makes exploration noise a no-op in that dimension and PPO can try nothing there;
  // penalising the excursion (the "bounds loss" of rl_games-style PPO) keeps the
  // deterministic action while the noise stays live.
  double bound_coef = 0.0;
};

// One minibatch as the networks saw it, row-major.
struct PpoMinibatch {
  int rows = 0, act_dim = 0;
  const float* mean = nullptr;          // mu(s)              [rows, act_dim]
  const float* value = nullptr;         // V(s)               [rows]
  const float* actions = nullptr;       // a, as sampled      [rows, act_dim]
  const float* old_log_prob = nullptr;  // log pi_old(a|s)    [rows]
  const float* advantage = nullptr;     // A, normalised      [rows]
  const float* returns = nullptr;       // R                  [rows]
  const float* log_std = nullptr;       // log sigma          [act_dim]
  const float* low = nullptr;           // action bounds      [act_dim]
  const float* high = nullptr;
};

struct PpoLossTerms {
  double policy = 0, value = 0, entropy = 0, bound = 0;
  double total = 0;          // policy + vf_coef value - ent_coef entropy + bound_coef bound
  double approx_kl = 0;      // mean((r - 1) - log r), the k3 estimate of KL(old || new), >= 0
  double clip_fraction = 0;  // share of rows with |r - 1| > clip
};

// Where the gradient goes: dL/dmu [rows, act_dim], dL/dV [rows], dL/dlog_sigma [act_dim].
struct PpoGradient {
  float* mean = nullptr;
  float* value = nullptr;
  float* log_std = nullptr;
};

// L^VF = 0.5 mean((V - R)^2) over n rows; where `grad` is given, scale * dL^VF/dV there.
double value_loss(const float* value, const float* returns, int n, float* grad = nullptr, double scale = 1.0);

// The loss terms, each a mean over the minibatch's rows, with
//   L^CLIP = mean(max(-A r, -A clip(r, 1 - eps, 1 + eps))),  r = exp(log pi - log pi_old),
//   L^VF   = 0.5 mean((V - R)^2),
//   S      = sum_j (log sigma_j + 0.5 log(2 pi e))  (the Gaussian's entropy);
// and, where `grad` is given, the gradient of the total written there (overwritten).
PpoLossTerms ppo_loss(const PpoMinibatch& batch, const PpoCoefficients& c, const PpoGradient* grad = nullptr);

}  // namespace segue
