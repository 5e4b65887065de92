#pragma once
// Runs a deterministic policy for a number of episodes. Episode i always starts from
// seed mix_seed(seed, i), so results do not depend on how many run side by side.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "algorithms/policy.h"
#include "core/env.h"

namespace segue {

struct EvalResult {
  std::vector<double> returns, success_counts, lengths;
  std::vector<uint8_t> successes;
  std::vector<std::string> metric_names;
  std::vector<std::vector<double>> metric_means;  // [metric][episode]: per-step mean
};

struct Summary {
  double mean = 0, std = 0;
};
Summary summarize(const std::vector<double>& xs);  // population std, as numpy's default

EvalResult evaluate_policy(const Policy& policy, const std::function<std::unique_ptr<Env>()>& make,
                           int episodes, uint64_t seed, int threads);

}  // namespace segue
