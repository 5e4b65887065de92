// The shipped artefacts work: every policy under assets/policies/walker/ loads (its
// TorchScript checked against Segue's reading of it), fits the task it is named after and
// runs 200 steps without NaN; composite recipes load with the shipped skills.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/assets.h"
#include "core/run_dir.h"
#include "environments/registry.h"
#include "hrl/composite_recipe.h"

namespace segue {

TEST(Shipped, EveryWalkerPolicyRunsOnItsTask) {
  int checked = 0;
  for (const auto& entry : std::filesystem::directory_iterator(assets_dir() + "/policies/walker")) {
    if (entry.path().extension() != ".pt") continue;
    // A policy file is named after its task, a variant with a suffix (walker_jump_v2.pt).
    const std::string stem = entry.path().stem().string(), path = entry.path().string();
    std::string task;
    for (const auto& t : task_names())
      if (stem.rfind(t, 0) == 0 && t.size() > task.size()) task = t;
    ASSERT_FALSE(task.empty()) << path << " is named after no task";
    Recipe r = Recipe::parse("{}", "test");
    auto make = task_factory(task, r.root().sub("env"));
    auto env = make();
    Policy p = Policy::load(path);
    p.check_fits(env->spec(), path);
    std::vector<float> obs(env->spec().obs_dim), act(env->spec().act_dim);
    env->reset(7, obs.data());
    for (int t = 0; t < 200; ++t) {
      p.act(obs.data(), 1, act.data());
      for (float a : act) ASSERT_TRUE(std::isfinite(a)) << task << " step " << t;
      StepResult s = env->step(act.data(), obs.data());
      for (float o : obs) ASSERT_TRUE(std::isfinite(o)) << task << " step " << t;
      if (s.done()) env->reset(obs.data());
    }
    ++checked;
  }
  EXPECT_GE(checked, 2) << "walk forward and backward at least are shipped";
}

TEST(Shipped, CompositeRecipesLoadWithTheirSkills) {
  for (const std::string task : {"hurdle", "obstacle_course", "patrol", "repetitive_picking", "repetitive_catching", "serve"}) {
    std::string file = CompositeRecipe::default_file(task);
    // Every shipped recipe names skills that are shipped.
    std::string missing;
    Recipe raw = Recipe::load(file);
    for (const auto& name : raw.root().sub("skills").keys()) {
      std::string policy = raw.root().sub("skills").sub(name).get<std::string>("policy", "");
      if (!std::filesystem::exists(std::string(SEGUE_SOURCE_DIR) + "/" + policy)) missing += " " + policy;
    }
    EXPECT_EQ(missing, "") << task << ": the recipe names skills that are not in the repository";
    if (!missing.empty()) continue;
    CompositeRecipe r = CompositeRecipe::load(file);
    EXPECT_EQ(r.task, task);
    EvalResult e = evaluate(r.make_env, method_controllers(r, "without-tp"), 2, 0, 1);
    ASSERT_EQ(e.returns.size(), 2u) << task;
    for (double ret : e.returns) EXPECT_TRUE(std::isfinite(ret)) << task;
  }
}

namespace {

// The mean success count of `method` on evaluation seed 0 in experiments/results/TASK.json.
double table_seed0(const std::string& task, const std::string& method) {
  const std::string text = read_file(std::string(SEGUE_SOURCE_DIR) + "/experiments/results/" + task + ".json");
  size_t at = text.find("\"" + method + "\": {");
  EXPECT_NE(at, std::string::npos) << task << " " << method;
  if (at == std::string::npos) return NAN;
  at = text.find("\"per_seed_means\": [", at);
  return std::stod(text.substr(at + std::string("\"per_seed_means\": [").size()));
}

// The shipped transition artefacts drive every transition method, and `method` reproduces
// its row of experiments/results/TASK.json on evaluation seed 0.
void reproduces_its_table(const std::string& task, const std::string& method) {
  CompositeRecipe r = CompositeRecipe::load(CompositeRecipe::default_file(task));
  for (const std::string m : {"tp", "lee", "tp+q"}) {
    EvalResult e = evaluate(r.make_env, method_controllers(r, m), 2, 0, 2);
    ASSERT_EQ(e.returns.size(), 2u) << task << " " << m;
    for (double ret : e.returns) EXPECT_TRUE(std::isfinite(ret)) << task << " " << m;
  }
  EvalResult e = evaluate(r.make_env, method_controllers(r, method), r.eval_episodes, 0, 2);
  double mean = 0;
  for (double c : e.success_counts) mean += c / e.success_counts.size();
  EXPECT_NEAR(mean, table_seed0(task, method), 1e-9) << task << " " << method;
}

}  // namespace

TEST(Shipped, PatrolTransitionMethodsReproduceTheirTable) { reproduces_its_table("patrol", "tp"); }
// The arm's: a composite of two skills (Serve) and a skill handing over to itself.
TEST(Shipped, ServeTransitionMethodsReproduceTheirTable) { reproduces_its_table("serve", "tp+q"); }
TEST(Shipped, RepetitiveCatchingTransitionMethodsReproduceTheirTable) {
  reproduces_its_table("repetitive_catching", "tp+q");
}

TEST(Shipped, CompositeRecipeRefusesBadSkills) {
  std::string file = CompositeRecipe::default_file("hurdle");
  std::string fwd = "assets/policies/walker/walker_forward.pt";
  try {
    CompositeRecipe::load(file, {"skills.walk.policy=assets/policies/walker/none.pt"});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("key 'skills.walk.policy': no such policy file"), std::string::npos) << e.what();
  }
  try {  // a 26-input policy given the whole 28-number Hurdle observation
    CompositeRecipe::load(file, {"skills.walk.policy=" + fwd, "skills.jump.policy=" + fwd, "skills.jump.obs=[0, 28]"});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("key 'skills.jump.obs'"), std::string::npos) << e.what();
  }
  try {
    CompositeRecipe::load(file, {"skills.walk.policy=" + fwd, "skills.jump.policy=" + fwd, "transitions.0.to=hop"});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no skill named 'hop'"), std::string::npos) << e.what();
  }
}

}  // namespace segue
