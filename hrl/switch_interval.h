#pragma once
// One transition interval as switch training plays it (Algorithm 2): from a state of S_a,
// pi_ab drives one step at a time (stay) until the interval ends; at a hand-over pi_b takes
// the episode on and is judged by whether it achieves its subtask (run_subtask). The double
// DQN's attempts (hrl/switch_training.h) and the held-out choice of the switch margin
// (hrl/switch_margin.h) both play it.
#include <cstdint>
#include <memory>
#include <vector>

#include "core/env.h"
#include "hrl/collection.h"
#include "hrl/meta_controller.h"
#include "hrl/skill.h"
#include "hrl/transition_controller.h"

namespace segue {

// Runs the episode on from the state in `obs` (the task observation, updated in place)
// with pi_b (`to_skill`) in control, driven on by `after`, until `lookahead` transition
// intervals have begun. It succeeds then, when the episode reaches its time limit, or after
// max_steps; it fails when the episode terminates first (a fall, a contact).
// lookahead 1 is the paper's "pi_b achieves its subtask": the next transition out of b
// starts, and `after` only runs pi_b. With more, `after` (the meta-controller with the
// trained transition policies, With TP) carries on through the following transitions, so
// a hand-over that leaves pi_b standing but badly placed for the next skill is a failure.
// `steps` (optional) is increased by the environment steps taken.
bool run_subtask(Env& env, TransitionController& after, int to_skill, float* obs, int lookahead, int max_steps,
                 int64_t* steps = nullptr);

class SwitchInterval {
 public:
  // Transition `transition` of `meta`, in environments of `make_env`, from the states
  // `starts` (S_a), pi_ab acting on pi_b's observation slice. `trained`: the transition
  // policies that carry the episode on after pi_b when lookahead > 1 (missing ones are
  // taken as Without TP); pi_b's run is cut, and counted a success, after max_subtask_steps.
  SwitchInterval(const EnvFactory& make_env, const std::vector<Skill>& skills, const MetaController& meta,
                 int transition, StartStates starts, Policy pi_ab, std::vector<TransitionArtefacts> trained,
                 int lookahead, int max_subtask_steps);

  enum class Stay { On, Fell, Ended };  // Ended: the interval ran out (the forced switch's state)

  int obs_dim() const { return env_->spec().obs_dim; }
  int starts() const { return starts_.size(); }
  // The environment at S_a's state i, the interval's first step; its observation into obs.
  void begin(int i, float* obs);
  // pi_ab acts at obs, its step `t` of the interval (0 at begin()); next_obs may be obs.
  Stay stay(const float* obs, int t, float* next_obs);
  // pi_b takes over at the current state (obs, updated in place): does it achieve its subtask?
  bool hand_over(float* obs);
  // pi_ab's whole run through the interval from S_a's state i: the full state at each of its
  // steps, then the forced switch's state unless pi_ab fell; with q_ab, Q(switch) - Q(stay)
  // at each of them (+inf at the forced switch's, where control passes anyway).
  struct Path {
    std::vector<std::vector<double>> states;
    std::vector<float> gap;  // empty without q_ab
    bool fell = false;
    int steps = 0;  // pi_ab's
  };
  void walk(int i, const Policy* q_ab, Path& path);
  // pi_b takes over at the path's state k: does it achieve its subtask?
  bool hand_over_at(const Path& path, size_t k);
  // Environment steps so far: pi_ab's and pi_b's.
  int64_t env_steps() const { return env_steps_; }

 private:
  std::unique_ptr<Env> env_;
  const Transition& transition_;
  int to_, obs_begin_;  // pi_b, and where its observation slice begins
  StartStates starts_;
  Policy pi_ab_;
  TransitionController after_;  // judges a hand-over: pi_b, then With TP (run_subtask)
  int lookahead_, max_subtask_steps_;
  int64_t env_steps_ = 0;
  std::vector<float> act_, obs_, q_;
  std::vector<double> features_, state_;
};

}  // namespace segue
