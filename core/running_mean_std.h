#pragma once
// Running mean and variance of observations (Chan et al.'s parallel update), used to
// normalise policy inputs: x' = clip((x - mean) / sqrt(var + eps), -clip, clip).
// The statistics travel with the policy (checkpoint and TorchScript export).
#include <torch/torch.h>

#include <vector>

#include "core/distributed.h"

namespace segue {

class RunningMeanStd {
 public:
  explicit RunningMeanStd(int dim = 0, double clip = 10.0, double eps = 1e-8);
  // Adds a batch of `n` rows of length dim(); with `across`, the batch is the union of
  // every rank's rows (a collective: every rank calls it), merged exactly.
  void update(const float* rows, int64_t n, const Distributed* across = nullptr);
  void normalize(const float* in, float* out) const;
  // Replaces the statistics, as if `count` rows with this mean and variance had been seen.
  void set(const std::vector<double>& mean, const std::vector<double>& var, double count);
  // Inputs in [begin, end) always normalise to 0, so a network fed from here never sees
  // them (policy.ignore_obs, e.g. the walker's qacc). Saved
  // with the statistics; the exported policy carries it as inv_std = 0.
  void ignore(int begin, int end);
  bool ignored(int j) const { return ignored_[j] != 0; }
  int dim() const { return static_cast<int>(mean_.size()); }
  double count() const { return count_; }
  const std::vector<double>& mean() const { return mean_; }
  const std::vector<double>& var() const { return var_; }
  double clip() const { return clip_; }
  double eps() const { return eps_; }
  // 1 / sqrt(var + eps), cached so normalize() is a multiply.
  const std::vector<float>& inv_std() const { return inv_std_; }

  void save(torch::serialize::OutputArchive& ar, const std::string& prefix) const;
  void load(torch::serialize::InputArchive& ar, const std::string& prefix);

 private:
  void refresh();
  std::vector<double> batch_mean_, batch_var_;  // scratch: update() allocates nothing
  std::vector<double> mean_, var_;
  std::vector<float> mean_f_, inv_std_;
  std::vector<uint8_t> ignored_;
  double count_ = 0.0;
  double clip_, eps_;
};

}  // namespace segue
