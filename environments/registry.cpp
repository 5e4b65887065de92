#include "environments/registry.h"

#include <functional>
#include <map>

#include "environments/walker.h"

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

const std::map<std::string, Builder>& builders() {
  static const std::map<std::string, Builder> table = {
      {"walker_forward", walker_walk(+1.0)},
      {"walker_backward", walker_walk(-1.0)},
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
