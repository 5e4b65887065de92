#include "algorithms/proximity_predictor.h"

#include <cmath>

namespace segue {

ProximityPredictorImpl::ProximityPredictorImpl(const ProximitySpec& s) : spec(s) {
  net = register_module("net", make_mlp(s.obs_dim, s.hidden, 1, Activation::Relu, 1.0));
}

std::vector<float> proximity_labels(int length, bool success, double decay) {
  std::vector<float> y(length, 0.0f);
  if (success)
    for (int t = 0; t < length; ++t) y[t] = static_cast<float>(std::pow(decay, length - 1 - t));
  return y;
}

std::vector<float> proximity_rewards(const std::vector<float>& p) {
  std::vector<float> r;
  for (size_t t = 0; t + 1 < p.size(); ++t) r.push_back(p[t + 1] - p[t]);
  if (!r.empty()) r.back() += p.back();
  return r;
}

}  // namespace segue
