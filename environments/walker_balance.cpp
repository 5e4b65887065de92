#include "environments/walker_balance.h"

#include <cmath>

namespace segue {

StepResult WalkerBalance::evaluate(const float* action) {
  double reward = -std::abs(x_velocity()) - 0.5 * std::abs(cfg_.height_target - delta_h()) + posture_terms(action);
  return survival_step(reward, fallen());
}

}  // namespace segue
