// Probe: are the pick episodes the reset's random steps spoil recoverable at all? Each
// episode is played from the same post-reset state three ways: the policy throughout, and
// a full brake (each arm motor pushing against its joint's velocity) for 5 or 10 steps
// before the policy takes over. An episode that fails all three ways is counted as lost
// to the reset; the box's distance from its placement after 10 steps says where it went.
// usage: probe_jaco_pick_brake POLICY.pt [episodes]   (the reference task: 10 random steps)
#include <cmath>
#include <cstdio>
#include <string>
#include "algorithms/policy.h"
#include "core/rng.h"
#include "environments/jaco.h"
#include "environments/registry.h"
using namespace segue;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s POLICY.pt [episodes]\n", argv[0]);
    return 2;
  }
  Policy p = Policy::load(argv[1]);
  const int episodes = argc > 2 ? std::stoi(argv[2]) : 300;
  auto env = reference_task_factory("jaco_pick")();
  auto* j = dynamic_cast<JacoEnv*>(env.get());
  std::vector<float> obs(env->spec().obs_dim), act(env->spec().act_dim);
  std::vector<double> start;
  const int brakes[3] = {0, 5, 10};
  int wins[3] = {}, any = 0, lost_far = 0;
  for (int e = 0; e < episodes; ++e) {
    env->reset(mix_seed(0, e), obs.data());
    env->save_state(start);
    const Vec3 box0 = j->object_pos();
    bool won = false;
    double moved = 0;
    for (int s = 0; s < 3; ++s) {
      env->restore_state(start, obs.data());
      StepResult r;
      int t = 0;
      do {
        if (t < brakes[s]) {
          for (int k = 0; k < 6; ++k) act[k] = obs[16 + k] > 0 ? -1.f : 1.f;
          for (int k = 6; k < 9; ++k) act[k] = 0.f;
        } else {
          p.act(obs.data(), 1, act.data());
        }
        r = env->step(act.data(), obs.data());
        if (++t == 10 && s == 2) moved = distance(box0, j->object_pos());
      } while (!r.done());
      if (r.info.success) ++wins[s], won = true;
    }
    if (won) ++any;
    else if (moved > 0.1) ++lost_far;
  }
  std::printf("episodes %d: policy %d, brake 5 then policy %d, brake 10 then policy %d, any of the three %d\n",
              episodes, wins[0], wins[1], wins[2], any);
  std::printf("failed all three ways: %d, of them with the box > 0.1 m from its start after a 10-step brake: %d\n",
              episodes - any, lost_far);
}
