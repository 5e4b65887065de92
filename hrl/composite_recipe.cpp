#include "hrl/composite_recipe.h"

#include <filesystem>

#include "core/assets.h"
#include "hrl/transition_controller.h"
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
  c.transitions_dir = methods.get<std::string>("transitions", "");
  c.pipeline = PipelineConfig::read(root, c.task);
  Section ev = root.sub("eval");
  c.eval_episodes = ev.get("episodes", c.eval_episodes);
  c.eval_seeds = ev.get("seeds", c.eval_seeds);
  recipe.reject_unknown();
  c.resolved = recipe.resolved_yaml();
  return c;
}

std::string CompositeRecipe::transition_name(int t) const {
  const Transition& tr = meta.transitions().at(t);
  return skills[tr.from].name + "-" + skills[tr.to].name;
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
  if (method == "tp" || method == "tp+q" || method == "lee") {
    if (r.transitions_dir.empty())
      throw Error(r.file + ": key 'methods.transitions' is not set (a folder of trained transition policies)");
    const std::string dir = repo_path(r.transitions_dir);
    const std::string file = method == "lee" ? "lee.pt" : "policy.pt";
    std::vector<TransitionArtefacts> artefacts(r.meta.transitions().size());
    for (size_t t = 0; t < artefacts.size(); ++t) {
      const Skill& b = r.skills[r.meta.transitions()[t].to];
      std::string path = dir + "/" + r.transition_name(int(t)) + "/" + file;
      if (!std::filesystem::exists(path))
        throw Error(r.file + ": key 'methods.transitions': no " + file + " for transition " +
                    r.transition_name(int(t)) + " in '" + r.transitions_dir + "' (train it with segue run)");
      Policy p = Policy::load(path);
      EnvSpec slice = r.spec;
      slice.obs_dim = b.obs_end - b.obs_begin;
      slice.act_dim = r.spec.act_dim + (method == "lee" ? 1 : 0);  // Lee's extra output: terminate
      p.check_fits(slice, path);
      artefacts[t].policy = p;
      if (method == "tp+q") {
        std::string q = dir + "/" + r.transition_name(int(t)) + "/q.pt";
        if (!std::filesystem::exists(q))
          throw Error(r.file + ": key 'methods.transitions': no q.pt for transition " + r.transition_name(int(t)) +
                      " in '" + r.transitions_dir + "' (train it with segue run)");
        Policy qp = Policy::load(q);
        EnvSpec qs = r.spec;
        qs.act_dim = 2;
        qp.check_fits(qs, q);
        artefacts[t].q = qp;
      }
    }
    SwitchRule rule = method == "tp" ? SwitchRule::IntervalEnd
                      : method == "tp+q" ? SwitchRule::QNetwork
                                         : SwitchRule::TerminationHead;
    return [&r, artefacts, rule] { return std::make_unique<TransitionController>(r.skills, r.meta, artefacts, rule); };
  }
  std::string known;
  for (const auto& m : method_names()) known += (known.empty() ? "" : ", ") + m;
  throw Error("unknown method '" + method + "' (methods: " + known + ")");
}

}  // namespace segue
