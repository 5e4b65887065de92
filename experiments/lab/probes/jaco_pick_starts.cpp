// Probe: the states a pick episode starts from (after the reset's random steps) against how
// it ends. Per failed episode, and as means over successes and failures: the hand-box
// distance, the hand's height, the arm's joint speeds and the finger angles at the start,
// the box's start and end and the hand's closest approach. Then whether any policy could
// save those episodes: each is played again from the same start with all six arm motors
// braking against their joints' velocities for 5 or 10 steps before the policy takes over;
// one that fails all three ways with the box still moved > 0.1 m after the 10-step brake is
// lost to the reset whatever the arm does.
// usage: probe_jaco_pick_starts POLICY.pt [episodes]   (the reference task: 10 random steps)
#include <cmath>
#include <cstdio>
#include <string>
#include "algorithms/policy.h"
#include "core/rng.h"
#include "environments/jaco.h"
#include "environments/registry.h"
using namespace segue;

namespace {
// Plays one episode from the env's current state: a brake for `brake` steps, then the policy.
// Returns success; `moved_at_10` gets the box's distance from `box0` after 10 steps.
bool play(JacoEnv& env, Policy& p, int brake, float* obs, float* act, const Vec3& box0, double& closest,
          double& moved_at_10) {
  StepResult r;
  int t = 0;
  do {
    if (t < brake) {
      for (int k = 0; k < 6; ++k) act[k] = obs[16 + k] > 0 ? -1.f : 1.f;
      for (int k = 6; k < 9; ++k) act[k] = 0.f;
    } else {
      p.act(obs, 1, act);
    }
    r = env.step(act, obs);
    closest = std::min(closest, env.hand_object_distance());
    if (++t == 10) moved_at_10 = distance(box0, env.object_pos());
  } while (!r.done());
  return r.info.success;
}
}  // namespace

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
  // per group (0 failure, 1 success): count, distance, hand z, arm speed, finger angle sum
  double sum[2][5] = {};
  int knocked[2] = {0, 0};  // episodes whose box the random steps already set moving (> 0.1 m/s)
  int braked_wins[2] = {0, 0}, any = 0, lost = 0;
  for (int e = 0; e < episodes; ++e) {
    env->reset(mix_seed(0, e), obs.data());
    env->save_state(start);
    const double d = j->hand_object_distance(), hz = j->hand_pos()[2];
    double speed = 0, fingers = 0;
    for (int k = 0; k < 6; ++k) speed += obs[16 + k] * obs[16 + k];
    for (int k = 6; k < 9; ++k) fingers += obs[k];
    speed = std::sqrt(speed);
    const double wrist = std::fabs(obs[21]);
    const Vec3 v = j->object_velocity();
    const double box_speed = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    const Vec3 box0 = j->object_pos();
    double closest = d, moved = 0;
    const int g = play(*j, p, 0, obs.data(), act.data(), box0, closest, moved) ? 1 : 0;
    const Vec3 box1 = j->object_pos();
    double row[5] = {1, d, hz, speed, fingers};
    for (int k = 0; k < 5; ++k) sum[g][k] += row[k];
    if (box_speed > 0.1) ++knocked[g];
    bool saved = g;
    for (int b = 0; b < 2; ++b) {
      double ignored = 0;
      env->restore_state(start, obs.data());
      const bool won = play(*j, p, b ? 10 : 5, obs.data(), act.data(), box0, ignored, moved);
      braked_wins[b] += won;
      saved = saved || won;
    }
    any += saved;
    lost += !saved && moved > 0.1;
    if (!g)
      std::printf("ep %3d fail: start d %.3f hand z %.3f arm speed %.2f (j6 %.2f) fingers %.2f box speed %.3f | "
                  "box (%.2f %.2f %.2f) -> (%.2f %.2f %.2f) closest %.3f\n",
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
  std::printf("successes: policy %.0f, brake 5 then policy %d, brake 10 then policy %d, any of the three %d\n",
              sum[1][0], braked_wins[0], braked_wins[1], any);
  std::printf("failed all three ways: %d, of them with the box > 0.1 m from its start after a 10-step brake: %d\n",
              episodes - any, lost);
}
