#include "hrl/skill_training.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <sstream>

#include "core/assets.h"
#include "core/distributed.h"
#include "core/progress.h"
#include "core/run_dir.h"
#include "core/thread_pool.h"
#include "hrl/evaluation.h"
#include "hrl/lead_in.h"
#include "hrl/skill_recipe.h"
#include "hrl/training_loop.h"

namespace segue {
namespace {

// The end of every run: export the policy, evaluate it on the recipe's eval task, write
// eval.json.
int finish_run(const Policy& policy, const SkillRecipe& s, const RunDir& dir, int64_t env_steps,
               double wall_seconds, int threads) {
  policy.export_torchscript(dir.file("policy.pt"));
  EvalResult ev = evaluate_policy(policy, s.eval_make_env, s.eval_episodes, s.eval_seed, threads, "eval " + s.task);
  Summary ret = summarize(ev.returns), count = summarize(ev.success_counts);
  double success = ev.success_rate();
  std::vector<std::pair<std::string, double>> fields{
      {"env_steps", double(env_steps)},  {"wall_seconds", wall_seconds},
      {"threads", double(threads)},      {"episodes", double(s.eval_episodes)},
      {"return_mean", ret.mean},         {"return_std", ret.std},
      {"success_rate", success},         {"success_count_mean", count.mean}};
  for (size_t k = 0; k < ev.metric_names.size(); ++k)
    fields.push_back({ev.metric_names[k] + "_mean", summarize(ev.metric_means[k]).mean});
  write_file_atomic(dir.file("eval.json"), json_object(fields) + "\n");
  spdlog::info("done: {} steps in {}; eval over {} episodes: return {:.1f} +- {:.1f}, success {:.0f}%",
               env_steps, format_duration(wall_seconds), s.eval_episodes, ret.mean, ret.std, 100 * success);
  spdlog::info("policy: {}", dir.file("policy.pt"));
  return 0;
}

// init_policy, checked against the task: its observation may be a prefix of the task's.
Policy load_init_policy(const SkillRecipe& s, const std::string& recipe_path, const EnvSpec& spec) {
  const std::string from = repo_path(s.init_policy);
  if (!std::filesystem::exists(from))
    throw Error(recipe_path + ": key 'init_policy': no such policy '" + s.init_policy + "'");
  Policy start = [&] {
    try {
      return Policy::load(from);
    } catch (const Error& e) {
      throw Error(recipe_path + ": key 'init_policy': " + e.what());
    }
  }();
  start.check_fits(spec, recipe_path + ": key 'init_policy': '" + s.init_policy + "'", /*prefix=*/true);
  return start;
}

// A skill recipe read whole (its lead-in included), unknown keys refused.
SkillRecipe read_skill(const Recipe& recipe, const std::string& default_run_dir) {
  SkillRecipe s = SkillRecipe::read(recipe, default_run_dir);
  if (recipe.root().has("lead_in"))  // training episodes only: eval_make_env keeps the task's start
    s.make_env = with_lead_in(s.make_env, LeadIn::read(recipe.root().sub("lead_in"), s.make_env()->spec()));
  recipe.reject_unknown();
  return s;
}

int train_skill(const Recipe& recipe, const SkillRecipe& s, const std::atomic<int>* stop);

// A curriculum: `stages:`, each a partial recipe laid over the rest of the file and run in
// its own directory RUN_DIR/N-NAME. Stage N+1 continues stage N's checkpoint (network,
// optimiser, normalisers, counters; its learner's total_steps are its own steps), or with
// `continue: policy` starts its actor as stage N's policy with a fresh critic. Finished
// stages are skipped, so rerunning resumes inside the stage that was interrupted.
struct Stage {
  std::string name;
  bool from_policy = false;
  YAML::Node overrides;
};

std::vector<Stage> read_stages(const Recipe& recipe) {
  std::vector<Stage> out;
  std::set<std::string> names;
  const std::vector<YAML::Node> items = recipe.stages();
  for (size_t i = 0; i < items.size(); ++i) {
    const std::string key = "stages." + std::to_string(i);
    auto bad = [&](const std::string& sub, const std::string& why) {
      return Error(recipe.file() + ": key '" + key + "." + sub + "' " + why);
    };
    Stage st;
    st.overrides = YAML::Clone(items[i]);
    if (!st.overrides["name"].IsDefined() || !st.overrides["name"].IsScalar())
      throw bad("name", "is required: a name for the stage's directory");
    st.name = st.overrides["name"].Scalar();
    if (st.name.empty() || st.name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_-") != std::string::npos)
      throw bad("name", "must be lower-case letters, digits, '_' or '-', got '" + st.name + "'");
    if (!names.insert(st.name).second) throw bad("name", "repeats the stage name '" + st.name + "'");
    if (st.overrides["continue"].IsDefined()) {
      const std::string how = st.overrides["continue"].Scalar();
      if (how != "checkpoint" && how != "policy") throw bad("continue", "must be 'checkpoint' or 'policy', got '" + how + "'");
      if (i == 0) throw bad("continue", "is for later stages: the first has nothing to continue");
      st.from_policy = how == "policy";
    }
    for (const char* k : {"run_dir", "stages"})
      if (st.overrides[k].IsDefined()) throw bad(k, "cannot be set per stage");
    if (i > 0)
      for (const char* k : {"init_from", "init_policy"})
        if (st.overrides[k].IsDefined()) throw bad(k, "is set by the stage before (see 'continue')");
    st.overrides.remove("name");
    st.overrides.remove("continue");
    out.push_back(st);
  }
  return out;
}

std::string stage_dir(const std::string& top, size_t i, const Stage& st) {
  return top + "/" + std::to_string(i + 1) + "-" + st.name;
}

double eval_env_steps(const std::string& eval_json) {
  std::smatch m;
  const std::string text = read_file(eval_json);
  if (!std::regex_search(text, m, std::regex("\"env_steps\":\\s*([0-9.eE+]+)")))
    throw Error(eval_json + ": no env_steps");
  return std::stod(m[1]);
}

// RUN_DIR/metrics.csv: every stage's rows in order, the stage's name in a first column.
void write_stage_metrics(const std::string& top, const std::vector<Stage>& stages) {
  std::vector<std::string> columns;
  std::vector<std::pair<std::string, std::map<std::string, std::string>>> rows;
  for (size_t i = 0; i < stages.size(); ++i) {
    std::ifstream in(stage_dir(top, i, stages[i]) + "/metrics.csv");
    std::string line;
    if (!std::getline(in, line)) continue;
    std::vector<std::string> header;
    std::stringstream hs(line);
    for (std::string c; std::getline(hs, c, ',');) {
      header.push_back(c);
      if (std::find(columns.begin(), columns.end(), c) == columns.end()) columns.push_back(c);
    }
    while (std::getline(in, line)) {
      std::map<std::string, std::string> row;
      std::stringstream ls(line);
      size_t k = 0;
      for (std::string v; std::getline(ls, v, ',') && k < header.size(); ++k) row[header[k]] = v;
      rows.push_back({stages[i].name, row});
    }
  }
  std::string out = "stage";
  for (const auto& c : columns) out += "," + c;
  out += "\n";
  for (const auto& [name, row] : rows) {
    out += name;
    for (const auto& c : columns) out += "," + (row.count(c) ? row.at(c) : "");
    out += "\n";
  }
  write_file_atomic(top + "/metrics.csv", out);
}

int train_stages(const Recipe& recipe, const std::string& default_run_dir, bool check_only,
                 const std::atomic<int>* stop) {
  const std::vector<Stage> stages = read_stages(recipe);
  const std::string top = recipe.root().get("run_dir", default_run_dir);
  // Stage i's recipe: the file, the stage's keys over it, then where it starts from.
  auto stage_recipe = [&](size_t i, const std::string& start, int64_t total_steps, const std::string& learner) {
    YAML::Node ov = YAML::Clone(stages[i].overrides);
    ov["run_dir"] = stage_dir(top, i, stages[i]);
    // A later stage starts from the stage before only: the file's own start (its first
    // stage's init_policy or init_from) is not carried over.
    if (i > 0) {
      ov[stages[i].from_policy ? "init_policy" : "init_from"] = start;
      ov[stages[i].from_policy ? "init_from" : "init_policy"] = "";
    }
    if (total_steps > 0) ov[learner]["total_steps"] = total_steps;
    // A stage that names its learner takes that learner's settings only: the file's
    // sections for the others (its PPO settings, say, under a TRPO stage) stay behind.
    std::vector<std::string> without;
    if (ov["learner"].IsDefined())
      for (const std::string other : kLearners)
        if (other != ov["learner"].Scalar()) without.push_back(other);
    return recipe.with_overrides(ov, recipe.file() + " (stage " + stages[i].name + ")", without);
  };
  // Every stage is read and checked before the first step of the first. The curriculum's
  // ETA: each stage's line at one rate per step, from 0 where it continues a checkpoint.
  JobPlan plan;
  int64_t line_end = 0;
  for (size_t i = 0; i < stages.size(); ++i) {
    const int64_t steps = read_skill(stage_recipe(i, "(the stage before)", 0, ""), top).total_steps();
    line_end = i == 0 || stages[i].from_policy ? steps : line_end + steps;
    plan.add(stages[i].name, 1e-3 * double(line_end));
  }
  if (check_only) return 0;
  // With several ranks, rank 0's files decide (which stages are done, their steps).
  const Distributed& group = Distributed::world();
  if (group.leader()) std::filesystem::create_directories(top);
  for (size_t i = 0; i < stages.size(); ++i) {
    const std::string dir = stage_dir(top, i, stages[i]);
    if (group.any(group.leader() && std::filesystem::exists(dir + "/eval.json"))) {
      spdlog::info("stage {}/{} '{}' is done ({})", i + 1, stages.size(), stages[i].name, dir);
      plan.skip(stages[i].name);
      continue;
    }
    std::string start;
    int64_t total = 0;
    const std::string learner = SkillRecipe::read(stage_recipe(i, "", 0, ""), top).learner;
    if (i > 0) {
      const std::string prev = stage_dir(top, i - 1, stages[i - 1]);
      start = prev + (stages[i].from_policy ? "/policy.pt" : "/checkpoint.pt");
      // Continuing a checkpoint: the stage's own steps on top of those it has done.
      if (!stages[i].from_policy)
        total = std::stoll(group.broadcast(group.leader() ? std::to_string(int64_t(eval_env_steps(prev + "/eval.json"))) : "")) +
                SkillRecipe::read(stage_recipe(i, start, 0, learner), top).total_steps();
    }
    const Recipe r = stage_recipe(i, start, total, learner);
    spdlog::info("stage {}/{} '{}' in {}  (curriculum: {})", i + 1, stages.size(), stages[i].name, dir,
                 plan.summary());
    plan.begin(stages[i].name);
    const int rc = train_skill(r, read_skill(r, top), stop);
    if (group.leader()) write_stage_metrics(top, stages);
    if (rc != 0) return rc;
  }
  if (!group.leader()) return 0;
  write_stage_metrics(top, stages);
  const std::string last = stage_dir(top, stages.size() - 1, stages.back());
  for (const char* f : {"policy.pt", "eval.json", "checkpoint.pt"})
    std::filesystem::copy_file(last + "/" + f, top + "/" + f, std::filesystem::copy_options::overwrite_existing);
  write_file_atomic(top + "/recipe.yaml", read_file(recipe.file()));
  spdlog::info("curriculum done: {} stages; policy {}/policy.pt", stages.size(), top);
  return 0;
}

int train_skill(const Recipe& recipe, const SkillRecipe& s, const std::atomic<int>* stop) {
  const std::string recipe_path = recipe.file();
  const Distributed& group = Distributed::world();
  require_same_recipe(recipe.resolved_yaml(), recipe.file());  // read whole by now: every key with its value or default
  const int threads = resolve_threads(s.threads);
  // LibTorch runs on one thread: the networks are too small to gain from more, and a
  // fixed thread count keeps floating-point sums, and so the trained policy, the same
  // whatever `threads` is. `threads` parallelises environment stepping only.
  set_torch_threads(1);
  // Rank 0 keeps the run directory; the other ranks learn from it whether to resume. A
  // fresh run reads its starting point before the directory is made, so that a refused
  // init_from or init_policy leaves no recipe behind for the corrected one to clash with.
  std::optional<RunDir> dir;
  auto make_dir = [&] {
    if (group.leader()) dir.emplace(s.run_dir, recipe.resolved_yaml(), recipe.defaulted_keys());
  };
  const std::string checkpoint = s.run_dir + "/checkpoint.pt";
  const bool resume = group.any(group.leader() && std::filesystem::exists(checkpoint));
  if (s.learner == "sac" && !group.single())
    throw Error(recipe_path + ": key 'learner': sac runs on one process (drop --nproc)");
  const Shard share = group.shard(s.num_envs(), recipe_path + ": key '" + s.learner + ".num_envs'");
  VectorEnv envs(s.make_env, share.count, threads, share.first);
  const std::unique_ptr<Learner> learner = make_learner(s, envs, group);
  OnPolicyLearner* on_policy = dynamic_cast<OnPolicyLearner*>(learner.get());  // PPO, TRPO: null for SAC
  const int64_t total_steps = s.total_steps();
  if (resume) {
    make_dir();  // first: a different recipe is refused before its checkpoint is read
    learner->load_checkpoint(checkpoint, /*resume=*/true);
    if (learner->global_step() >= total_steps) {  // nothing left to train: export and evaluate again
      spdlog::info("{} is finished ({} steps); re-evaluating its policy", s.run_dir, learner->global_step());
      if (!group.leader()) return 0;
      return finish_run(learner->policy(), s, *dir, learner->global_step(), learner->wall_seconds(), threads);
    }
    spdlog::info("resuming {} from iteration {} ({} steps)", s.run_dir, learner->iteration(), learner->global_step());
  } else if (!s.init_from.empty()) {
    const std::string from = repo_path(s.init_from);
    if (group.leader() && !std::filesystem::exists(from))
      throw Error(recipe_path + ": key 'init_from': no such checkpoint '" + s.init_from + "'");
    try {
      learner->load_checkpoint(from, /*resume=*/false);
    } catch (const Error& e) {
      throw Error(recipe_path + ": key 'init_from': " + e.what());
    }
    if (!std::isnan(s.init_log_std)) on_policy->set_log_std(s.init_log_std);
    if (s.restart_lr_schedule) on_policy->restart_lr_schedule();
    spdlog::info("training {} in {} from {} (iteration {}, {} steps) to {} steps", s.task, s.run_dir, s.init_from,
                 learner->iteration(), learner->global_step(), total_steps);
  } else if (!s.init_policy.empty()) {
    const std::string key = recipe_path + ": key 'init_policy': '" + s.init_policy + "'";
    Policy start = load_init_policy(s, recipe_path, envs.spec());
    try {
      on_policy->init_actor(start);
    } catch (const Error& e) {
      throw Error(key + ": " + e.what());
    }
    spdlog::info("training {} in {} with the actor of {} to {} steps", s.task, s.run_dir, s.init_policy,
                 total_steps);
  } else if (group.single()) {
    spdlog::info("training {} in {} ({} steps, {} threads)", s.task, s.run_dir, total_steps, threads);
  } else {
    spdlog::info("training {} in {} ({} steps) on {} ranks, {} threads each", s.task, s.run_dir, total_steps,
                 group.size(), threads);
  }
  if (!resume) make_dir();
  TrainingLoop loop{s.task, total_steps, s.checkpoint_every, "", {}, &group, stop};
  if (group.leader()) {
    // The episode columns, the learner's own (update_columns()), then the timings.
    loop.csv_path = dir->file("metrics.csv");
    loop.columns = {"iteration", "global_step", "episodes", "episode_return", "episode_length", "success_rate",
                    "success_count"};
    for (const auto& c : learner->update_columns()) loop.columns.push_back(c);
    for (const char* c : {"rollout_seconds", "update_seconds", "wall_seconds", "comm_seconds"}) loop.columns.push_back(c);
  }
  const int sig = run_training_loop(
      loop, learner->iteration(), learner->global_step(),
      [&](std::vector<double>& row) {
        IterationStats st = learner->iterate();
        row = {double(st.iteration), double(st.global_step), double(st.episodes), st.episode_return,
               st.episode_length,    st.success_rate,        st.success_count};
        for (double v : learner->update_values(st)) row.push_back(v);
        for (double v : {st.rollout_seconds, st.update_seconds, learner->wall_seconds(), st.comm_seconds})
          row.push_back(v);
        return st;
      },
      [&] { learner->save(checkpoint, recipe.resolved_yaml()); });
  if (sig) {
    spdlog::warn("interrupted: checkpoint saved at iteration {}; rerun the same command to resume",
                 learner->iteration());
    return 128 + sig;
  }
  if (!group.leader()) return 0;  // rank 0 exports and evaluates
  return finish_run(learner->policy(), s, *dir, learner->global_step(), learner->wall_seconds(), threads);
}

}  // namespace

size_t check_skill_recipe(const Recipe& recipe, const std::string& default_run_dir) {
  if (recipe.stages().empty()) {
    read_skill(recipe, default_run_dir);
    return 0;
  }
  train_stages(recipe, default_run_dir, /*check_only=*/true, nullptr);
  return recipe.stages().size();
}

int train_skill_recipe(const Recipe& recipe, const std::string& default_run_dir, const std::atomic<int>* stop) {
  if (!recipe.stages().empty()) return train_stages(recipe, default_run_dir, /*check_only=*/false, stop);
  return train_skill(recipe, read_skill(recipe, default_run_dir), stop);
}

}  // namespace segue
