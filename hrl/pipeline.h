#pragma once
// `segue run RECIPE`: Algorithms 1 and 2 for every transition of a composite task, then
// the results table. Stages 1-2 run for every transition, then 3 for every one, then 4.
// Per transition NAME ("walk-jump"), in the run directory:
//   1. collect     NAME/start_states.pt (S_a), NAME/demonstrations.pt (T_b)
//   2. transition  NAME/policy.pt (pi_ab, TorchScript), NAME/transition.csv; training
//                  checkpoints to NAME/transition_checkpoint.pt and resumes from it
//   3. switch      NAME/q.pt (q_ab, TorchScript), NAME/switch.csv
//   4. lee         NAME/lee.pt (Lee et al.'s transition policy, TorchScript), NAME/lee.csv;
//                  checkpoints to NAME/lee_checkpoint.pt (recipe key lee.enabled)
// and finally
//   5. evaluate    TASK.md / TASK.json: every method whose artefacts exist, 50 episodes x 3
//                  seeds (the recipe's eval:), also written to --publish DIR; NAME/actions.csv,
//                  the actions of pi_a, pi_ab and pi_b from the same S_a states through the
//                  interval (paper Fig. 4: tools/tsne_actions.py draws it)
// A stage whose outputs exist is skipped, so rerunning an interrupted run resumes it.
#include <atomic>
#include <string>
#include <vector>

#include "core/distributed.h"
#include "hrl/composite_recipe.h"

namespace segue {

struct PipelineOptions {
  int threads = 1;                     // environment stepping
  const std::atomic<int>* stop = nullptr;  // set by a signal: checkpoint and return
  std::string publish_dir;             // also write the table here ("" = only the run dir)
  std::string command;                 // how the run was started, for the table
  // Several ranks (segue run --nproc N): the PPO stages (pi_ab with its D, Lee's policy)
  // are data-parallel, collection and the switch's attempts are split between the ranks;
  // rank 0 writes the run directory, which every rank must see (one host, or a shared
  // filesystem), and evaluates alone.
  const Distributed* group = &Distributed::alone();
};

// Returns 0 when every stage is done, or the signal number when stopped early.
int run_pipeline(const CompositeRecipe& recipe, const PipelineOptions& options);

}  // namespace segue
