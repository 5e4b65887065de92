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
  c.make_env = read_task(root, c.task, c.spec);
  c.skills = read_skills(root.sub("skills"), c.spec);
  c.meta = MetaController(root, c.skills, c.spec.feature_names);
  const auto items = root.items("transitions");
  for (size_t t = 0; t < c.meta.transitions().size(); ++t) {
    const Transition& rule = c.meta.transitions()[t];
    TransitionTrainingSpec spec = TransitionTrainingSpec::read(
        items[t], rule, c.spec.feature_names,
        [](const std::string& task) { return reference_task_factory(task)()->spec().feature_names; });
    Section training = items[t].sub("training");
    if (training.has("env")) {
      training.sub("env").filled_from(root.sub("env"));
      EnvSpec own;
      spec.env = read_task(training, c.task, own);
      if (own.obs_dim != c.spec.obs_dim || own.act_dim != c.spec.act_dim || own.feature_names != c.spec.feature_names)
        throw training.error("env", "changes the task's observations, actions or features; it may change only how "
                                    "episodes run (pushes, noise, rules)");
    } else {
      spec.env = c.make_env;
    }
    if (!spec.expert_task.empty()) {  // pi_b's own task must give it the numbers it sees here
      Section e = items[t].sub("expert");
      std::unique_ptr<Env> own;
      try {
        own = reference_task_factory(spec.expert_task)();
      } catch (const Error& err) {
        throw e.error("task", err.what());
      }
      const Skill& b = c.skills[rule.to];
      if (own->spec().obs_dim != b.obs_end - b.obs_begin)
        throw e.error("task", "'" + spec.expert_task + "' has obs_dim " + std::to_string(own->spec().obs_dim) +
                                  ", but skill '" + b.name + "' sees " + std::to_string(b.obs_end - b.obs_begin) +
                                  " numbers of this task");
    }
    c.training.push_back(spec);
  }
  Section methods = root.sub("methods");
  if (methods.has("single")) c.single_policy = methods.sub("single").require<std::string>("policy");
  c.transitions_dir = methods.get<std::string>("transitions", "");
  c.pipeline = PipelineConfig::read(root, c.task);
  if (c.pipeline.transition.init_from_next)  // pi_ab starts as a copy of pi_b: the same layers
    for (const Transition& tr : c.meta.transitions()) {
      const Skill& b = c.skills[tr.to];
      const auto& w = b.policy.mlp().weights();
      std::vector<int> hidden;
      for (size_t l = 0; l + 1 < w.size(); ++l) hidden.push_back(int(w[l].rows()));
      if (hidden != c.pipeline.transition.net.pi_hidden) {
        auto list = [](const std::vector<int>& v) {
          std::string out;
          for (int x : v) out += (out.empty() ? "" : ", ") + std::to_string(x);
          return "[" + out + "]";
        };
        throw root.sub("transition").sub("policy").error(
            "pi_hidden", list(c.pipeline.transition.net.pi_hidden) + ", but pi_ab starts as skill '" + b.name +
                             "' (init_from_next), whose hidden layers are " + list(hidden));
      }
    }
  Section ev = root.sub("eval");
  c.eval_episodes = ev.get("episodes", c.eval_episodes, Range::positive());
  c.eval_seeds = ev.get("seeds", c.eval_seeds, Range::non_negative());
  if (c.eval_seeds.empty()) throw ev.error("seeds", "lists no seed");
  c.handover_point = ev.choice("handover_point", "fixed", {"fixed", "random"}) == "random" ? HandOverPoint::Random
                                                                                          : HandOverPoint::Fixed;
  recipe.reject_unknown();
  c.resolved = recipe.resolved_yaml();
  c.defaulted = recipe.defaulted_keys();
  c.key_rules = recipe.key_rules();
  return c;
}

std::string CompositeRecipe::transition_name(int t) const {
  const Transition& tr = meta.transitions().at(t);
  return skills[tr.from].name + "-" + skills[tr.to].name;
}

std::string CompositeRecipe::transition_source(int t) const { return spec.name + " " + transition_name(t); }

int CompositeRecipe::start_state_count(int t) const {
  const int own = training.at(t).start_states;
  return own > 0 ? own : pipeline.collect.start_states;
}

const std::vector<std::string>& method_names() {
  static const std::vector<std::string> names{"single", "without-tp", "tp", "lee", "tp+q"};
  return names;
}

std::vector<TransitionArtefacts> load_transition_artefacts(const CompositeRecipe& r, const std::string& dir,
                                                          const std::string& policy_file, bool with_q) {
  std::vector<TransitionArtefacts> out(r.meta.transitions().size());
  for (size_t t = 0; t < out.size(); ++t) {
    const Skill& b = r.skills[r.meta.transitions()[t].to];
    const std::string folder = dir + "/" + r.transition_name(int(t)) + "/";
    // A file that says it was made for another transition or task (copied between
    // folders) is refused; older files say nothing and are let through.
    auto check_source = [&](const Policy& p, const std::string& file) {
      const std::string expected = r.transition_source(int(t)) + " " + file;
      if (!p.source().empty() && p.source() != expected)
        throw Error(folder + file + ": made for '" + p.source() + "', but this is '" + expected + "'");
    };
    if (std::filesystem::exists(folder + policy_file)) {
      Policy p = Policy::load(folder + policy_file);
      check_source(p, policy_file);
      EnvSpec slice = r.spec;
      slice.obs_dim = b.obs_end - b.obs_begin;
      slice.act_dim = r.spec.act_dim + (policy_file == "lee.pt" ? 1 : 0);  // Lee's extra output: terminate
      p.check_fits(slice, folder + policy_file);
      out[t].policy = p;
    }
    if (with_q && std::filesystem::exists(folder + "q.pt")) {
      Policy q = Policy::load(folder + "q.pt");
      check_source(q, "q.pt");
      EnvSpec qs = r.spec;
      qs.act_dim = 2;
      q.check_fits(qs, folder + "q.pt");
      out[t].q = q;
    }
  }
  return out;
}

ControllerFactory method_controllers(const CompositeRecipe& r, const std::string& method) {
  if (method == "without-tp") {
    // Transition controllers with no transition policy trained: the meta-controller
    // switches straight to the next skill as the interval begins (or, at a random hand-over
    // point, lets the skill before it carry on until then).
    return [&r] {
      return std::make_unique<TransitionController>(r.skills, r.meta, std::vector<TransitionArtefacts>{},
                                                    SwitchRule::IntervalEnd, r.handover_point);
    };
  }
  if (method == "single") {
    if (r.single_policy.empty()) throw Error(r.file + ": key 'methods.single.policy' is not set");
    std::string path = repo_path(r.single_policy);
    if (!std::filesystem::exists(path))
      throw Error(r.file + ": key 'methods.single.policy': no such policy file '" + r.single_policy + "'");
    try {
      Policy p = Policy::load(path);
      p.check_fits(r.spec, path);
      return [p] { return std::make_unique<PolicyController>(p); };
    } catch (const Error& e) {
      throw Error(r.file + ": key 'methods.single.policy': " + e.what());
    }
  }
  if (method == "tp" || method == "tp+q" || method == "lee") {
    if (r.transitions_dir.empty())
      throw Error(r.file + ": key 'methods.transitions' is not set (a folder of trained transition policies)");
    const std::string file = method == "lee" ? "lee.pt" : "policy.pt";
    std::vector<TransitionArtefacts> artefacts;
    try {
      artefacts = load_transition_artefacts(r, repo_path(r.transitions_dir), file, /*with_q=*/method == "tp+q");
    } catch (const Error& e) {
      throw Error(r.file + ": key 'methods.transitions': " + e.what());
    }
    for (size_t t = 0; t < artefacts.size(); ++t) {
      auto missing = [&](const std::string& f) {
        return Error(r.file + ": key 'methods.transitions': no " + f + " for transition " +
                     r.transition_name(int(t)) + " in '" + r.transitions_dir + "' (train it with segue run)");
      };
      if (!artefacts[t].policy) throw missing(file);
      if (method == "tp+q" && !artefacts[t].q) throw missing("q.pt");
    }
    SwitchRule rule = method == "tp" ? SwitchRule::IntervalEnd
                      : method == "tp+q" ? SwitchRule::QNetwork
                                         : SwitchRule::TerminationHead;
    return [&r, artefacts, rule] {
      return std::make_unique<TransitionController>(r.skills, r.meta, artefacts, rule, r.handover_point);
    };
  }
  std::string known;
  for (const auto& m : method_names()) known += (known.empty() ? "" : ", ") + m;
  throw Error("unknown method '" + method + "' (methods: " + known + ")");
}

}  // namespace segue
