// segue train RECIPE: PPO on one task (or, with an `es` section, an evolution-strategy
// fine-tuning of a trained policy), with a run directory that survives interruption.
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include <spdlog/spdlog.h>

#include "hrl/evaluation.h"
#include "hrl/lead_in.h"
#include "algorithms/skill_recipe.h"
#include "core/assets.h"
#include "core/progress.h"
#include "core/run_dir.h"
#include "tools/segue/cli.h"

namespace segue::cli {
namespace {


const Command kTrain{
    "train",
    "RECIPE [--set key=value ...]",
    "Trains a skill with PPO, or with an `es:` section fine-tunes init_policy with\n"
    "evolution strategies. Writes the run directory (recipe.yaml, metrics.csv,\n"
    "checkpoint.pt, policy.pt, eval.json). Rerunning the same command after an\n"
    "interruption resumes from the last checkpoint; a finished run is only re-evaluated.",
    {"RECIPE"},
    {{"set", "key=value", "override a recipe key (repeatable), e.g. --set ppo.lr=1e-4", true},
     {"threads", "N", "threads for environments and LibTorch (overrides the recipe; 0 = all)"}}};

// The end of every run: export the policy, evaluate it on the recipe's eval task, write
// eval.json.
int finish_run(const Policy& policy, const SkillRecipe& s, const RunDir& dir, int64_t env_steps,
               double wall_seconds, int threads) {
  policy.export_torchscript(dir.file("policy.pt"));
  EvalResult ev = evaluate_policy(policy, s.eval_make_env, s.eval_episodes, s.eval_seed, threads);
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

Policy load_init_policy(const SkillRecipe& s, const std::string& recipe_path, const EnvSpec& spec, bool prefix) {
  const std::string from = repo_path(s.init_policy);
  if (!std::filesystem::exists(from))
    throw Error(recipe_path + ": key 'init_policy': no such policy '" + s.init_policy + "'");
  Policy start = Policy::load(from);
  start.check_fits(spec, recipe_path + ": key 'init_policy': '" + s.init_policy + "'", prefix);
  return start;
}

// Evolution strategies from init_policy: a checkpoint (with the step and time counters),
// policy.pt (theta, to evaluate mid-run) and a metrics row every generation.
int train_es(const SkillRecipe& s, const Recipe& recipe, const std::string& recipe_path, RunDir& dir,
             int threads) {
  const EsConfig& cfg = *s.es;
  const Policy start = load_init_policy(s, recipe_path, s.make_env()->spec(), /*prefix=*/false);
  const SearchedParameters space = [&] {
    try {
      return SearchedParameters(start, cfg.inputs);
    } catch (const Error& e) {
      throw Error(recipe_path + ": key 'es.inputs': " + e.what());
    }
  }();
  EvolutionStrategy es(cfg, space.initial(), s.seed);
  int64_t env_steps = 0;
  double wall = 0.0;
  if (dir.has_checkpoint()) {
    std::vector<int64_t> counters = es.load(dir.checkpoint());
    if (counters.size() == 2) env_steps = counters[0], wall = counters[1] / 1000.0;
    spdlog::info("resuming {} from generation {} ({} steps)", dir.path(), es.generation(), env_steps);
  } else {
    spdlog::info("fine-tuning {} on {} in {} with evolution strategies: {} generations of {} candidates x {} "
                 "episodes",
                 s.init_policy, s.task, dir.path(), cfg.generations, 2 * cfg.pairs, cfg.episodes);
  }
  MetricsCsv csv(dir.file("metrics.csv"),
                 {"generation", "global_step", "theta_success", "theta_return", "candidate_success_mean",
                  "candidate_success_max", "candidate_return_mean", "gradient_norm", "wall_seconds"},
                 es.generation());
  const std::atomic<int>& stop = install_stop_signals();
  Progress progress(s.task + " (es)", cfg.generations, es.generation(), "generation");
  while (es.generation() < cfg.generations) {
    auto t0 = std::chrono::steady_clock::now();
    std::vector<Policy> candidates;
    for (const auto& theta : es.ask()) candidates.push_back(space.policy_at(theta));
    candidates.push_back(space.policy_at(es.theta()));  // the centre, for the log only
    const uint64_t seed = es.episode_seed();
    std::vector<EvalResult> results = evaluate_population(candidates, s.make_env, cfg.episodes, seed, threads);
    std::vector<double> fitness;
    double steps = 0, best = 0, mean_success = 0, mean_return = 0;
    const double n = double(results.size() - 1);
    for (size_t c = 0; c + 1 < results.size(); ++c) {
      const double success = results[c].success_rate(), ret = summarize(results[c].returns).mean;
      fitness.push_back(cfg.fitness == "success" ? success : ret);
      best = std::max(best, success);
      mean_success += success / n;
      mean_return += ret / n;
    }
    for (const EvalResult& r : results)
      for (double l : r.lengths) steps += l;
    const EvalResult& centre = results.back();
    const double centre_success = centre.success_rate(), centre_return = summarize(centre.returns).mean;
    const double grad = es.tell(fitness);
    env_steps += int64_t(steps);
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    es.save(dir.checkpoint(), recipe.resolved_yaml(), {env_steps, int64_t(wall * 1000)});
    space.policy_at(es.theta()).export_torchscript(dir.file("policy.pt"));
    csv.write({double(es.generation()), double(env_steps), centre_success, centre_return, mean_success, best,
               mean_return, grad, wall});
    progress.update(es.generation(), centre_return, centre_success);
    if (stop && es.generation() < cfg.generations) {
      progress.finish();
      spdlog::warn("interrupted: checkpoint saved at generation {}; rerun the same command to resume",
                   es.generation());
      return 128 + stop;
    }
  }
  progress.finish();
  uninstall_stop_signals();
  return finish_run(space.policy_at(es.theta()), s, dir, env_steps, wall, threads);
}

}  // namespace

int train_main(int argc, char** argv) {
  Args args(kTrain, argc, argv);
  if (args.help()) return print_help(kTrain);
  const std::string recipe_path = args.positional(0);
  auto sets = args.all("set");
  if (args.has("threads")) sets.push_back("threads=" + args.get("threads", "0"));
  Recipe recipe = Recipe::load(recipe_path, sets);
  std::string stem = std::filesystem::path(recipe_path).stem().string();
  SkillRecipe s = SkillRecipe::read(recipe, "runs/" + stem);
  if (recipe.root().has("lead_in"))  // training episodes only: eval_make_env keeps the task's start
    s.make_env = with_lead_in(s.make_env, LeadIn::read(recipe.root().sub("lead_in"), s.make_env()->spec()));
  recipe.reject_unknown();

  const int threads = resolve_threads(s.threads);
  // LibTorch runs on one thread: the networks are too small to gain from more, and a
  // fixed thread count keeps floating-point sums, and so the trained policy, the same
  // whatever `threads` is. `threads` parallelises environment stepping only.
  set_torch_threads(1);
  RunDir dir(s.run_dir, recipe.resolved_yaml(), recipe.defaulted_keys());
  if (s.es) return train_es(s, recipe, recipe_path, dir, threads);
  VectorEnv envs(s.make_env, s.ppo.num_envs, threads);
  PPO ppo(s.ppo, s.net, envs, s.seed);
  if (dir.has_checkpoint()) {
    ppo.load(dir.checkpoint());
    spdlog::info("resuming {} from iteration {} ({} steps)", dir.path(), ppo.iteration(), ppo.global_step());
  } else if (!s.init_from.empty()) {
    const std::string from = repo_path(s.init_from);
    if (!std::filesystem::exists(from))
      throw Error(recipe_path + ": key 'init_from': no such checkpoint '" + s.init_from + "'");
    ppo.load(from);
    if (!std::isnan(s.init_log_std)) ppo.set_log_std(s.init_log_std);
    if (s.restart_lr_schedule) ppo.restart_lr_schedule();
    spdlog::info("training {} in {} from {} (iteration {}, {} steps) to {} steps", s.task, dir.path(), s.init_from,
                 ppo.iteration(), ppo.global_step(), s.ppo.total_steps);
  } else if (!s.init_policy.empty()) {
    const std::string key = recipe_path + ": key 'init_policy': '" + s.init_policy + "'";
    Policy start = load_init_policy(s, recipe_path, envs.spec(), /*prefix=*/true);
    try {
      ppo.init_actor(start);
    } catch (const Error& e) {
      throw Error(key + ": " + e.what());
    }
    spdlog::info("training {} in {} with the actor of {} to {} steps", s.task, dir.path(), s.init_policy,
                 s.ppo.total_steps);
  } else {
    spdlog::info("training {} in {} ({} steps, {} threads)", s.task, dir.path(), s.ppo.total_steps, threads);
  }
  MetricsCsv csv(dir.file("metrics.csv"),
                 {"iteration", "global_step", "episodes", "episode_return", "episode_length",
                  "success_rate", "success_count", "policy_loss", "value_loss", "entropy",
                  "approx_kl", "clip_fraction", "rollout_seconds", "update_seconds", "wall_seconds"},
                 ppo.iteration());

  const std::atomic<int>& stop = install_stop_signals();
  Progress progress(s.task, s.ppo.total_steps, ppo.global_step());
  double recent_return = NAN, recent_success = NAN;
  while (ppo.global_step() < s.ppo.total_steps) {
    IterationStats st = ppo.iterate();
    if (st.episodes > 0) recent_return = st.episode_return, recent_success = st.success_rate;
    csv.write({double(st.iteration), double(st.global_step), double(st.episodes), st.episode_return,
               st.episode_length, st.success_rate, st.success_count, st.policy_loss, st.value_loss,
               st.entropy, st.approx_kl, st.clip_fraction, st.rollout_seconds, st.update_seconds,
               ppo.wall_seconds()});
    bool last = ppo.global_step() >= s.ppo.total_steps;
    if (last || stop || st.iteration % s.checkpoint_every == 0)
      ppo.save(dir.checkpoint(), recipe.resolved_yaml());
    progress.update(ppo.global_step(), recent_return, recent_success);
    if (stop && !last) {
      progress.finish();
      spdlog::warn("interrupted: checkpoint saved at iteration {}; rerun the same command to resume",
                   ppo.iteration());
      return 128 + stop;
    }
  }
  progress.finish();
  uninstall_stop_signals();

  return finish_run(ppo.policy(), s, dir, ppo.global_step(), ppo.wall_seconds(), threads);
}

}  // namespace segue::cli
