// segue train RECIPE: PPO on one task, with a run directory that survives interruption.
#include <atomic>
#include <cstdio>
#include <filesystem>

#include <spdlog/spdlog.h>

#include "hrl/evaluation.h"
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
    "Trains a skill with PPO. Writes the run directory (recipe.yaml, metrics.csv,\n"
    "checkpoint.pt, policy.pt, eval.json). Rerunning the same command after an\n"
    "interruption resumes from the last checkpoint; a finished run is only re-evaluated.",
    {"RECIPE"},
    {{"set", "key=value", "override a recipe key (repeatable), e.g. --set ppo.lr=1e-4", true},
     {"threads", "N", "threads for environments and LibTorch (overrides the recipe; 0 = all)"}}};

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
  recipe.reject_unknown();

  const int threads = resolve_threads(s.threads);
  // LibTorch runs on one thread: the networks are too small to gain from more, and a
  // fixed thread count keeps floating-point sums, and so the trained policy, the same
  // whatever `threads` is. `threads` parallelises environment stepping only.
  set_torch_threads(1);
  RunDir dir(s.run_dir, recipe.resolved_yaml(), recipe.defaulted_keys());
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
    const std::string from = repo_path(s.init_policy);
    if (!std::filesystem::exists(from))
      throw Error(recipe_path + ": key 'init_policy': no such policy '" + s.init_policy + "'");
    Policy start = Policy::load(from);
    const std::string key = recipe_path + ": key 'init_policy': '" + s.init_policy + "'";
    start.check_fits(envs.spec(), key, /*prefix=*/true);
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

  Policy policy = ppo.policy();
  policy.export_torchscript(dir.file("policy.pt"));
  EvalResult ev = evaluate_policy(policy, s.eval_make_env, s.eval_episodes, s.eval_seed, threads);
  Summary ret = summarize(ev.returns), count = summarize(ev.success_counts);
  double success = summarize(std::vector<double>(ev.successes.begin(), ev.successes.end())).mean;
  std::vector<std::pair<std::string, double>> fields{
      {"env_steps", double(ppo.global_step())}, {"wall_seconds", ppo.wall_seconds()},
      {"threads", double(threads)},             {"episodes", double(s.eval_episodes)},
      {"return_mean", ret.mean},                {"return_std", ret.std},
      {"success_rate", success},                {"success_count_mean", count.mean}};
  for (size_t k = 0; k < ev.metric_names.size(); ++k)
    fields.push_back({ev.metric_names[k] + "_mean", summarize(ev.metric_means[k]).mean});
  write_file_atomic(dir.file("eval.json"), json_object(fields) + "\n");
  spdlog::info("done: {} steps in {}; eval over {} episodes: return {:.1f} +- {:.1f}, success {:.0f}%",
               ppo.global_step(), format_duration(ppo.wall_seconds()), s.eval_episodes, ret.mean,
               ret.std, 100 * success);
  spdlog::info("policy: {}", dir.file("policy.pt"));
  return 0;
}

}  // namespace segue::cli
