#pragma once
// Algorithm 2: the switch Q-network q_ab, which decides during a transition interval when
// pi_ab hands control to pi_b. An attempt starts from a state of S_a; at every state q_ab
// picks stay (pi_ab acts one step) or switch (pi_b takes over and runs its subtask).
// Rewards (docs/reference/learners.md#switch-network): switch -> r_s if pi_b then
// achieves its subtask, r_f if it fails; stay -> r_f on a fall, else 0. How far "its
// subtask" reaches is config.lookahead (run_subtask below). Every reward but the
// uneventful stay ends the attempt.
// Where the interval runs out while staying, control passes to pi_b as it does when the
// method runs (the forced switch), and that last stay is valued by pi_b's outcome. The
// paper's Algorithm 2 gives r_f there instead, which teaches q_ab that switching at any
// point beats reaching the interval's end, even where pi_ab run to the end (With TP) does
// better: on Patrol that made With TP + Q score below With TP (1.94 vs 3.41 turns).
// Double DQN (Eq. 4) on a replay buffer, hard target copy.
#include <memory>
#include <string>
#include <vector>

#include "algorithms/switch_q_network.h"
#include "core/rng.h"
#include "hrl/collection.h"
#include "hrl/composite_recipe.h"
#include "hrl/pipeline_config.h"
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

// The held-out choice of the switch margin (SwitchConfig::validation_starts).
struct MarginChoice {
  std::vector<double> margins, success;  // pi_b's success rate from the held-out starts, per margin
  double margin = 0;                     // the chosen one
};

struct SwitchStats {
  int attempts = 0;
  double success_rate = 0;   // of pi_b's subtask, over the attempts in this report
  double switch_step = 0;    // mean step of the interval where control was handed over
  double epsilon = 0, loss = 0;
  int64_t replay_rows = 0;   // transitions stored so far, every rank's
  int64_t rank0_rows = 0;    // of those, from rank 0's own attempts
};

class SwitchTrainer {
 public:
  // `trained`: the recipe's transition policies (by transition; missing ones are taken
  // as Without TP), which carry the episode on after pi_b when config.lookahead > 1.
  // With `group` of W ranks, attempts go in rounds of W, one per rank (each rank its own
  // random stream); every rank's transitions are then stored, in rank order, in every
  // rank's replay buffer, and all ranks make the round's updates alike, so q_ab stays
  // the same on every rank. save() is then a collective, rank 0 writing.
  SwitchTrainer(const SwitchConfig& config, const CompositeRecipe& recipe, int transition, StartStates starts,
                Policy transition_policy, std::vector<TransitionArtefacts> trained, uint64_t seed,
                const Distributed& group = Distributed::alone());
  // Runs `n` attempts (with their updates) and reports on them.
  SwitchStats run(int n);
  int attempts_done() const { return attempts_; }
  // Seconds spent in run() so far, over resumes.
  double wall_seconds() const { return wall_seconds_; }
  // Everything later attempts depend on: q_ab, its target and optimiser, the replay
  // buffer, the counters and both random streams (ours and LibTorch's, which draws the
  // minibatches). A trainer built as this one was and loaded from it continues exactly as
  // this one would. Written atomically.
  void save(const std::string& path) const;
  void load(const std::string& path);
  // Environment steps so far: pi_ab's in the interval and pi_b's subtasks after switches.
  int64_t env_steps() const { return env_steps_; }
  // q_ab as a function of switch_input() (the task observation, then the task's features
  // with switch.interval_features): forward(in) -> [Q(stay), Q(switch)], input
  // normalisation included (exported like a policy, with unbounded outputs). The margin is
  // added to Q(stay), so that the exported rule "switch where Q(switch) > Q(stay)" is the
  // rule with the margin.
  Policy q_function(double margin = 0.0) const;
  // From each held-out start: pi_ab runs through the interval (its path does not depend on
  // the margin); each margin's hand-over point is the first state where Q(switch) > Q(stay)
  // + m, else the interval's end; pi_b is judged from each distinct point as in training.
  MarginChoice choose_margin();
  const std::vector<SwitchQNetwork>& networks() const { return q_; }

 private:
  struct Outcome {
    bool success;
    int switch_step;
  };
  Outcome attempt(bool random);
  void store(const float* s, int a, double r, const float* s2, bool done);
  // Appends a normalised transition to the replay ring.
  void push(const float* s, int64_t a, float r, const float* s2, float done);
  // A round of attempts on several ranks (run()'s body there).
  void run_round(int round, SwitchStats& s, int& updates);
  double update();
  int greedy(const float* in);
  // switch_input() at the env's current state, whose features must be current in features_.
  void q_input(const float* obs, float* in);
  // pi_b takes over at the state in `obs` (the task observation, updated in place): did it succeed?
  bool hand_over(float* obs);

  SwitchConfig cfg_;
  const CompositeRecipe& recipe_;
  const Transition& tr_;
  StartStates starts_;
  Policy pi_ab_;
  std::unique_ptr<Env> env_;
  TransitionController after_;  // judges a hand-over: pi_b, then With TP (run_subtask)
  // The ensemble's members (switch.ensemble; one for the paper's q_ab), each with its target.
  std::vector<SwitchQNetwork> q_, target_;
  std::vector<std::unique_ptr<torch::optim::Adam>> opt_;
  EigenMlp mean_network() const;  // the members' mean as one MLP
  // q_ab for per-step inference, as q_function() exports it: input (s - mean) / std from
  // the probe clipped to +-5, then switch.fourier's features of s; refreshed after updates.
  Policy q_ab_;
  Rng rng_;
  // Replay buffer, a ring of `replay` rows.
  std::vector<float> obs_, next_obs_;
  std::vector<int64_t> action_;
  std::vector<float> reward_, done_;
  int64_t stored_ = 0;
  int attempts_ = 0, updates_ = 0, interval_length_ = 1;
  int train_starts_ = 0;  // S_a's first train_starts_ states train; the rest are held out
  int64_t env_steps_ = 0, rank0_rows_ = 0;
  const Distributed& group_;
  // This rank's transitions of the round in flight, normalised: obs, next obs, then per
  // row action, reward, done.
  std::vector<float> pending_obs_, pending_next_, pending_reward_, pending_done_;
  std::vector<int64_t> pending_action_;
  double wall_seconds_ = 0;
  std::vector<float> full_, next_full_, qvals_, in_, next_in_;
  std::vector<double> features_, state_;
};

}  // namespace segue
