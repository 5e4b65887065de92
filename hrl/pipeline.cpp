#include "hrl/pipeline.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <sstream>

#include "core/progress.h"
#include "core/run_dir.h"
#include "hrl/lee_transition.h"
#include "hrl/results_table.h"
#include "hrl/switch_training.h"
#include "hrl/transition_env.h"
#include "hrl/transition_policy.h"

namespace segue {
namespace {

namespace fs = std::filesystem;

bool exists(const std::string& path) { return fs::exists(path); }

// The signal number that asked the run to stop, or 0.
int signal_of(const std::atomic<int>* stop) { return stop ? stop->load() : 0; }

// Exports transition t's trained `file` (policy.pt, lee.pt, q.pt) into its folder, saying
// what it is for (checked by load_transition_artefacts).
void export_artefact(Policy p, const CompositeRecipe& r, int t, const std::string& dir, const std::string& file) {
  p.set_source(r.transition_source(t) + " " + file);
  p.export_torchscript(dir + "/" + file);
}

// Refuses S_a or T_b collected for another task or transition (files copied between
// folders or runs). Files from before sources were kept have none and are let through.
void check_source(const std::string& source, const CompositeRecipe& r, int t, const std::string& path,
                  const std::string& what) {
  const std::string expected = r.transition_source(t);
  if (!source.empty() && source != expected)
    throw Error(path + ": " + what + " collected for '" + source + "', but this folder is '" + expected + "'");
}

// Transition t's S_a and T_b from its folder, refused (naming the file) when they were
// collected for another transition or their widths are not this task's and pi_b's.
StartStates starts_of(const CompositeRecipe& r, int t, const std::string& dir) {
  const std::string path = dir + "/start_states.pt";
  StartStates s = load_start_states(path);
  check_source(s.source, r, t, path, "S_a");
  if (s.obs_dim != r.spec.obs_dim)
    throw Error(path + ": S_a of observations " + std::to_string(s.obs_dim) + " wide, but task '" + r.spec.name +
                "' has " + std::to_string(r.spec.obs_dim));
  return s;
}

Demonstrations demonstrations_of(const CompositeRecipe& r, int t, const std::string& dir) {
  const std::string path = dir + "/demonstrations.pt";
  const Skill& b = r.skills[r.meta.transitions()[t].to];
  Demonstrations d = load_demonstrations(path);
  check_source(d.source, r, t, path, "T_b");
  if (d.obs_dim != b.obs_end - b.obs_begin || d.act_dim != r.spec.act_dim)
    throw Error(path + ": T_b of (s, a) " + std::to_string(d.obs_dim) + " x " + std::to_string(d.act_dim) +
                " wide, but pi_b takes " + std::to_string(b.obs_end - b.obs_begin) + " x " +
                std::to_string(r.spec.act_dim));
  return d;
}

// Returns the signal number when stopped (nothing of the unfinished set is kept), else 0.
int collect(const CompositeRecipe& r, int t, const std::string& run, const std::string& dir,
            const std::atomic<int>* stop) {
  const CollectConfig& c = r.pipeline.collect;
  if (!exists(dir + "/start_states.pt")) {
    const int count = r.start_state_count(t);
    spdlog::info("  collecting S_a: {} states where the interval begins", count);
    StartStates s = collect_start_states(r, t, count, mix_seed(r.pipeline.seed, 2 * t),
                                         load_transition_artefacts(r, run, "policy.pt", /*with_q=*/false),
                                         kStartStateEpisodes, stop);
    if (int sig = signal_of(stop)) return sig;
    save(s, dir + "/start_states.pt");
  }
  if (!exists(dir + "/demonstrations.pt")) {
    const Transition& tr = r.meta.transitions()[t];
    if (tr.expert_after_handover)
      spdlog::info("  collecting T_b: at most {} steps of pi_b in its window, taking over at S_a's states",
                   c.demonstrations);
    else if (tr.expert_task.empty())
      spdlog::info("  collecting T_b: {} steps of pi_b in its own interval", c.demonstrations);
    else if (tr.expert_steps > 0)
      spdlog::info("  collecting T_b: {} steps of pi_b, its first {} of each episode on {}", c.demonstrations,
                   tr.expert_steps, tr.expert_task);
    else
      spdlog::info("  collecting T_b: {} steps of pi_b in its window on {}", c.demonstrations, tr.expert_task);
    // After the hand-over: from S_a's states less those held out for the switch margin.
    StartStates handovers;
    if (tr.expert_after_handover) {
      handovers = starts_of(r, t, dir);
      handovers.keep_first(handovers.size() - r.pipeline.switching.validation_starts);
    }
    Demonstrations d = collect_demonstrations(r, t, c.demonstrations, mix_seed(r.pipeline.seed, 2 * t + 1),
                                              kDemonstrationEpisodes, stop, &handovers);
    if (int sig = signal_of(stop)) return sig;
    save(d, dir + "/demonstrations.pt");
  }
  return 0;
}

// PPO iterations of `trainer` (a TransitionPolicyTrainer or LeeTrainer) to the budget,
// with checkpoints; `row` turns an iteration's stats into its CSV row. Returns the signal
// number when stopped, else 0.
template <class Trainer, class Row>
int train_loop(Trainer& trainer, const CompositeRecipe& r, int64_t total_steps, const std::string& label,
               const std::string& ckpt, MetricsCsv& csv, const PipelineOptions& o, Row row) {
  Progress progress(label, total_steps, trainer.ppo().global_step());
  double recent = NAN;
  while (trainer.ppo().global_step() < total_steps) {
    auto s = trainer.iterate();
    if (s.ppo.episodes > 0) recent = s.ppo.success_rate;
    csv.write(row(s));
    bool last = trainer.ppo().global_step() >= total_steps;
    int stop = signal_of(o.stop);
    if (last || stop || s.ppo.iteration % 10 == 0) trainer.save(ckpt, r.resolved);
    progress.update(trainer.ppo().global_step(), s.ppo.episode_return, recent);
    if (stop && !last) {
      progress.finish();
      return stop;
    }
  }
  progress.finish();
  spdlog::info("  {}: {} steps in {}; success {:.0f}% in its last episodes", label, trainer.ppo().global_step(),
               format_duration(trainer.ppo().wall_seconds()), 100 * recent);
  return 0;
}

template <class Trainer>
void resume(Trainer& trainer, const std::string& ckpt) {
  if (!exists(ckpt)) return;
  trainer.load(ckpt);
  spdlog::info("  resuming from iteration {} ({} steps)", trainer.ppo().iteration(), trainer.ppo().global_step());
}

// Algorithm 1. "success" in its log: episodes that reach the interval's end on their feet.
int train_transition(const CompositeRecipe& r, int t, const std::string& dir, const PipelineOptions& o) {
  const TransitionPolicyConfig& cfg = r.pipeline.transition;
  const Transition& tr = r.meta.transitions()[t];
  const Skill& b = r.skills[tr.to];
  StartStates starts = starts_of(r, t, dir);
  VectorEnv envs(
      [&] { return std::make_unique<TransitionEnv>(r.make_env(), starts, tr.training_window(), b.obs_begin, b.obs_end); },
      cfg.ppo.num_envs, o.threads);
  TransitionPolicyTrainer trainer(cfg, envs, demonstrations_of(r, t, dir), b.policy,
                                  mix_seed(r.pipeline.seed, 100 + t));
  const std::string ckpt = dir + "/transition_checkpoint.pt";
  resume(trainer, ckpt);
  MetricsCsv csv(dir + "/transition.csv",
                 {"iteration", "global_step", "episodes", "interval_completed", "episode_length", "airl_reward",
                  "disc_loss", "expert_accuracy", "generator_accuracy", "policy_loss", "value_loss", "approx_kl",
                  "wall_seconds"},
                 trainer.ppo().iteration());
  int stop = train_loop(trainer, r, cfg.ppo.total_steps, r.transition_name(t) + " pi_ab", ckpt, csv, o,
                        [&](const TransitionIterationStats& s) -> std::vector<double> {
                          return {double(s.ppo.iteration), double(s.ppo.global_step), double(s.ppo.episodes),
                                  s.ppo.success_rate, s.ppo.episode_length, s.airl_reward, s.disc_loss,
                                  s.expert_accuracy, s.generator_accuracy, s.ppo.policy_loss, s.ppo.value_loss,
                                  s.ppo.approx_kl, trainer.ppo().wall_seconds()};
                        });
  if (!stop) export_artefact(trainer.policy(), r, t, dir, "policy.pt");
  return stop;
}

// Lee et al. 2019. "success" in its log: hand-overs after which pi_b succeeded.
int train_lee(const CompositeRecipe& r, int t, const std::string& dir, const PipelineOptions& o) {
  const TransitionPolicyConfig& cfg = r.pipeline.transition;
  const Skill& b = r.skills[r.meta.transitions()[t].to];
  StartStates starts = starts_of(r, t, dir);
  const int subtask_steps = r.pipeline.switching.max_subtask_steps;
  VectorEnv envs([&] { return std::make_unique<LeeTransitionEnv>(r, t, starts, subtask_steps); }, cfg.ppo.num_envs,
                 o.threads);
  LeeTrainer trainer(cfg, r.pipeline.lee, envs, demonstrations_of(r, t, dir), b.policy,
                     mix_seed(r.pipeline.seed, 300 + t));
  const std::string ckpt = dir + "/lee_checkpoint.pt";
  resume(trainer, ckpt);
  MetricsCsv csv(dir + "/lee.csv",
                 {"iteration", "global_step", "episodes", "handover_success", "episode_length", "predictor_loss",
                  "policy_loss", "value_loss", "approx_kl", "wall_seconds"},
                 trainer.ppo().iteration());
  int stop = train_loop(trainer, r, cfg.ppo.total_steps, r.transition_name(t) + " Lee", ckpt, csv, o,
                        [&](const LeeTrainer::Stats& s) -> std::vector<double> {
                          return {double(s.ppo.iteration), double(s.ppo.global_step), double(s.ppo.episodes),
                                  s.handover_success, s.ppo.episode_length, s.predictor_loss, s.ppo.policy_loss,
                                  s.ppo.value_loss, s.ppo.approx_kl, trainer.ppo().wall_seconds()};
                        });
  if (!stop) export_artefact(trainer.policy(), r, t, dir, "lee.pt");
  return stop;
}

// Reports and checkpoints every tenth of the attempts (at most 100), so that a stopped
// stage resumes where it was; the checkpoint goes once q.pt is written. Returns the
// signal number when stopped, else 0.
int train_switch(const CompositeRecipe& r, int t, const std::string& run, const std::string& dir,
                 const std::atomic<int>* stop) {
  const SwitchConfig& cfg = r.pipeline.switching;
  SwitchTrainer trainer(cfg, r, t, starts_of(r, t, dir), Policy::load(dir + "/policy.pt"),
                        load_transition_artefacts(r, run, "policy.pt", /*with_q=*/false),
                        mix_seed(r.pipeline.seed, 200 + t));
  const std::string ckpt = dir + "/switch_checkpoint.pt";
  const int chunk = std::clamp(cfg.attempts / 10, 1, 100);
  if (exists(ckpt)) {
    trainer.load(ckpt);
    spdlog::info("  resuming from attempt {}", trainer.attempts_done());
  }
  MetricsCsv csv(dir + "/switch.csv", {"attempts", "epsilon", "subtask_success", "switch_step", "loss", "env_steps", "wall_seconds"},
                 (trainer.attempts_done() + chunk - 1) / chunk);
  while (trainer.attempts_done() < cfg.attempts) {
    SwitchStats s = trainer.run(std::min(chunk, cfg.attempts - trainer.attempts_done()));
    csv.write({double(trainer.attempts_done()), s.epsilon, s.success_rate, s.switch_step, s.loss,
               double(trainer.env_steps()), trainer.wall_seconds()});
    spdlog::info("  q_ab: {}/{} attempts, epsilon {:.2f}, pi_b succeeded in {:.0f}%, switch at step {:.1f}",
                 trainer.attempts_done(), cfg.attempts, s.epsilon, 100 * s.success_rate, s.switch_step);
    trainer.save(ckpt);
    int sig = signal_of(stop);
    if (sig && trainer.attempts_done() < cfg.attempts) return sig;
  }
  double margin = 0.0;
  if (cfg.validation_starts > 0) {
    MarginChoice c = trainer.choose_margin();
    // env_steps: the whole stage's, training and this check.
    MetricsCsv mc(dir + "/margins.csv", {"margin", "held_out_success", "chosen", "env_steps"}, 0);
    for (size_t m = 0; m < c.margins.size(); ++m) {
      mc.write({c.margins[m], c.success[m], double(c.margins[m] == c.margin), double(trainer.env_steps())});
      spdlog::info("  q_ab: margin {:g}: pi_b succeeded from {:.1f}% of {} held-out starts", c.margins[m],
                   100 * c.success[m], cfg.validation_starts);
    }
    margin = c.margin;
    spdlog::info("  q_ab: switches where Q(switch) > Q(stay) + {:g}", margin);
  }
  export_artefact(trainer.q_function(margin), r, t, dir, "q.pt");
  fs::remove(ckpt);
  spdlog::info("  q_ab: {} attempts, {} environment steps in {}", cfg.attempts, trainer.env_steps(),
               format_duration(trainer.wall_seconds()));
  return 0;
}

// Fig. 4's data: from the same S_a states, each of pi_a, pi_ab and pi_b drives through
// the interval; every action is a row "label,a0,...".
void write_actions(const CompositeRecipe& r, int t, const std::string& dir, int starts_used = 40) {
  const Transition& tr = r.meta.transitions()[t];
  const Skill& a = r.skills[tr.from];
  const Skill& b = r.skills[tr.to];
  StartStates starts = starts_of(r, t, dir);
  Policy pi_ab = Policy::load(dir + "/policy.pt");
  auto env = r.make_env();
  std::vector<float> obs(r.spec.obs_dim), act(r.spec.act_dim);
  std::vector<double> f(r.spec.feature_names.size()), state;
  std::ostringstream csv;
  csv << "label";
  for (int j = 0; j < r.spec.act_dim; ++j) csv << ",a" << j;
  csv << "\n";
  struct Driver {
    const char* label;
    const Policy* policy;
    int begin;
  };
  const std::string la = "pi_" + a.name, lab = "pi_" + a.name + "_" + b.name, lb = "pi_" + b.name;
  const Driver drivers[3] = {{la.c_str(), &a.policy, a.obs_begin}, {lab.c_str(), &pi_ab, b.obs_begin},
                             {lb.c_str(), &b.policy, b.obs_begin}};
  for (const Driver& d : drivers)
    for (int i = 0; i < std::min(starts_used, starts.size()); ++i) {
      starts.state(i, state);
      env->restore_state(state, obs.data());
      for (int step = 0; step < 1000; ++step) {
        d.policy->act(obs.data() + d.begin, 1, act.data());
        csv << d.label;
        for (float x : act) csv << "," << x;
        csv << "\n";
        if (env->step(act.data(), obs.data()).done()) break;
        env->features(f.data());
        if (!tr.running(f.data(), step + 1)) break;
      }
    }
  write_file_atomic(dir + "/actions.csv", csv.str());
}

}  // namespace

int run_pipeline(const CompositeRecipe& recipe, const PipelineOptions& o) {
  const std::string run = recipe.pipeline.run_dir;
  RunDir dir(run, recipe.resolved, recipe.defaulted);
  const int n = int(recipe.meta.transitions().size());
  const bool lee = recipe.pipeline.lee.enabled;
  const int stages = (lee ? 4 : 3) * n + 1;
  int stage = 0;
  auto announce = [&](const std::string& what) { spdlog::info("[stage {}/{}] {}", ++stage, stages, what); };
  // Runs a training stage unless its output exists; the signal number if it was stopped.
  auto stage_unless_done = [&](const std::string& output, const std::function<int()>& train) {
    if (exists(output)) {
      spdlog::info("  done already: {}", output);
      return 0;
    }
    int stop = train();
    if (stop) spdlog::warn("interrupted: rerun the same command to resume from the stage's last checkpoint");
    return stop;
  };
  auto tdir = [&](int t) { return run + "/" + recipe.transition_name(t); };
  // Every pi_ab first: S_a of a later transition is collected With TP through the earlier
  // ones, and switch training may carry episodes on through any of them (lookahead).
  for (int t = 0; t < n; ++t) {
    fs::create_directories(tdir(t));
    announce(recipe.transition_name(t) + ": collect S_a and T_b");
    if (int stop = collect(recipe, t, run, tdir(t), o.stop)) {
      spdlog::warn("interrupted: rerun the same command to resume (this collection starts over)");
      return stop;
    }
    announce(recipe.transition_name(t) + ": transition policy (AIRL, Algorithm 1)");
    if (int stop = stage_unless_done(tdir(t) + "/policy.pt", [&] { return train_transition(recipe, t, tdir(t), o); }))
      return stop;
  }
  for (int t = 0; t < n; ++t) {
    announce(recipe.transition_name(t) + ": switch Q-network (double DQN, Algorithm 2)");
    if (int stop = stage_unless_done(tdir(t) + "/q.pt", [&] { return train_switch(recipe, t, run, tdir(t), o.stop); }))
      return stop;
  }
  for (int t = 0; t < n && lee; ++t) {
    announce(recipe.transition_name(t) + ": Lee et al. 2019 baseline (proximity reward, termination head)");
    if (int stop = stage_unless_done(tdir(t) + "/lee.pt", [&] { return train_lee(recipe, t, tdir(t), o); }))
      return stop;
  }
  announce("evaluate every method");
  for (int t = 0; t < n; ++t)
    if (!exists(tdir(t) + "/actions.csv")) write_actions(recipe, t, tdir(t));
  const std::string table = run + "/" + recipe.task + ".json";
  if (exists(table)) {
    spdlog::info("  done already: {} (remove it to measure again)", table);
    return 0;
  }
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
