#pragma once
// Evaluation episodes. Episode i always starts from seed mix_seed(seed, i), so results do
// not depend on how many environments run side by side or on how many threads step them.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/env.h"
#include "hrl/controller.h"

namespace segue {

struct EvalResult {
  std::vector<double> returns, success_counts, lengths;
  std::vector<uint8_t> successes;
  std::vector<uint8_t> terminated;        // ended by the task (success, a fall), not its time limit
  std::vector<std::string> ended_under;   // Controller::in_control() at the episode's last step
  std::vector<std::string> metric_names;
  std::vector<std::vector<double>> metric_means;  // [metric][episode]: per-step mean
  double success_rate() const;  // the fraction of episodes that succeeded
  void append(const EvalResult& more);  // more's episodes after these
};

struct Summary {
  double mean = 0, std = 0;
};
Summary summarize(const std::vector<double>& xs);  // population std, as numpy's default

using EnvFactory = std::function<std::unique_ptr<Env>()>;
using ControllerFactory = std::function<std::unique_ptr<Controller>()>;

// `progress`: a label for a progress line on stderr (episodes, rate, ETA); none if empty.
EvalResult evaluate(const EnvFactory& make_env, const ControllerFactory& make_controller, int episodes,
                    uint64_t seed, int threads, const std::string& progress = "");
// The common case: one deterministic policy.
EvalResult evaluate_policy(const Policy& policy, const EnvFactory& make_env, int episodes, uint64_t seed,
                           int threads, const std::string& progress = "");

}  // namespace segue
