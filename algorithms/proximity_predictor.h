#pragma once
// Lee et al. 2019's proximity predictor P(s) in [0, 1] for one skill: how close s is to
// the skill's successful initiation states. Trained by least squares on labels:
//   1 for the skill's own successful starts and for the last state of a successful
//   transition, decayed 0.95^k for the state k steps before it; 0 for failed transitions.
// A transition policy trained on it gets the dense reward P(s_t) - P(s_{t-1}), plus
// P(s_T) at its final step.
#include <torch/torch.h>

#include <vector>

#include "algorithms/mlp.h"

namespace segue {

struct ProximitySpec {
  int obs_dim = 0;
  std::vector<int> hidden{96, 96};  // 2 x 96 ReLU, the reference's (docs/reference/learners.md)
  double decay = 0.95;
};

class ProximityPredictorImpl : public torch::nn::Module {
 public:
  explicit ProximityPredictorImpl(const ProximitySpec& spec);
  // P(s): the network's output clipped to [0, 1].
  torch::Tensor forward(const torch::Tensor& obs) { return unclipped(obs).clamp(0.0, 1.0); }
  // Least squares on the unclipped output: a state predicted beyond [0, 1] on the wrong
  // side of its label still gets a gradient (clipped, it would get none).
  torch::Tensor loss(const torch::Tensor& obs, const torch::Tensor& label) {
    return (unclipped(obs) - label).pow(2).mean();
  }
  torch::Tensor unclipped(const torch::Tensor& obs) { return net->forward(obs).squeeze(-1); }
  ProximitySpec spec;
  torch::nn::Sequential net{nullptr};
};
TORCH_MODULE(ProximityPredictor);

// Labels for one trajectory of length T ending in success (decay^(T-1-t)) or failure (0).
std::vector<float> proximity_labels(int length, bool success, double decay);
// Rewards r_t = P(s_{t+1}) - P(s_t) for t < T-1 steps, plus P(s_T) added at the last step.
// `p` holds P at s_0..s_T (T + 1 values); returns T rewards.
std::vector<float> proximity_rewards(const std::vector<float>& p);

}  // namespace segue
