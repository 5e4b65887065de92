#pragma once
// Algorithm 2: the switch Q-network q_ab, which decides during a transition interval when
// pi_ab hands control to pi_b. An attempt starts from a state of S_a; at every state q_ab
// picks stay (pi_ab acts one step) or switch (pi_b takes over and runs its subtask).
// Rewards (docs/reference/learners.md#switch-network): switch -> r_s if pi_b then
// achieves its subtask, r_f if it fails; stay -> r_f on a fall, else 0. How far "its
// subtask" reaches is config.lookahead (run_subtask). Every reward but the uneventful stay
// ends the attempt.
// Where the interval runs out while staying, control passes to pi_b as it does when the
// method runs (the forced switch), and that last stay is valued by pi_b's outcome. The
// paper's Algorithm 2 gives r_f there instead, which teaches q_ab that switching at any
// point beats reaching the interval's end, even where pi_ab run to the end (With TP) does
// better: on Patrol that made With TP + Q score below With TP (1.94 vs 3.41 turns).
// Double DQN (Eq. 4) on a replay buffer, hard target copy.
#include <memory>
#include <string>
#include <vector>

#include "algorithms/replay_buffer.h"
#include "algorithms/switch_q_network.h"
#include "core/distributed.h"
#include "core/rng.h"
#include "hrl/pipeline_config.h"
#include "hrl/switch_interval.h"
#include "hrl/switch_margin.h"

namespace segue {

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
  // Attempts go in rounds, one per rank of `group` (each rank its own random stream); every
  // rank's transitions are then stored, in rank order, in every rank's replay buffer, and
  // all ranks make the round's updates alike, so q_ab stays the same on every rank. One
  // process is a group of one. save() is then a collective, rank 0 writing.
  SwitchTrainer(const SwitchConfig& config, SwitchInterval interval, uint64_t seed,
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
  // q_ab as a function of the task observation: forward(obs) -> [Q(stay), Q(switch)],
  // input normalisation included (exported like a policy, with unbounded outputs). The
  // margin is added to Q(stay), so that the exported rule "switch where Q(switch) >
  // Q(stay)" is the rule with the margin.
  Policy q_function(double margin = 0.0) const;
  // The margin chosen on S_a's held-out states (config.validation_starts; hrl/switch_margin.h).
  MarginChoice choose_margin();
  const SwitchQNetwork& network() const { return q_; }

 private:
  struct Outcome {
    bool success;
    int switch_step;
  };
  Outcome attempt(bool random);
  // Records a transition of this rank's attempt, normalised with q_ab's input statistics.
  void store(const float* s, int a, double r, const float* s2, bool done);
  // A round of `round` attempts, one per rank, with their updates.
  void run_round(int round, SwitchStats& s, int& updates);
  double update();
  int greedy(const float* obs);

  SwitchConfig cfg_;
  SwitchInterval interval_;
  SwitchQNetwork q_, target_;
  std::unique_ptr<torch::optim::Adam> opt_;
  // q_ab for per-step inference, as q_function() exports it: input (s - mean) / std from
  // the probe, clipped to +-5; refreshed after updates.
  Policy q_ab_;
  ReplayBuffer replay_;  // the action column holds 0 (stay) or 1 (switch)
  Rng rng_;
  int attempts_ = 0, updates_ = 0, interval_length_ = 1;
  int train_starts_ = 0;  // S_a's first train_starts_ states train; the rest are held out
  int64_t stored_ = 0, env_steps_ = 0, rank0_rows_ = 0;
  const Distributed& group_;
  // This rank's transitions of the round in flight, normalised: obs, next obs, then per
  // row action, reward, done.
  std::vector<float> pending_obs_, pending_next_, pending_reward_, pending_done_;
  std::vector<int64_t> pending_action_;
  double wall_seconds_ = 0;
  std::vector<float> obs_, next_obs_, at_switch_, qvals_;
};

}  // namespace segue
