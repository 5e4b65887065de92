#include "hrl/pipeline.h"

#include <spdlog/spdlog.h>

#include <filesystem>

#include "core/progress.h"
#include "core/run_dir.h"
#include "hrl/results_table.h"
#include "hrl/switch_training.h"
#include "hrl/transition_env.h"
#include "hrl/transition_policy.h"

namespace segue {
namespace {

namespace fs = std::filesystem;

bool exists(const std::string& path) { return fs::exists(path); }

// The transition policies and Q-networks trained so far in this run.
std::vector<TransitionArtefacts> trained_so_far(const CompositeRecipe& r, const std::string& run) {
  std::vector<TransitionArtefacts> out(r.meta.transitions().size());
  for (size_t t = 0; t < out.size(); ++t) {
    std::string dir = run + "/" + r.transition_name(int(t));
    if (exists(dir + "/policy.pt")) out[t].policy = Policy::load(dir + "/policy.pt");
    if (exists(dir + "/q.pt")) out[t].q = Policy::load(dir + "/q.pt");
  }
  return out;
}

void collect(const CompositeRecipe& r, int t, const std::string& run, const std::string& dir) {
  const CollectConfig& c = r.pipeline.collect;
  if (!exists(dir + "/start_states.pt")) {
    spdlog::info("  collecting S_a: {} states where pi_a enters the interval", c.start_states);
    save(collect_start_states(r, t, c.start_states, mix_seed(r.pipeline.seed, 2 * t), trained_so_far(r, run)),
         dir + "/start_states.pt");
  }
  if (!exists(dir + "/demonstrations.pt")) {
    spdlog::info("  collecting T_b: {} steps of pi_b in its own interval", c.demonstrations);
    save(collect_demonstrations(r, t, c.demonstrations, mix_seed(r.pipeline.seed, 2 * t + 1)),
         dir + "/demonstrations.pt");
  }
}

// Returns the signal number when stopped, else 0.
int train_transition(const CompositeRecipe& r, int t, const std::string& dir, const PipelineOptions& o) {
  const TransitionPolicyConfig& cfg = r.pipeline.transition;
  const Transition& tr = r.meta.transitions()[t];
  const Skill& b = r.skills[tr.to];
  StartStates starts = load_start_states(dir + "/start_states.pt");
  Demonstrations expert = load_demonstrations(dir + "/demonstrations.pt");
  VectorEnv envs(
      [&] { return std::make_unique<TransitionEnv>(r.make_env(), starts, tr.when, b.obs_begin, b.obs_end); },
      cfg.ppo.num_envs, o.threads);
  TransitionPolicyTrainer trainer(cfg, envs, std::move(expert), b.policy, mix_seed(r.pipeline.seed, 100 + t));
  const std::string ckpt = dir + "/transition_checkpoint.pt";
  if (exists(ckpt)) {
    trainer.load(ckpt);
    spdlog::info("  resuming from iteration {} ({} steps)", trainer.ppo().iteration(), trainer.ppo().global_step());
  }
  MetricsCsv csv(dir + "/transition.csv",
                 {"iteration", "global_step", "episodes", "interval_completed", "episode_length", "airl_reward",
                  "disc_loss", "expert_accuracy", "generator_accuracy", "policy_loss", "value_loss", "approx_kl",
                  "wall_seconds"},
                 trainer.ppo().iteration());
  Progress progress(r.transition_name(t) + " pi_ab", cfg.ppo.total_steps, trainer.ppo().global_step());
  double completed = NAN;
  while (trainer.ppo().global_step() < cfg.ppo.total_steps) {
    TransitionIterationStats s = trainer.iterate();
    if (s.ppo.episodes > 0) completed = s.ppo.success_rate;
    csv.write({double(s.ppo.iteration), double(s.ppo.global_step), double(s.ppo.episodes), s.ppo.success_rate,
               s.ppo.episode_length, s.airl_reward, s.disc_loss, s.expert_accuracy, s.generator_accuracy,
               s.ppo.policy_loss, s.ppo.value_loss, s.ppo.approx_kl, trainer.ppo().wall_seconds()});
    bool last = trainer.ppo().global_step() >= cfg.ppo.total_steps;
    int stop = o.stop ? o.stop->load() : 0;
    if (last || stop || s.ppo.iteration % 10 == 0) trainer.save(ckpt, r.resolved);
    // "success" here: episodes that reach the interval's end on their feet.
    progress.update(trainer.ppo().global_step(), s.airl_reward, completed);
    if (stop && !last) {
      progress.finish();
      return stop;
    }
  }
  progress.finish();
  trainer.policy().export_torchscript(dir + "/policy.pt");
  spdlog::info("  pi_ab: {} steps in {}; {:.0f}% of its last episodes reached the interval's end",
               trainer.ppo().global_step(), format_duration(trainer.ppo().wall_seconds()), 100 * completed);
  return 0;
}

void train_switch(const CompositeRecipe& r, int t, const std::string& dir) {
  const SwitchConfig& cfg = r.pipeline.switching;
  SwitchTrainer trainer(cfg, r, t, load_start_states(dir + "/start_states.pt"), Policy::load(dir + "/policy.pt"),
                        mix_seed(r.pipeline.seed, 200 + t));
  MetricsCsv csv(dir + "/switch.csv", {"attempts", "epsilon", "subtask_success", "switch_step", "loss"}, 0);
  const int chunk = 100;
  auto t0 = std::chrono::steady_clock::now();
  SwitchStats s;
  while (trainer.attempts_done() < cfg.attempts) {
    s = trainer.run(std::min(chunk, cfg.attempts - trainer.attempts_done()));
    csv.write({double(trainer.attempts_done()), s.epsilon, s.success_rate, s.switch_step, s.loss});
    spdlog::info("  q_ab: {}/{} attempts, epsilon {:.2f}, pi_b succeeded in {:.0f}%, switch at step {:.1f}",
                 trainer.attempts_done(), cfg.attempts, s.epsilon, 100 * s.success_rate, s.switch_step);
  }
  trainer.q_function().export_torchscript(dir + "/q.pt");
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  spdlog::info("  q_ab: {} attempts in {}", cfg.attempts, format_duration(secs));
}

}  // namespace

int run_pipeline(const CompositeRecipe& recipe, const PipelineOptions& o) {
  const std::string run = recipe.pipeline.run_dir;
  RunDir dir(run, recipe.resolved);
  const int n = int(recipe.meta.transitions().size());
  const int stages = 3 * n + 1;
  int stage = 0;
  auto announce = [&](const std::string& what) { spdlog::info("[stage {}/{}] {}", ++stage, stages, what); };
  for (int t = 0; t < n; ++t) {
    const std::string name = recipe.transition_name(t), tdir = run + "/" + name;
    fs::create_directories(tdir);
    announce(name + ": collect S_a and T_b");
    collect(recipe, t, run, tdir);
    announce(name + ": transition policy (AIRL, Algorithm 1)");
    if (exists(tdir + "/policy.pt")) {
      spdlog::info("  done already: {}/policy.pt", tdir);
    } else if (int stop = train_transition(recipe, t, tdir, o)) {
      spdlog::warn("interrupted: checkpoint saved; rerun the same command to resume");
      return stop;
    }
    announce(name + ": switch Q-network (double DQN, Algorithm 2)");
    if (exists(tdir + "/q.pt"))
      spdlog::info("  done already: {}/q.pt", tdir);
    else
      train_switch(recipe, t, tdir);
    if (o.stop && o.stop->load()) return o.stop->load();
  }
  announce("evaluate every method");
  CompositeRecipe trained = recipe;
  trained.transitions_dir = fs::absolute(run).string();
  std::vector<std::pair<std::string, std::string>> skipped;
  auto methods = available_methods(trained, method_names(), /*skip_missing=*/true, skipped);
  std::vector<MethodResult> results = measure_methods(trained, methods, o.threads);
  write_results(trained, results, skipped, o.command, run);
  spdlog::info("  wrote {}/{}.md and .json", run, recipe.task);
  if (!o.publish_dir.empty()) {
    write_results(trained, results, skipped, o.command, o.publish_dir);
    spdlog::info("  wrote {}/{}.md and .json", o.publish_dir, recipe.task);
  }
  return 0;
}

}  // namespace segue
