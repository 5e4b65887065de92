// Developer probe (not part of `segue`): how often With TP gets through a transition's
// subtask, judged as switch training judges a hand-over at the interval's end with
// lookahead 2 (the second skill change after the transition begins).
//   from-sa:    episodes restored from RUN/a-b/start_states.pt (what switch training sees)
//   in-context: whole With TP episodes, every time the transition begins
//   switch-at:  from S_a, pi_ab for k steps, then pi_b (switch training's hand-over,
//               lookahead 2), for k = 0, 10, 20, ... and at the interval's end: where in
//               the interval a hand-over succeeds most, i.e. what q_ab could gain over With TP
// Build: cmake --build build --target probe_subtask_success
// usage: build/probe_subtask_success RECIPE RUN_DIR TRANSITION_INDEX from-sa|in-context|switch-at N
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/assets.h"
#include "hrl/collection.h"
#include "hrl/switch_training.h"

using namespace segue;

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(stderr, "usage: %s RECIPE RUN_DIR TRANSITION_INDEX from-sa|in-context|switch-at N\n", argv[0]);
    return 2;
  }
  const CompositeRecipe r = CompositeRecipe::load(argv[1]);
  const std::string run = argv[2], mode = argv[4];
  const int t = std::atoi(argv[3]), n = std::atoi(argv[5]);
  const auto artefacts = load_transition_artefacts(r, repo_path(run), "policy.pt", false);
  TransitionController c(r.skills, r.meta, artefacts, SwitchRule::IntervalEnd);
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
  } else if (mode == "switch-at") {
    StartStates s = load_start_states(run + "/" + r.transition_name(t) + "/start_states.pt");
    const Transition& tr = r.meta.transitions()[t];
    const Skill& b = r.skills[tr.to];
    Policy pi_ab = *artefacts.at(t).policy;
    std::vector<double> state, features(env->spec().feature_names.size());
    std::vector<int> at_k, tried_k;  // by k / 10
    int end_ok = 0, falls = 0, any_ok = 0, rescued = 0;
    // k = 0 by where the start is, per 10 m of x (snapshot[2], the walker's root x): on
    // Hurdle, the curb the hand-over is for.
    std::vector<int> k0_ok(16, 0), k0_tried(16, 0);
    for (int i = 0; i < n; ++i) {
      bool some = false, last = false;  // some k succeeded; the last k before the end or fall did
      for (int k = 0;; k += 10) {
        s.state(i % s.size(), state);
        env->restore_state(state, obs.data());
        bool left = false, fell = false;
        for (int step = 0; step < k && !left && !fell; ++step) {
          pi_ab.act(obs.data() + b.obs_begin, 1, act.data());
          StepResult sr = env->step(act.data(), obs.data());
          env->features(features.data());
          fell = sr.terminated;
          left = sr.truncated || !MetaController::holds(tr.when, features.data());
        }
        if (fell) { ++falls, rescued += last; break; }
        const bool success = run_subtask(*env, c, tr.to, obs.data(), 2, 5000);
        some = some || success;
        if (left) { end_ok += success; break; }  // the forced switch: With TP
        if (k == 0) {
          const int at = std::min(15, std::max(0, int(state[2] / 10)));
          ++k0_tried[at], k0_ok[at] += success;
        }
        if (tried_k.size() <= size_t(k / 10)) tried_k.push_back(0), at_k.push_back(0);
        ++tried_k[k / 10], at_k[k / 10] += success, last = success;
      }
      any_ok += some;
    }
    std::printf("some k succeeds (a per-start oracle): %d of %d; of the %d falls, a switch at the last k "
                "before it succeeds in %d\n", any_ok, n, falls, rescued);
    for (size_t j = 0; j < tried_k.size(); ++j) std::printf("switch at %3zu: %d of %d\n", 10 * j, at_k[j], tried_k[j]);
    std::printf("interval end (With TP): %d of %d; %d fell before it\n", end_ok, n - falls, falls);
    for (int j = 0; j < 16; ++j)
      if (k0_tried[j]) std::printf("switch at 0, start x in [%d, %d) m: %d of %d\n", 10 * j, 10 * j + 10, k0_ok[j], k0_tried[j]);
    return 0;
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
