// Developer probe (not part of `segue`): does a better continuation exist from a jump
// policy's approach? Each episode runs the policy deterministically until the curb's start
// is D m ahead, saves the full state, and from it runs the policy on (the nominal) and K
// continuations with Gaussian action noise (std SIGMA) held for HOLD steps, so that a hop
// is made longer or shorter as a whole. Prints, over N episodes, how often the nominal
// clears the curb and how often at least one continuation does.
// Build: cmake --build build --target probe_jump_branches
// usage: build/probe_jump_branches POLICY N SEED D K SIGMA HOLD [key=value ...]  (env keys)
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "algorithms/policy.h"
#include "environments/walker_obstacles.h"
#include "experiments/lab/probes/jump_env.h"

using namespace segue;

int main(int argc, char** argv) {
  if (argc < 8) {
    std::fprintf(stderr, "usage: %s POLICY N SEED D K SIGMA HOLD [key=value ...]\n", argv[0]);
    return 2;
  }
  const std::unique_ptr<Env> env = jump_env_from_args(8, argc, argv);
  const Policy pi = Policy::load(argv[1]);
  const int n = std::atoi(argv[2]), k = std::atoi(argv[5]), hold = std::atoi(argv[7]);
  const uint64_t seed = std::strtoull(argv[3], nullptr, 10);
  const double dist = std::atof(argv[4]), sigma = std::atof(argv[6]);
  const int obs_dim = env->spec().obs_dim, act_dim = env->spec().act_dim;
  std::vector<float> obs(obs_dim), act(act_dim), noise(act_dim);
  std::vector<double> state;
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> normal(0.f, float(sigma));
  // Runs from the current state to the episode's end; true on success.
  auto run = [&](bool noisy) {
    for (int t = 0;; ++t) {
      pi.act(obs.data(), 1, act.data());
      if (noisy) {
        if (t % hold == 0)
          for (auto& z : noise) z = normal(rng);
        for (int i = 0; i < act_dim; ++i) act[i] += noise[i];
      }
      StepResult r = env->step(act.data(), obs.data());
      if (r.done()) return r.info.success;
    }
  };
  int reached = 0, nominal = 0, any = 0, branches = 0;
  for (int e = 0; e < n; ++e) {
    env->reset(seed + e, obs.data());
    bool ended = false;
    while (obs[obs_dim - 2] > dist && !ended) {  // (start - x, end - x) close the observation
      pi.act(obs.data(), 1, act.data());
      ended = env->step(act.data(), obs.data()).done();
    }
    if (ended) continue;
    ++reached;
    env->save_state(state);
    const bool ok = run(false);
    int wins = 0;
    for (int b = 0; b < k; ++b) {
      env->restore_state(state, obs.data());
      wins += run(true);
    }
    nominal += ok;
    any += ok || wins > 0;
    branches += wins;
    std::printf("episode %d: curb at %.2f, nominal %s, %d of %d continuations clear\n", e,
                dynamic_cast<const WalkerJump&>(*env).obstacles()[0].start, ok ? "clears" : "fails", wins, k);
  }
  std::printf("reached %d of %d; nominal clears %d; some continuation or the nominal %d; continuations %.1f%%\n",
              reached, n, nominal, any, 100.0 * branches / std::max(1, reached * k));
}
