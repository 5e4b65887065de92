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
  WalkerConfig w = WalkerConfig::read(env);
  ObstacleConfig o = ObstacleConfig::read(env);
  WalkerJump::Config j;
  j.curb_x = env.get("curb_x", j.curb_x, Range::any());
  j.curb_noise = env.get("curb_noise", j.curb_noise, Range::non_negative());
  j.cross_bonus = env.get("cross_bonus", j.cross_bonus, Range::non_negative());
  j.upward_weight = env.get("upward_weight", j.upward_weight, Range::non_negative());
  j.height_weight = env.get("height_weight", j.height_weight, Range::non_negative());
  j.end_x = env.get("end_x", j.end_x, Range::any());
  j.curb_height = env.get("curb_height", j.curb_height, Range::positive());
  j.curb_height_min = env.get("curb_height_min", j.curb_height, Range::positive());
  if (j.curb_height_min > j.curb_height) throw env.error("curb_height_min", "must be at most curb_height");
  j.curbs = env.get("curbs", j.curbs, Range::at_least(1));
  j.curb_spacing = env.get("curb_spacing", j.curb_spacing, Range::positive());
  j.clearance_weight = env.get("clearance_weight", j.clearance_weight, Range::non_negative());
  j.clearance_before = env.get("clearance_before", j.clearance_before, Range::non_negative());
  j.peak_weight = env.get("peak_weight", j.peak_weight, Range::non_negative());
  j.contact_ends = env.get("contact_ends", j.contact_ends);
  j.mark_upward_weight = env.get("mark_upward_weight", j.mark_upward_weight, Range::non_negative());
  j.ghost_curbs = env.get("ghost_curbs", j.ghost_curbs);
  j.ghost_depth_cost = env.get("ghost_depth_cost", j.ghost_depth_cost, Range::non_negative());
  j.takeoff_bonus = env.get("takeoff_bonus", j.takeoff_bonus, Range::non_negative());
  j.close_stance_cost = env.get("close_stance_cost", j.close_stance_cost, Range::non_negative());
  j.stance_height = env.get("stance_height", j.stance_height, Range::non_negative());
  j.placement_bonus = env.get("placement_bonus", j.placement_bonus, Range::non_negative());
  j.placement_target = env.get("placement_target", j.placement_target, Range::any());
  j.placement_width = env.get("placement_width", j.placement_width, Range::positive());
  j.approach_speed = env.get("approach_speed", j.approach_speed, Range::non_negative());
  j.approach_from = env.get("approach_from", j.approach_from, Range::positive());
  j.approach_to = env.get("approach_to", j.approach_to, Range::non_negative());
  if (!(j.approach_to < j.approach_from)) throw env.error("approach_to", "must be below approach_from");
  if (env.has("takeoff_zone")) {
    const auto zone = env.get("takeoff_zone", std::vector<double>(), Range::at_most(0));
    if (zone.size() != 2 || !(zone[0] < zone[1]))
      throw env.error("takeoff_zone", "must be [low, high] with low < high <= 0 (metres before the curb)");
    j.takeoff_zone = {zone[0], zone[1]};
  }
  if (j.curbs > 1 && j.curb_spacing <= 2 * j.curb_noise + o.curb_width)
    throw env.error("curb_spacing", "must exceed 2 curb_noise + curb_width so curbs do not overlap");
  return [=] { return std::make_unique<WalkerJump>(name, w, o, j); };
}

Factory walker_crawl(const std::string& name, const Section& env) {
  WalkerConfig defaults;
  defaults.fall_height = 0.3;  // crawling is low: only a torso below 0.3 m is a fall
  WalkerConfig w = WalkerConfig::read(env, defaults);
  ObstacleConfig o = ObstacleConfig::read(env);
  WalkerCrawl::Config c;
  c.ceiling_start = env.get("ceiling_start", c.ceiling_start, Range::any());
  c.ceiling_end = env.get("ceiling_end", c.ceiling_end, Range::any());
  c.crouch_weight = env.get("crouch_weight", c.crouch_weight, Range::non_negative());
  c.crouch_height = env.get("crouch_height", c.crouch_height, Range::positive());
  if (!(c.ceiling_start < c.ceiling_end)) throw env.error("ceiling_end", "must be beyond ceiling_start");
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
Builder walker_course(WalkerCourse::Config defaults, int max_steps) {
  return [defaults, max_steps](const std::string& name, const Section& env) -> Factory {
    const WalkerConfig wd = composite_defaults(max_steps);
    WalkerConfig w = WalkerConfig::read(env, wd);
    ObstacleConfig o = ObstacleConfig::read(env);
    WalkerCourse::Config c = defaults;
    c.positions = env.get("positions", c.positions, Range::any());
    c.position_noise = env.get("position_noise", c.position_noise, Range::non_negative());
    c.kinds = env.get("kinds", c.kinds);
    c.shuffle = env.get("shuffle", c.shuffle);
    c.pass_bonus = env.get("pass_bonus", c.pass_bonus, Range::non_negative());
    c.speed_weight = env.get("speed_weight", c.speed_weight, Range::non_negative());
    c.height_weight = env.get("height_weight", c.height_weight, Range::non_negative());
    c.cross_bonus = env.get("cross_bonus", c.cross_bonus, Range::non_negative());
    c.mark_upward_weight = env.get("mark_upward_weight", c.mark_upward_weight, Range::non_negative());
    c.ceiling_zone = env.get("ceiling_zone", c.ceiling_zone, Range::non_negative());
    c.ceiling_fall_height = env.get("ceiling_fall_height", c.ceiling_fall_height, Range::non_negative());
    if (c.kinds.size() != c.positions.size())
      throw env.error("kinds", "needs one entry per position (" + std::to_string(c.positions.size()) + ")");
    for (const auto& k : c.kinds)
      if (k != "curb" && k != "ceiling") throw env.error("kinds", "entries are 'curb' or 'ceiling', got '" + k + "'");
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
  WalkerConfig w = WalkerConfig::read(env, composite_defaults(10000));
  WalkerPatrol::Config c;
  c.stone_x = env.get("stone_x", c.stone_x, Range::positive());
  c.max_turns = env.get("max_turns", c.max_turns, Range::at_least(1));
  c.turn_bonus = env.get("turn_bonus", c.turn_bonus, Range::non_negative());
  c.min_pass_speed = env.get("min_pass_speed", c.min_pass_speed, Range::non_negative());
  c.max_leg_steps = env.get("max_leg_steps", c.max_leg_steps, Range::non_negative());
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

int read_successes(const Section& env) {
  return env.get("successes", 5, Range::at_least(1));
}

Factory repetitive_picking(const std::string& name, const Section& env) {
  JacoConfig c = jaco_composite(env, 1000);
  JacoRepetitivePick::Config k;
  k.successes = read_successes(env);
  k.pick_steps = env.get("pick_steps", k.pick_steps, Range::at_least(1));
  k.unwind_arm = env.get("unwind_arm", k.unwind_arm);
  k.pick = PickRule::Config::read(env);
  return [=] { return std::make_unique<JacoRepetitivePick>(name, c, k); };
}

Factory repetitive_catching(const std::string& name, const Section& env) {
  // The first box falls for 10 random steps before its throw, as in Catch (the reference: 0).
  JacoConfig c = jaco_composite(env, 1000, 10);
  JacoRepetitiveCatch::Config k;
  k.successes = read_successes(env);
  k.pin_steps = env.get("pin_steps", k.pin_steps, Range::non_negative());
  k.fall_steps = env.get("fall_steps", k.fall_steps, Range::non_negative());
  k.unwind_arm = env.get("unwind_arm", k.unwind_arm);
  k.catching = CatchRule::Config::read(env, /*hold_target=*/{0.0, 0.2, 0.2});  // KeepCatch's, not Catch's
  return [=] { return std::make_unique<JacoRepetitiveCatch>(name, c, k); };
}

// Serve's `start`, `start_noise` and `vel_noise` are the toss's (the ball starts on the ground).
Factory serve(const std::string& name, const Section& env) {
  JacoConfig c = jaco_composite(env, 300);
  JacoServe::Config k;
  k.judge_height = env.get("judge_height", k.judge_height, Range::non_negative());
  k.toss_bonus = env.get("toss_bonus", k.toss_bonus, Range::non_negative());
  k.toss_tolerance = env.get("toss_tolerance", k.toss_tolerance, Range::non_negative());
  k.toss = TossRule::Config::read(env);
  k.hit = HitRule::Config::read(env);
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
