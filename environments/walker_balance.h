#pragma once
// The balance sub-task (task `walker_balance`): the walker stands still under strong
// pushes. Its settings are the walker's own (WalkerConfig); environments/registry.cpp
// gives it the reference's harder, rarer pushes.
#include "environments/walker.h"

namespace segue {

// Balance: stand still under strong pushes for success_steps steps.
class WalkerBalance : public WalkerEnv {
 public:
  using WalkerEnv::WalkerEnv;

 protected:
  StepResult evaluate(const float* action) override;
};

}  // namespace segue
