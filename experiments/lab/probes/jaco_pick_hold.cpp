// Probe: how a pick or catch policy holds its box, episode by episode: the lift step, the
// held steps, the hand-box distance while held, the finger actions and angles, and for a
// failure the box's start, end and closest approach (a box knocked away, or one that slips),
// and the step of the box's fastest horizontal move before any pick with what touched it then.
// usage: probe_jaco_pick_hold POLICY.pt TASK [episodes]   (the task's reference settings)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include "algorithms/policy.h"
#include "core/rng.h"
#include "environments/jaco.h"
#include "environments/registry.h"
using namespace segue;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s POLICY.pt TASK [episodes]\n", argv[0]);
    return 2;
  }
  Policy p = Policy::load(argv[1]);
  auto env = reference_task_factory(argv[2])();
  auto* j = dynamic_cast<JacoEnv*>(env.get());
  if (!j) {
    std::fprintf(stderr, "%s is not an arm task\n", argv[2]);
    return 2;
  }
  const int episodes = argc > 3 ? std::stoi(argv[3]) : 100;
  const double in_hand = 0.06, in_air = 0.05;  // the tasks' defaults (jaco.md §3)
  std::vector<float> obs(env->spec().obs_dim), act(env->spec().act_dim);
  int successes = 0;
  for (int e = 0; e < episodes; ++e) {
    env->reset(mix_seed(0, e), obs.data());
    StepResult r;
    int t = 0, held = 0, lift = -1, t_closest = 0;
    double dsum = 0, dmax = 0, closest = 9, fa[3] = {0, 0, 0}, fq[3] = {0, 0, 0};
    const Vec3 start = j->object_pos();
    Vec3 at_closest = start;
    double vmax = 0;
    int t_vmax = 0;
    std::string touch;  // the geoms touching the box at its fastest move before a pick
    do {
      p.act(obs.data(), 1, act.data());
      r = env->step(act.data(), obs.data());
      ++t;
      const double d = j->hand_object_distance();
      if (d < closest) closest = d, t_closest = t, at_closest = j->object_pos();
      const Vec3 v = j->object_velocity();
      const double speed = std::hypot(v[0], v[1]);
      if (lift < 0 && speed > vmax) {
        vmax = speed, t_vmax = t, touch.clear();
        const mjModel* m = j->model();
        const mjData* dd = j->data();
        for (int c = 0; c < dd->ncon; ++c) {
          const int g1 = dd->contact[c].geom1, g2 = dd->contact[c].geom2;
          const char* n1 = mj_id2name(m, mjOBJ_GEOM, g1);
          const char* n2 = mj_id2name(m, mjOBJ_GEOM, g2);
          const std::string a = n1 ? n1 : "?", b = n2 ? n2 : "?";
          if (a == "object") touch += " " + b;
          else if (b == "object") touch += " " + a;
        }
      }
      if (d < in_hand && j->object_z() > in_air) {
        if (lift < 0) lift = t;
        ++held, dsum += d, dmax = std::max(dmax, d);
        for (int k = 0; k < 3; ++k) fa[k] += act[6 + k], fq[k] += j->data()->qpos[6 + k];
      }
    } while (!r.done());
    const int h = std::max(held, 1);
    std::printf("ep %2d %s t=%3d lift@%3d held=%2d dmean=%.3f dmax=%.3f dend=%.3f z=%.3f "
                "fingers a=(%.2f %.2f %.2f) q=(%.2f %.2f %.2f)\n",
                e, r.info.success ? "OK  " : (r.terminated ? "FAIL" : "TIME"), t, lift, held, dsum / h, dmax,
                j->hand_object_distance(), j->object_z(), fa[0] / h, fa[1] / h, fa[2] / h, fq[0] / h, fq[1] / h,
                fq[2] / h);
    if (!r.info.success) {
      const Vec3 b = j->object_pos();
      std::printf("   box start (%.3f %.3f %.3f) end (%.3f %.3f %.3f) closest %.3f at t=%d box then (%.3f %.3f %.3f)\n",
                  start[0], start[1], start[2], b[0], b[1], b[2], closest, t_closest, at_closest[0], at_closest[1],
                  at_closest[2]);
      std::printf("   fastest box move before a pick %.2f m/s at t=%d, touching:%s\n", vmax, t_vmax, touch.c_str());
    }
    successes += r.info.success;
  }
  std::printf("success %d / %d\n", successes, episodes);
}
