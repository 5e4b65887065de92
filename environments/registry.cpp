#include "environments/registry.h"

#include <functional>
#include <map>

#include "environments/walker.h"
#include "environments/walker_obstacles.h"

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
  defaults.push_force = 400.0;  // the reference pushes harder while balancing
  defaults.foot_cost = 0.0;     // and has no foot term
  WalkerConfig c = WalkerConfig::read(env, defaults);
  return [=] { return std::make_unique<WalkerBalance>(name, c); };
}

Factory walker_jump(const std::string& name, const Section& env) {
  WalkerConfig w = WalkerConfig::read(env);
  ObstacleConfig o = ObstacleConfig::read(env);
  WalkerJump::Config j;
  j.curb_x = env.get("curb_x", j.curb_x);
  j.curb_noise = env.get("curb_noise", j.curb_noise);
  j.cross_bonus = env.get("cross_bonus", j.cross_bonus);
  j.upward_weight = env.get("upward_weight", j.upward_weight);
  j.end_x = env.get("end_x", j.end_x);
  return [=] { return std::make_unique<WalkerJump>(name, w, o, j); };
}

Factory walker_crawl(const std::string& name, const Section& env) {
  WalkerConfig defaults;
  defaults.fall_height = 0.3;  // crawling is low: only a torso below 0.3 m is a fall
  WalkerConfig w = WalkerConfig::read(env, defaults);
  ObstacleConfig o = ObstacleConfig::read(env);
  WalkerCrawl::Config c;
  c.ceiling_start = env.get("ceiling_start", c.ceiling_start);
  c.ceiling_end = env.get("ceiling_end", c.ceiling_end);
  return [=] { return std::make_unique<WalkerCrawl>(name, w, o, c); };
}

const std::map<std::string, Builder>& builders() {
  static const std::map<std::string, Builder> table = {
      {"walker_forward", walker_walk(+1.0)},
      {"walker_backward", walker_walk(-1.0)},
      {"walker_balance", walker_balance},
      {"walker_jump", walker_jump},
      {"walker_crawl", walker_crawl},
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

std::vector<std::string> task_names() {
  std::vector<std::string> names;
  for (const auto& kv : builders()) names.push_back(kv.first);
  return names;
}

}  // namespace segue
