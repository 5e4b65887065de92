// Probe: the states a pick episode starts from (after the reset's random steps) against how
// it ends: per failed episode, and as means over successes and failures, the hand-box
// distance, the hand's height, the arm's joint speeds and the finger angles at the start.
// usage: probe_jaco_pick_starts POLICY.pt [episodes]   (the reference task: 10 random steps)
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
  // per group (0 failure, 1 success): count, distance, hand z, arm speed, finger angle sum
  double sum[2][5] = {};
  int knocked[2] = {0, 0};  // episodes whose box the random steps already set moving (> 0.1 m/s)
  for (int e = 0; e < episodes; ++e) {
    env->reset(mix_seed(0, e), obs.data());
    const double d = j->hand_object_distance(), hz = j->hand_pos()[2];
    double speed = 0, fingers = 0, wrist = 0;
    for (int k = 0; k < 6; ++k) speed += obs[16 + k] * obs[16 + k];
    for (int k = 6; k < 9; ++k) fingers += obs[k];
    wrist = std::fabs(obs[21]);
    const double box_speed = std::sqrt(obs[25] * obs[25] + obs[26] * obs[26] + obs[27] * obs[27]);
    speed = std::sqrt(speed);
    const Vec3 box0 = j->object_pos();
    double closest = d;
    StepResult r;
    do {
      p.act(obs.data(), 1, act.data());
      r = env->step(act.data(), obs.data());
      closest = std::min(closest, j->hand_object_distance());
    } while (!r.done());
    const Vec3 box1 = j->object_pos();
    const int g = r.info.success ? 1 : 0;
    double row[5] = {1, d, hz, speed, fingers};
    for (int k = 0; k < 5; ++k) sum[g][k] += row[k];
    if (box_speed > 0.1) ++knocked[g];
    if (!g)
      std::printf("ep %3d fail: start d %.3f hand z %.3f arm speed %.2f (j6 %.2f) fingers %.2f box speed %.3f | box (%.2f %.2f %.2f) -> (%.2f %.2f %.2f) closest %.3f\n",
                  e, d, hz, speed, wrist, fingers, box_speed, box0[0], box0[1], box0[2], box1[0], box1[1], box1[2],
                  closest);
  }
  std::printf("box moving at the start (> 0.1 m/s): %d episodes, %d of them failed\n", knocked[0] + knocked[1],
              knocked[0]);
  for (int g = 0; g < 2; ++g) {
    const double n = std::max(1.0, sum[g][0]);
    std::printf("%s %4.0f: start d %.3f hand z %.3f arm speed %.2f fingers %.2f\n", g ? "successes" : "failures ",
                sum[g][0], sum[g][1] / n, sum[g][2] / n, sum[g][3] / n, sum[g][4] / n);
  }
}
