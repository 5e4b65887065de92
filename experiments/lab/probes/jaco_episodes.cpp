// Lab probe: how the arm skill of a checkpoint ends its episodes on the reference task
// (success, failure with the object height and hand distance, or the time limit).
//   build/probe_jaco_episodes CHECKPOINT TASK
#include <cstdio>
#include "algorithms/policy.h"
#include "algorithms/ppo.h"
#include "environments/registry.h"
#include "environments/jaco_skills.h"
#include "core/rng.h"
using namespace segue;
int main(int argc, char** argv) {
  Policy p = PPO::policy_from_checkpoint(argv[1]);
  auto make = reference_task_factory(argv[2]);
  auto env = make();
  auto* j = dynamic_cast<JacoEnv*>(env.get());
  int n = env->spec().obs_dim;
  std::vector<float> obs(n), act(9);
  int succ = 0, fail = 0, timeout = 0;
  for (int e = 0; e < 100; ++e) {
    env->reset(mix_seed(0, e), obs.data());
    StepResult r; int t = 0; double maxz = 0;
    do { p.act(obs.data(), 1, act.data()); r = env->step(act.data(), obs.data()); ++t; maxz = std::max(maxz, j->object_z()); } while (!r.done());
    if (r.info.success) succ++; else if (r.terminated) { fail++; printf("ep %d fail at t=%d z=%.3f maxz=%.3f d=%.3f\n", e, t, j->object_z(), maxz, j->hand_object_distance()); } else { timeout++; printf("ep %d timeout z=%.3f maxz=%.3f d=%.3f\n", e, j->object_z(), maxz, j->hand_object_distance()); }
  }
  printf("success %d fail %d timeout %d\n", succ, fail, timeout);
}
