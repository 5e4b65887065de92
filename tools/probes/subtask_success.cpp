// Developer probe (not part of `segue`): how often With TP gets through a transition's
// subtask, judged as switch training judges a hand-over at the interval's end with
// lookahead 2 (the second skill change after the transition begins).
//   from-sa:    episodes restored from RUN/a-b/start_states.pt (what switch training sees)
//   in-context: whole With TP episodes, every time the transition begins
// Build: cmake --build build --target probe_subtask_success
// usage: build/probe_subtask_success RECIPE RUN_DIR TRANSITION_INDEX from-sa|in-context N
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/assets.h"
#include "hrl/collection.h"
#include "hrl/switch_training.h"

using namespace segue;

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(stderr, "usage: %s RECIPE RUN_DIR TRANSITION_INDEX from-sa|in-context N\n", argv[0]);
    return 2;
  }
  const CompositeRecipe r = CompositeRecipe::load(argv[1]);
  const std::string run = argv[2], mode = argv[4];
  const int t = std::atoi(argv[3]), n = std::atoi(argv[5]);
  TransitionController c(r.skills, r.meta, load_transition_artefacts(r, repo_path(run), "policy.pt", false),
                         SwitchRule::IntervalEnd);
  auto env = r.make_env();
  std::vector<float> obs(env->spec().obs_dim), act(env->spec().act_dim);
  int starts = 0, ok = 0;
  if (mode == "from-sa") {
    StartStates s = load_start_states(run + "/" + r.transition_name(t) + "/start_states.pt");
    std::vector<double> state;
    for (int i = 0; i < n; ++i, ++starts) {
      s.state(i % s.size(), state);
      env->restore_state(state, obs.data());
      // From a's phase: the transition into b is the first skill change, then two more.
      ok += run_subtask(*env, c, r.meta.transitions()[t].from, obs.data(), /*lookahead=*/3, /*max_steps=*/5000);
    }
  } else {
    for (int e = 0; e < n; ++e) {
      env->reset(uint64_t(777 + e), obs.data());
      c.reset(*env, obs.data());
      int changes = -1, skill = c.skill();
      for (;;) {
        const int before = c.transition();
        c.act(*env, obs.data(), act.data());
        if (c.transition() == t && before != t) changes = 1, skill = c.skill(), ++starts;
        else if (changes > 0 && c.skill() != skill && (skill = c.skill(), ++changes == 3)) ++ok, changes = -1;
        StepResult sr = env->step(act.data(), obs.data());
        if (sr.done()) {
          if (sr.truncated && changes > 0) ++ok;
          break;
        }
      }
    }
  }
  std::printf("%s, %s: %d of %d\n", r.transition_name(t).c_str(), mode.c_str(), ok, starts);
}
