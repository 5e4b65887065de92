// Developer probe (not part of `segue`): where a composite task's episodes are lost. Runs
// a method's episodes as `segue eval` does (episode i from mix_seed(SEED, i)) and, for each
// episode that ends in a fall, says who was in control (a skill, or pi_ab of a transition)
// and how many successes the episode had by then (on Hurdle: the curb it fell at); with
// FEATURE, also that feature's value at the fall, to 0.5 (e.g. curb_behind: how far past
// the last curb).
// Build: cmake --build build --target probe_episode_ends
// usage: build/probe_episode_ends RECIPE METHOD EPISODES SEED [FEATURE]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "core/rng.h"
#include "hrl/composite_recipe.h"
#include "hrl/transition_controller.h"

using namespace segue;

int main(int argc, char** argv) {
  if (argc != 5 && argc != 6) {
    std::fprintf(stderr, "usage: %s RECIPE METHOD EPISODES SEED [FEATURE]\n", argv[0]);
    return 2;
  }
  try {
    const CompositeRecipe r = CompositeRecipe::load(argv[1]);
    const std::string method = argv[2];
    const int episodes = std::atoi(argv[3]);
    const uint64_t seed = std::strtoull(argv[4], nullptr, 10);
    ControllerFactory make = method_controllers(r, method);
    auto env = r.make_env();
    std::vector<float> obs(r.spec.obs_dim), act(r.spec.act_dim);
    int feature = -1;
    if (argc == 6) {
      const auto& names = r.spec.feature_names;
      feature = int(std::find(names.begin(), names.end(), std::string(argv[5])) - names.begin());
      if (feature == int(names.size())) throw Error(std::string("no feature '") + argv[5] + "' in " + r.task);
    }
    std::vector<double> f(r.spec.feature_names.size());
    std::map<std::pair<int, std::string>, int> falls;  // (successes so far, in control) -> count
    std::map<std::pair<std::string, double>, int> at;  // (in control, feature to 0.5) -> count
    double total = 0;
    for (int e = 0; e < episodes; ++e) {
      auto c = make();
      env->reset(mix_seed(seed, e), obs.data());
      c->reset(*env, obs.data());
      for (;;) {
        c->act(*env, obs.data(), act.data());
        StepResult sr = env->step(act.data(), obs.data());
        if (!sr.done()) continue;
        total += sr.info.success_count;
        if (sr.terminated) {
          std::string who = "its own policy";
          if (auto* t = dynamic_cast<TransitionController*>(c.get()))
            who = t->transition() >= 0 ? "pi_ab " + r.transition_name(t->transition()) : r.skills[t->skill()].name;
          ++falls[{sr.info.success_count, who}];
          if (feature >= 0) env->features(f.data()), ++at[{who, 0.5 * std::floor(2 * f[feature])}];
        }
        break;
      }
    }
    std::printf("%s, %s: mean success count %.2f over %d episodes (seed %llu)\n", r.task.c_str(), method.c_str(),
                total / episodes, episodes, (unsigned long long)seed);
    for (const auto& [key, n] : falls)
      std::printf("  fell after %d successes, %s in control: %d\n", key.first, key.second.c_str(), n);
    for (const auto& [key, n] : at)
      std::printf("  fell with %s in [%g, %g), %s in control: %d\n", argv[5], key.second, key.second + 0.5,
                  key.first.c_str(), n);
  } catch (const Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
