#pragma once
// Whatever chooses actions during an evaluation episode: one policy, or a meta-controller
// switching between skills. One controller per environment slot, so a controller may
// keep per-episode state (the current skill) and need not be thread-safe.
#include <memory>
#include <string>

#include "algorithms/policy.h"
#include "core/env.h"

namespace segue {

class Controller {
 public:
  virtual ~Controller() = default;
  // A new episode has started in `env` with observation `obs`; `seed` is the episode's, for
  // a controller that draws random numbers of its own.
  virtual void reset(const Env& env, const float* obs, uint64_t seed) {}
  virtual void act(const Env& env, const float* obs, float* action) = 0;
  // Who chose the last action, for a viewer: a skill's name, a transition policy
  // ("walk->jump"), or "" for a single policy.
  virtual std::string in_control() const { return ""; }
};

// One deterministic policy on the whole observation (a skill alone, or Single).
class PolicyController : public Controller {
 public:
  explicit PolicyController(Policy policy) : policy_(std::move(policy)) {}
  void act(const Env&, const float* obs, float* action) override { policy_.act(obs, 1, action); }

 private:
  Policy policy_;  // a copy per slot: Policy::act keeps scratch buffers
};

}  // namespace segue
