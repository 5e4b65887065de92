// Developer probe (not part of `segue`): how a jump policy's episodes end on the
// reference jump task. For each episode: success, fall or curb contact; for a contact,
// which geom touched and where the walker was; how deep it reached into the curb (with
// ghost_curbs=true); and where its last two-footed stance before the curb was (mean ankle
// x minus the curb's start): the take-off point of a hop; and the frontmost footfall before
// the curb (either foot's ankle x minus the curb's start): the take-off of an alternating run.
// Also: per action dimension, the fraction of steps whose mean action (before the clamp to
// the ctrl range) lies outside the range, where exploration noise added to it is clamped away.
// TRACE=1 prints every step near the curb.
// Build: cmake --build build --target probe_jump_failures
// usage: build/probe_jump_failures POLICY N SEED [key=value ...]  (env keys, e.g. curb_height=0.2)
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "algorithms/policy.h"
#include "core/mujoco_env.h"
#include "environments/walker_obstacles.h"
#include "experiments/lab/probes/jump_env.h"

using namespace segue;

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s POLICY N SEED [key=value ...]\n", argv[0]);
    return 2;
  }
  const std::unique_ptr<Env> env = jump_env_from_args(4, argc, argv);
  auto* walker = dynamic_cast<WalkerJump*>(env.get());
  const MujocoEnv* mj = walker;
  const Policy pi = Policy::load(argv[1]);
  const int n = std::atoi(argv[2]);
  const uint64_t seed = std::strtoull(argv[3], nullptr, 10);
  const mjModel* m = mj->model();
  const int floor = mj_name2id(m, mjOBJ_GEOM, "floor");
  const int f1 = mj_name2id(m, mjOBJ_BODY, "foot"), f2 = mj_name2id(m, mjOBJ_BODY, "foot_left");
  std::map<std::string, std::vector<double>> stances;  // outcome -> last stances
  std::map<std::string, std::vector<double>> takeoffs;  // outcome -> frontmost footfalls
  std::map<std::string, int> ends;
  const EnvSpec& spec = env->spec();
  std::vector<float> obs(spec.obs_dim), act(spec.act_dim), x(pi.in_dim()), mu(spec.act_dim);
  std::vector<long> outside(spec.act_dim, 0);
  long total_steps = 0;
  for (int e = 0; e < n; ++e) {
    env->reset(seed + e, obs.data());
    int steps = 0;
    double deepest = 0.0;  // the walker's summed depth in the curb (nonzero only with ghost curbs)
    double last_stance = NAN;
    double takeoff = NAN;  // the last foot on the ground before the curb (an alternating gait's take-off)
    for (;;) {
      pi.act(obs.data(), 1, act.data());
      pi.normalize(obs.data(), 1, x.data());
      pi.mlp().forward(x.data(), 1, mu.data());
      for (int j = 0; j < spec.act_dim; ++j) outside[j] += mu[j] < spec.act_low[j] || mu[j] > spec.act_high[j];
      ++total_steps;
      StepResult r = env->step(act.data(), obs.data());
      ++steps;
      const mjData* d = mj->data();
      const Obstacle& curb = walker->obstacles()[0];
      const double depth = walker->depth_in_curb(0);
      deepest = std::max(deepest, depth);
      const double a1 = d->xpos[3 * f1] - curb.start, a2 = d->xpos[3 * f2] - curb.start;
      if (d->xpos[3 * f1 + 2] < 0.07 && d->xpos[3 * f2 + 2] < 0.07 && std::max(a1, a2) < 0) last_stance = 0.5 * (a1 + a2);
      double front = -INFINITY;  // the frontmost foot standing this step, as the env's placement_bonus counts it
      if (std::max(a1, a2) < 0)
        for (auto [z, a] : {std::pair{d->xpos[3 * f1 + 2], a1}, std::pair{d->xpos[3 * f2 + 2], a2}})
          if (z < 0.07) front = std::max(front, a);
      if (front > -INFINITY) takeoff = front;
      if (std::getenv("TRACE") && d->qpos[0] > curb.start - 2.0) {
        std::printf("  x-start %+.2f torso z %.2f  foot (%+.2f, %.2f)  foot_left (%+.2f, %.2f)\n", d->qpos[0] - curb.start,
                    d->qpos[1], d->xpos[3 * f1] - curb.start, d->xpos[3 * f1 + 2], d->xpos[3 * f2] - curb.start,
                    d->xpos[3 * f2 + 2]);
      }
      if (!r.done()) continue;
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
      const std::string outcome = why.substr(0, why.find_first_of(" ,"));
      if (!std::isnan(last_stance)) stances[outcome].push_back(last_stance);
      if (!std::isnan(takeoff)) takeoffs[outcome].push_back(takeoff);
      std::printf("episode %d: %s after %d steps, torso x %.2f, obs start-x %.2f, deepest %.3f, last stance %.2f, "
                  "take-off %.2f\n", e, why.c_str(), steps, d->qpos[0], obs[26], deepest, last_stance, takeoff);
      break;
    }
  }
  for (auto [what, by_outcome] : {std::pair{"last stance", &stances}, std::pair{"take-off", &takeoffs}})
    for (auto& kv : *by_outcome) {
      std::sort(kv.second.begin(), kv.second.end());
      std::printf("%s before the curb, %s:", what, kv.first.c_str());
      for (double x : kv.second) std::printf(" %.2f", x);
      std::printf("\n");
    }
  for (auto& kv : ends) std::printf("%-32s %d\n", kv.first.c_str(), kv.second);
  std::printf("mean action outside the ctrl range, fraction of %ld steps per dimension:", total_steps);
  for (long k : outside) std::printf(" %.2f", double(k) / double(total_steps));
  std::printf("\n");
}
