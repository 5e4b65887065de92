#include "environments/registry.h"

#include <functional>
#include <map>

#include "environments/jaco_skills.h"
#include "environments/jaco_tasks.h"
#include "environments/walker.h"
#include "environments/walker_balance.h"
#include "environments/walker_course.h"
#include "environments/walker_obstacles.h"
#include "environments/walker_patrol.h"

namespace segue {
namespace {

using Factory = std::function<std::unique_ptr<Env>()>;
using Builder = std::function<Factory(const std::string&, const Section&)>;

Builder walker_walk(double direction) {
  return [direction](const std::string& name, const Section& env) -> Factory {
    WalkerConfig c = WalkerConfig::read(env);
    return [=] { return std::make_unique<WalkerWalk>(name, c, direction); };
  };
}

Factory walker_balance(const std::string& name, const Section& env) {
  WalkerConfig defaults;
  defaults.push_force = 400.0;  // the reference pushes harder while balancing,
  defaults.push_prob = 0.1;     // half as often (its Walker2dBalanceEnv's prob_apply_force)
  defaults.foot_cost = 0.0;     // and has no foot term
  WalkerConfig c = WalkerConfig::read(env, defaults);
  return [=] { return std::make_unique<WalkerBalance>(name, c); };
}

Factory walker_jump(const std::string& name, const Section& env) {
  const WalkerConfig w = WalkerConfig::read(env);
  const ObstacleConfig o = ObstacleConfig::read(env);
  const WalkerJump::Config j = WalkerJump::Config::read(env, o);
  return [=] { return std::make_unique<WalkerJump>(name, w, o, j); };
}

Factory walker_crawl(const std::string& name, const Section& env) {
  WalkerConfig defaults;
  defaults.fall_height = 0.3;  // crawling is low: only a torso below 0.3 m is a fall
  const WalkerConfig w = WalkerConfig::read(env, defaults);
  const ObstacleConfig o = ObstacleConfig::read(env);
  const WalkerCrawl::Config c = WalkerCrawl::Config::read(env);
  return [=] { return std::make_unique<WalkerCrawl>(name, w, o, c); };
}

// The reference's composite tasks push nothing (their prob_apply_force is 0); the pushes
// belong to the sub-tasks a skill is trained on.
WalkerConfig composite_defaults(int max_steps) {
  WalkerConfig wd;
  wd.max_episode_steps = max_steps;
  wd.push_prob = 0.0;
  return wd;
}

// Hurdle and Obstacle course differ only in their layout defaults.
Builder walker_course(WalkerCourse::Config layout, int max_steps) {
  return [layout, max_steps](const std::string& name, const Section& env) -> Factory {
    const WalkerConfig w = WalkerConfig::read(env, composite_defaults(max_steps));
    const ObstacleConfig o = ObstacleConfig::read(env);
    const WalkerCourse::Config c = WalkerCourse::Config::read(env, layout);
    return [=] { return std::make_unique<WalkerCourse>(name, w, o, c); };
  };
}

WalkerCourse::Config hurdle_layout() {
  WalkerCourse::Config c;
  c.positions = {8, 18, 28, 38, 48};
  c.kinds.assign(5, "curb");
  return c;
}

WalkerCourse::Config obstacle_course_layout() {
  WalkerCourse::Config c;
  c.positions = {8, 19, 30, 41, 52};
  c.kinds = {"curb", "curb", "curb", "ceiling", "ceiling"};  // the reference code's mix
  c.shuffle = true;
  return c;
}

Factory walker_patrol(const std::string& name, const Section& env) {
  const WalkerConfig w = WalkerConfig::read(env, composite_defaults(10000));
  const WalkerPatrol::Config c = WalkerPatrol::Config::read(env);
  return [=] { return std::make_unique<WalkerPatrol>(name, w, c); };
}

// An arm sub-task: the arm's settings (with the task's reference start noise and random
// steps) and its rule's, both from `env:`.
template <class Rule>
Builder jaco_skill(const std::string& model, bool with_rotation, double init_noise, int random_steps) {
  return [=](const std::string& name, const Section& env) -> Factory {
    JacoConfig defaults;
    defaults.init_noise = init_noise;
    defaults.init_random_steps = random_steps;
    JacoConfig c = JacoConfig::read(env, defaults);
    typename Rule::Config r = Rule::Config::read(env);
    return [=] { return std::make_unique<JacoSkill<Rule>>(name, c, model, with_rotation, r); };
  };
}

// The arm's composite tasks (docs/reference/tasks.md#arm-tasks): start noise 0.005, no random steps.
JacoConfig jaco_composite(const Section& env, int max_steps, int random_steps = 0) {
  JacoConfig d;
  d.init_noise = 0.005;
  d.init_random_steps = random_steps;
  d.max_episode_steps = max_steps;
  return JacoConfig::read(env, d);
}

Factory repetitive_picking(const std::string& name, const Section& env) {
  const JacoConfig c = jaco_composite(env, 1000);
  const JacoRepetitivePick::Config k = JacoRepetitivePick::Config::read(env);
  return [=] { return std::make_unique<JacoRepetitivePick>(name, c, k); };
}

Factory repetitive_catching(const std::string& name, const Section& env) {
  // The first box falls for 10 random steps before its throw, as in Catch (the reference: 0).
  const JacoConfig c = jaco_composite(env, 1000, 10);
  const JacoRepetitiveCatch::Config k = JacoRepetitiveCatch::Config::read(env);
  return [=] { return std::make_unique<JacoRepetitiveCatch>(name, c, k); };
}

Factory serve(const std::string& name, const Section& env) {
  const JacoConfig c = jaco_composite(env, 300);
  const JacoServe::Config k = JacoServe::Config::read(env);
  return [=] { return std::make_unique<JacoServe>(name, c, k); };
}

const std::map<std::string, Builder>& builders() {
  static const std::map<std::string, Builder> table = {
      {"walker_forward", walker_walk(+1.0)},
      {"walker_backward", walker_walk(-1.0)},
      {"walker_balance", walker_balance},
      {"walker_jump", walker_jump},
      {"walker_crawl", walker_crawl},
      {"hurdle", walker_course(hurdle_layout(), 5000)},
      {"obstacle_course", walker_course(obstacle_course_layout(), 5000)},
      {"patrol", walker_patrol},
      // Pick and catch see the box's rotation (49 numbers), toss and hit do not (39):
      // docs/reference/jaco.md#observation.
      {"jaco_pick", jaco_skill<PickRule>("jaco/jaco_box.xml", true, 0.01, 10)},
      {"jaco_catch", jaco_skill<CatchRule>("jaco/jaco_box.xml", true, 0.01, 10)},
      {"jaco_toss", jaco_skill<TossRule>("jaco/jaco_ball.xml", false, 0.005, 0)},
      {"jaco_hit", jaco_skill<HitRule>("jaco/jaco_ball.xml", false, 0.005, 10)},
      {"repetitive_picking", repetitive_picking},
      {"repetitive_catching", repetitive_catching},
      {"serve", serve},
  };
  return table;
}

}  // namespace

Factory task_factory(const std::string& task, const Section& env) {
  auto it = builders().find(task);
  if (it == builders().end()) {
    std::string known;
    for (const auto& n : task_names()) known += (known.empty() ? "" : ", ") + n;
    throw Error("unknown task '" + task + "' (known: " + known + ")");
  }
  return it->second(task, env);
}

Factory read_task(const Section& root, const std::string& task, EnvSpec& spec) {
  Factory make;
  try {
    make = task_factory(task, root.sub("env"));
  } catch (const Error& e) {
    if (std::string(e.what()).rfind("unknown task", 0) == 0) throw root.error("task", e.what());
    throw;
  }
  try {
    spec = make()->spec();
  } catch (const Error& e) {
    throw root.error("env", e.what());
  }
  return make;
}

std::vector<std::string> task_names() {
  std::vector<std::string> names;
  for (const auto& kv : builders()) names.push_back(kv.first);
  return names;
}

std::function<std::unique_ptr<Env>()> reference_task_factory(const std::string& task) {
  return task_factory(task, Recipe::parse("{}", "reference " + task).root());
}

}  // namespace segue
