// Developer probe (not part of `segue`): how a jump policy's episodes end on the
// reference jump task. For each episode: success, fall or curb contact; for a contact,
// which geom touched and where the walker was; the highest both feet were off the ground
// before the curb.
// Build: cmake --build build --target probe_jump_failures
// usage: build/probe_jump_failures POLICY N SEED [key=value ...]  (env keys, e.g. curb_height=0.2)
#include <mujoco/mujoco.h>

#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "algorithms/policy.h"
#include "core/mujoco_env.h"
#include "core/recipe.h"
#include "environments/walker_obstacles.h"
#include "environments/registry.h"

using namespace segue;

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s POLICY N SEED [key=value ...]\n", argv[0]);
    return 2;
  }
  std::string yaml = "{";
  for (int i = 4; i < argc; ++i) {
    std::string kv = argv[i];
    auto eq = kv.find('=');
    yaml += (i > 4 ? ", " : "") + kv.substr(0, eq) + ": " + kv.substr(eq + 1);
  }
  yaml += "}";
  auto env = task_factory("walker_jump", Recipe::parse(yaml, "probe").root())();
  auto* walker = dynamic_cast<WalkerObstacleEnv*>(env.get());
  const MujocoEnv* mj = walker;
  const Policy pi = Policy::load(argv[1]);
  const int n = std::atoi(argv[2]);
  const uint64_t seed = std::strtoull(argv[3], nullptr, 10);
  const mjModel* m = mj->model();
  const int floor = mj_name2id(m, mjOBJ_GEOM, "floor");
  std::map<std::string, int> ends;
  std::vector<float> obs(env->spec().obs_dim), act(env->spec().act_dim);
  for (int e = 0; e < n; ++e) {
    env->reset(seed + e, obs.data());
    int steps = 0;
    for (;;) {
      pi.act(obs.data(), 1, act.data());
      StepResult r = env->step(act.data(), obs.data());
      ++steps;
      if (!r.done()) continue;
      const mjData* d = mj->data();
      std::string why;
      if (r.info.success) why = "success";
      else if (r.truncated) why = "time limit";
      else if (d->qpos[1] < 0.8)
        why = std::string("fall, curb ") + (walker->min_x() < walker->obstacles()[0].end ? "ahead" : "behind");
      else {
        for (int c = 0; c < d->ncon; ++c) {
          int g1 = d->contact[c].geom1, g2 = d->contact[c].geom2;
          if (g1 == floor || g2 == floor) continue;
          const char* a = mj_id2name(m, mjOBJ_GEOM, g1);
          const char* b = mj_id2name(m, mjOBJ_GEOM, g2);
          why = std::string("contact ") + (a ? a : "?") + "/" + (b ? b : "?");
          break;
        }
        if (why.empty()) why = "touched earlier (contact_ends false)";
      }
      ++ends[why];
      std::printf("episode %d: %s after %d steps, torso x %.2f, obs start-x %.2f\n", e, why.c_str(), steps,
                  d->qpos[0], obs[26]);
      break;
    }
  }
  for (auto& kv : ends) std::printf("%-32s %d\n", kv.first.c_str(), kv.second);
}
