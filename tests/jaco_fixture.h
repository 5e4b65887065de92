#pragma once
// Scripting the arm in tests: a task of a given class, contacts off, the arm held still, the
// object pinned where a scripted sequence wants it.
#include <gtest/gtest.h>

#include "environments/jaco.h"
#include "tests/task_fixture.h"

namespace segue {

template <class T>
inline std::unique_ptr<T> make_arm(const std::string& task, const std::string& env = "{}") {
  std::unique_ptr<Env> e = make_task(task, env);
  T* raw = dynamic_cast<T*>(e.get());
  EXPECT_NE(raw, nullptr);
  e.release();
  return std::unique_ptr<T>(raw);
}

inline mjModel* writable(const MujocoEnv& env) { return const_cast<mjModel*>(env.model()); }

// Turns off every contact of the arm's geoms, so the object flies as if the arm were absent.
inline void arm_contacts_off(const MujocoEnv& env) {
  mjModel* m = writable(env);
  int object = mj_name2id(m, mjOBJ_BODY, "object");
  for (int g = 0; g < m->ngeom; ++g)
    if (m->geom_bodyid[g] != 0 && m->geom_bodyid[g] != object) m->geom_contype[g] = m->geom_conaffinity[g] = 0;
}

inline void object_contacts_off(const MujocoEnv& env) {
  mjModel* m = writable(env);
  int g = mj_name2id(m, mjOBJ_GEOM, "object");
  m->geom_contype[g] = m->geom_conaffinity[g] = 0;
}

// Holds the arm still at `q` (arm joints only), as a scripted sequence needs.
inline void hold_arm(JacoEnv& env, const std::vector<double>& q) {
  mjData* d = env.mutable_data();
  for (int i = 0; i < JacoEnv::kArmDof; ++i) {
    d->qpos[i] = i < int(q.size()) ? q[i] : 0.0;
    d->qvel[i] = 0.0;
  }
}

inline void pin(JacoEnv& env, const Vec3& p, std::vector<float>& obs) {
  env.pin_object(p);
  env.forward(obs.data());
}

}  // namespace segue
