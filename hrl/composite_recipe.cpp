#include "hrl/composite_recipe.h"

#include <filesystem>

#include "core/assets.h"
#include "environments/registry.h"

namespace segue {

std::string CompositeRecipe::default_file(const std::string& task) {
  return std::string(SEGUE_SOURCE_DIR) + "/experiments/" + task + ".yaml";
}

CompositeRecipe CompositeRecipe::load(const std::string& file, const std::vector<std::string>& overrides) {
  Recipe recipe = Recipe::load(file, overrides);
  Section root = recipe.root();
  CompositeRecipe c;
  c.file = file;
  c.task = root.require<std::string>("task");
  try {
    c.make_env = task_factory(c.task, root.sub("env"));
  } catch (const Error& e) {
    if (std::string(e.what()).rfind("unknown task", 0) == 0) throw root.error("task", e.what());
    throw;
  }
  c.spec = c.make_env()->spec();
  c.skills = read_skills(root.sub("skills"), c.spec);
  c.meta = MetaController(root, c.skills, c.spec.feature_names);
  Section methods = root.sub("methods");
  if (methods.has("single")) c.single_policy = methods.sub("single").require<std::string>("policy");
  Section ev = root.sub("eval");
  c.eval_episodes = ev.get("episodes", c.eval_episodes);
  c.eval_seeds = ev.get("seeds", c.eval_seeds);
  recipe.reject_unknown();
  return c;
}

const std::vector<std::string>& method_names() {
  static const std::vector<std::string> names{"single", "without-tp", "tp", "lee", "tp+q"};
  return names;
}

namespace {

// "Without TP": the meta-controller switches straight to the next skill as soon as the
// transition interval begins.
class WithoutTpController : public Controller {
 public:
  WithoutTpController(const std::vector<Skill>& skills, const MetaController& meta)
      : skills_(skills), meta_(meta) {}
  void reset(const Env& env, const float*) override {
    features_.resize(env.spec().feature_names.size());
    env.features(features_.data());
    skill_ = meta_.start_skill(features_.data());
  }
  void act(const Env& env, const float* obs, float* action) override {
    env.features(features_.data());
    int t = meta_.active_transition(skill_, features_.data());
    if (t >= 0) skill_ = meta_.transitions()[t].to;
    const Skill& s = skills_[skill_];
    s.policy.act(obs + s.obs_begin, 1, action);
  }

 private:
  std::vector<Skill> skills_;  // own copies: Policy::act keeps scratch buffers
  const MetaController& meta_;
  std::vector<double> features_;
  int skill_ = 0;
};

}  // namespace

ControllerFactory method_controllers(const CompositeRecipe& r, const std::string& method) {
  if (method == "without-tp")
    return [&r] { return std::make_unique<WithoutTpController>(r.skills, r.meta); };
  if (method == "single") {
    if (r.single_policy.empty()) throw Error(r.file + ": key 'methods.single.policy' is not set");
    std::string path = repo_path(r.single_policy);
    if (!std::filesystem::exists(path))
      throw Error(r.file + ": key 'methods.single.policy': no such policy file '" + r.single_policy + "'");
    Policy p = Policy::load(path);
    p.check_fits(r.spec, path);
    return [p] { return std::make_unique<PolicyController>(p); };
  }
  for (const auto& m : method_names())
    if (m == method) throw Error("method '" + method + "' needs trained transition policies, which Segue cannot train yet");
  std::string known;
  for (const auto& m : method_names()) known += (known.empty() ? "" : ", ") + m;
  throw Error("unknown method '" + method + "' (methods: " + known + ")");
}

}  // namespace segue
