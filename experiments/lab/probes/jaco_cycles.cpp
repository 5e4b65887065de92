// Developer probe (not part of `segue`): how a repetitive arm task's cycles go, episode by
// episode: the step of each success, the six arm joints' angles there (unlimited joints can
// wind up over cycles), and how the episode ended (who was in control, box height, hand
// distance, steps since the last success).
// Build: cmake --build build --target probe_jaco_cycles
// usage: build/probe_jaco_cycles RECIPE METHOD EPISODES SEED [KEY=VALUE ...]  (as segue's --set)
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/rng.h"
#include "environments/jaco.h"
#include "hrl/composite_recipe.h"
#include "hrl/transition_controller.h"

using namespace segue;

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: %s RECIPE METHOD EPISODES SEED [KEY=VALUE ...]\n", argv[0]);
    return 2;
  }
  try {
    const CompositeRecipe r = CompositeRecipe::load(argv[1], std::vector<std::string>(argv + 5, argv + argc));
    ControllerFactory make = method_controllers(r, argv[2]);
    auto env = r.make_env();
    auto* j = dynamic_cast<JacoEnv*>(env.get());
    if (!j) throw Error(r.task + " is not an arm task");
    std::vector<float> obs(r.spec.obs_dim), act(r.spec.act_dim);
    const int episodes = std::atoi(argv[3]);
    const uint64_t seed = std::strtoull(argv[4], nullptr, 10);
    double total = 0;
    for (int e = 0; e < episodes; ++e) {
      auto c = make();
      env->reset(mix_seed(seed, e), obs.data());
      c->reset(*env, obs.data());
      int t = 0, last = 0, count = 0;
      std::printf("ep %2d:", e);
      for (;;) {
        c->act(*env, obs.data(), act.data());
        StepResult sr = env->step(act.data(), obs.data());
        ++t;
        if (sr.info.success_count > count) {
          count = sr.info.success_count, last = t;
          const double* q = j->data()->qpos;
          std::printf(" [%d q=%.1f %.1f %.1f %.1f %.1f %.1f]", t, q[0], q[1], q[2], q[3], q[4], q[5]);
        }
        if (!sr.done()) continue;
        std::string who = "own";
        if (auto* tc = dynamic_cast<TransitionController*>(c.get()))
          who = tc->transition() >= 0 ? "pi_ab" : r.skills[tc->skill()].name;
        std::printf(" -> %s at t=%d (+%d) %s z=%.3f d=%.3f\n", sr.terminated ? "end" : "cut", t, t - last,
                    who.c_str(), j->object_z(), j->hand_object_distance());
        total += sr.info.success_count;
        break;
      }
    }
    std::printf("mean success count %.2f over %d episodes\n", total / episodes, episodes);
  } catch (const Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
