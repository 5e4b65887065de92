#include "hrl/pipeline.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <optional>
#include <sstream>

#include "core/progress.h"
#include "core/run_dir.h"
#include "hrl/lee_transition.h"
#include "hrl/results_table.h"
#include "hrl/switch_training.h"
#include "hrl/training_loop.h"
#include "hrl/transition_env.h"
#include "hrl/transition_policy.h"

namespace segue {
namespace {

namespace fs = std::filesystem;

bool exists(const std::string& path) { return fs::exists(path); }

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
  if (s.size() > 0) {  // a state of another layout (an older Segue's) is refused here, naming the file
    std::vector<double> state;
    std::vector<float> obs(size_t(r.spec.obs_dim));
    s.state(0, state);
    try {
      r.training[t].env()->restore_state(state, obs.data());
    } catch (const Error& e) {
      throw Error(path + ": " + e.what() + "; remove it to collect S_a again");
    }
  }
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

// With several ranks each collects its share (its own episode seeds) into FILE.partR,
// and rank 0 joins the parts in rank order into FILE.
template <class Items, class Collect>
int collect_shared(const Distributed& group, const std::string& file, int count, uint64_t seed,
                   const std::atomic<int>* stop, Collect collect, Items (*load)(const std::string&)) {
  const Shard share = group.shard(count, file);
  Items items = collect(share.count, group.single() ? seed : mix_seed(seed, 0xc011 + group.rank()));
  if (const int sig = agreed_stop(group, stop)) return sig;
  if (group.single()) {
    save(items, file);
    return 0;
  }
  const std::string part = file + ".part" + std::to_string(group.rank());
  save(items, part);
  group.barrier();
  if (group.leader()) {
    Items all = load(file + ".part0");
    for (int r = 1; r < group.size(); ++r) all.append(load(file + ".part" + std::to_string(r)));
    save(all, file);
    for (int r = 0; r < group.size(); ++r) fs::remove(file + ".part" + std::to_string(r));
  }
  group.leader_done("collection");
  return 0;
}

// Returns the signal number when stopped (nothing of the unfinished set is kept), else 0.
// s_a: S_a as collected (read from its file once).
int collect(const CompositeRecipe& r, int t, const std::string& run, const std::string& dir,
            const std::function<const StartStates&()>& s_a, const std::atomic<int>* stop, const Distributed& group,
            int threads, JobPlan& plan) {
  const CollectConfig& c = r.pipeline.collect;
  const std::string name = r.transition_name(t);
  if (group.any(group.leader() && exists(dir + "/start_states.pt"))) {
    plan.skip(name + " S_a");
  } else {
    plan.begin(name + " S_a");
    const int count = r.start_state_count(t);
    spdlog::info("  collecting S_a: {} states where the interval begins", count);
    const auto trained = load_transition_artefacts(r, run, "policy.pt", /*with_q=*/false);
    if (int sig = collect_shared<StartStates>(
            group, dir + "/start_states.pt", count, mix_seed(r.pipeline.seed, 2 * t), stop,
            [&](int n, uint64_t seed) { return collect_start_states(r, t, n, seed, trained, kStartStateEpisodes, stop, threads); },
            load_start_states))
      return sig;
  }
  if (group.any(group.leader() && exists(dir + "/demonstrations.pt"))) {
    plan.skip(name + " T_b");
  } else {
    plan.begin(name + " T_b");
    const TransitionTrainingSpec& tr = r.training[t];
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
      handovers = s_a();
      handovers.keep_first(handovers.size() - r.pipeline.switching.validation_starts);
      // Each rank takes over at its own block of them.
      const Shard mine = group.shard(handovers.size(), dir + "/start_states.pt");
      handovers.states.erase(handovers.states.begin(), handovers.states.begin() + size_t(mine.first) * handovers.state_dim);
      handovers.obs.erase(handovers.obs.begin(), handovers.obs.begin() + size_t(mine.first) * handovers.obs_dim);
      handovers.keep_first(mine.count);
    }
    return collect_shared<Demonstrations>(
        group, dir + "/demonstrations.pt", c.demonstrations, mix_seed(r.pipeline.seed, 2 * t + 1), stop,
        [&](int n, uint64_t seed) {
          return collect_demonstrations(r, t, n, seed, kDemonstrationEpisodes, stop, &handovers, threads);
        },
        load_demonstrations);
  }
  return 0;
}

// PPO iterations of `trainer` (a TransitionPolicyTrainer or LeeTrainer) to the budget
// (hrl/training_loop.h); `row` turns an iteration's stats into its CSV row. Returns the
// signal number when stopped, else 0.
template <class Trainer, class Row>
int train_loop(Trainer& trainer, const CompositeRecipe& r, int64_t total_steps, const std::string& label,
               const std::string& ckpt, const std::string& csv_path, const std::vector<std::string>& columns,
               const PipelineOptions& o, Row row) {
  TrainingLoop loop{label, total_steps, 10, csv_path, columns, o.group, o.stop};
  double recent = NAN;
  const int stop = run_training_loop(
      loop, trainer.ppo().iteration(), trainer.ppo().global_step(),
      [&](std::vector<double>& out) {
        const auto s = trainer.iterate();
        out = row(s);
        if (s.ppo.episodes > 0) recent = s.ppo.success_rate;
        return s.ppo;
      },
      [&] { trainer.save(ckpt, r.resolved); });
  if (stop) return stop;
  spdlog::info("  {}: {} steps in {}; success {:.0f}% in its last episodes", label, trainer.ppo().global_step(),
               format_duration(trainer.ppo().wall_seconds()), 100 * recent);
  return 0;
}

template <class Trainer>
void resume(Trainer& trainer, const std::string& ckpt, const Distributed& group) {
  if (!group.any(group.leader() && exists(ckpt))) return;
  trainer.load(ckpt);
  spdlog::info("  resuming from iteration {} ({} steps)", trainer.ppo().iteration(), trainer.ppo().global_step());
}

// Algorithm 1. "success" in its log: episodes that reach the interval's end on their feet.
int train_transition(const CompositeRecipe& r, int t, const StartStates& starts, const std::string& dir,
                     const PipelineOptions& o) {
  const TransitionPolicyConfig& cfg = r.pipeline.transition;
  const Transition& tr = r.meta.transitions()[t];
  const Skill& b = r.skills[tr.to];
  const Shard share = o.group->shard(cfg.ppo.num_envs, "transition.ppo.num_envs");
  VectorEnv envs(
      [&] { return std::make_unique<TransitionEnv>(r.training[t].env(), starts, r.training[t].window(tr), b.obs_begin, b.obs_end); },
      share.count, o.threads, share.first);
  TransitionPolicyTrainer trainer(cfg, envs, demonstrations_of(r, t, dir), b.policy,
                                  mix_seed(r.pipeline.seed, 100 + t), *o.group);
  const std::string ckpt = dir + "/transition_checkpoint.pt";
  resume(trainer, ckpt, *o.group);
  int stop = train_loop(trainer, r, cfg.ppo.total_steps, r.transition_name(t) + " pi_ab", ckpt,
                        dir + "/transition.csv",
                        {"iteration", "global_step", "episodes", "interval_completed", "episode_length", "airl_reward",
                         "disc_loss", "expert_accuracy", "generator_accuracy", "policy_loss", "value_loss", "approx_kl",
                         "wall_seconds"},
                        o,
                        [&](const TransitionIterationStats& s) -> std::vector<double> {
                          return {double(s.ppo.iteration), double(s.ppo.global_step), double(s.ppo.episodes),
                                  s.ppo.success_rate, s.ppo.episode_length, s.airl_reward, s.disc_loss,
                                  s.expert_accuracy, s.generator_accuracy, s.ppo.policy_loss, s.ppo.value_loss,
                                  s.ppo.approx_kl, trainer.ppo().wall_seconds()};
                        });
  if (!stop && o.group->leader()) export_artefact(trainer.policy(), r, t, dir, "policy.pt");
  if (!stop) o.group->leader_done("export of pi_ab");
  return stop;
}

// Lee et al. 2019. "success" in its log: hand-overs after which pi_b succeeded.
int train_lee(const CompositeRecipe& r, int t, const StartStates& starts, const std::string& dir,
              const PipelineOptions& o) {
  const TransitionPolicyConfig cfg = r.pipeline.lee.transition(r.pipeline.transition);
  const Skill& b = r.skills[r.meta.transitions()[t].to];
  const int subtask_steps = r.pipeline.switching.max_subtask_steps;
  const Shard share = o.group->shard(cfg.ppo.num_envs, "transition.ppo.num_envs");
  VectorEnv envs([&] { return std::make_unique<LeeTransitionEnv>(r.make_env, r.skills, r.meta, t, starts, r.pipeline.lee.max_steps, subtask_steps); }, share.count,
                 o.threads, share.first);
  LeeTrainer trainer(cfg, r.pipeline.lee, envs, demonstrations_of(r, t, dir), b.policy,
                     mix_seed(r.pipeline.seed, 300 + t), *o.group);
  const std::string ckpt = dir + "/lee_checkpoint.pt";
  resume(trainer, ckpt, *o.group);
  int stop = train_loop(trainer, r, cfg.ppo.total_steps, r.transition_name(t) + " Lee", ckpt, dir + "/lee.csv",
                        {"iteration", "global_step", "episodes", "handover_success", "episode_length", "predictor_loss",
                         "policy_loss", "value_loss", "approx_kl", "wall_seconds"},
                        o,
                        [&](const LeeTrainer::Stats& s) -> std::vector<double> {
                          return {double(s.ppo.iteration), double(s.ppo.global_step), double(s.ppo.episodes),
                                  s.handover_success, s.ppo.episode_length, s.predictor_loss, s.ppo.policy_loss,
                                  s.ppo.value_loss, s.ppo.approx_kl, trainer.ppo().wall_seconds()};
                        });
  if (!stop && o.group->leader()) export_artefact(trainer.policy(), r, t, dir, "lee.pt");
  if (!stop) o.group->leader_done("export of Lee's policy");
  return stop;
}

// Reports and checkpoints every tenth of the attempts (at most 100), so that a stopped
// stage resumes where it was; the checkpoint goes once q.pt is written. Returns the
// signal number when stopped, else 0.
// With several ranks the attempts are split between them (SwitchTrainer); rank 0 writes
// and chooses the margin while the others wait.
int train_switch(const CompositeRecipe& r, int t, const StartStates& starts, const std::string& run,
                 const std::string& dir, const std::atomic<int>* stop, const Distributed& group, JobPlan& plan) {
  const SwitchConfig& cfg = r.pipeline.switching;
  SwitchTrainer trainer(cfg,
                        SwitchInterval(r.make_env, r.skills, r.meta, t, starts,
                                       Policy::load(dir + "/policy.pt"),
                                       load_transition_artefacts(r, run, "policy.pt", /*with_q=*/false),
                                       cfg.lookahead, cfg.max_subtask_steps),
                        mix_seed(r.pipeline.seed, 200 + t), group);
  const std::string ckpt = dir + "/switch_checkpoint.pt";
  const int chunk = std::clamp(cfg.attempts / 10, 1, 100);
  if (group.any(group.leader() && exists(ckpt))) {
    trainer.load(ckpt);
    spdlog::info("  resuming from attempt {}", trainer.attempts_done());
  }
  const double resumed_at = double(trainer.attempts_done()) / cfg.attempts;
  std::optional<MetricsCsv> csv;
  if (group.leader())
    csv.emplace(dir + "/switch.csv",
                std::vector<std::string>{"attempts", "epsilon", "subtask_success", "switch_step", "loss", "env_steps",
                                         "wall_seconds", "replay_rows", "rank0_rows"},
                (trainer.attempts_done() + chunk - 1) / chunk);
  while (trainer.attempts_done() < cfg.attempts) {
    SwitchStats s = trainer.run(std::min(chunk, cfg.attempts - trainer.attempts_done()));
    if (csv)
      csv->write({double(trainer.attempts_done()), s.epsilon, s.success_rate, s.switch_step, s.loss,
                  double(trainer.env_steps()), trainer.wall_seconds(), double(s.replay_rows), double(s.rank0_rows)});
    plan.report(double(trainer.attempts_done()) / cfg.attempts, resumed_at, NAN);
    spdlog::info("  q_ab: {}/{} attempts, epsilon {:.2f}, pi_b succeeded in {:.0f}%, switch at step {:.1f}  job ETA ~{}",
                 trainer.attempts_done(), cfg.attempts, s.epsilon, 100 * s.success_rate, s.switch_step,
                 format_duration(plan.eta_seconds()));
    trainer.save(ckpt);
    const int sig = agreed_stop(group, stop);
    if (sig && trainer.attempts_done() < cfg.attempts) return sig;
  }
  if (!group.leader()) {
    group.leader_done("the switch's margin");
    return 0;
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
  group.leader_done("the switch's margin");
  return 0;
}

// Fig. 4's data: from the same S_a states, each of pi_a, pi_ab and pi_b drives through
// the interval; every action is a row "label,a0,...".
void write_actions(const CompositeRecipe& r, int t, const StartStates& starts, const std::string& dir,
                   int starts_used = 40) {
  const Transition& tr = r.meta.transitions()[t];
  const Skill& a = r.skills[tr.from];
  const Skill& b = r.skills[tr.to];
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

// The job's cost model: seconds per unit of each part on the 2-core VM the main job was
// measured on (tools/main_job.sh, experiments/hurdle.yaml; README, "Set-up"). Elsewhere,
// and for other tasks, the parts' own times here rescale it (JobPlan).
struct Costs {
  double start_state = 0.27;           // S_a: per state (the walk to the interval: 0.12 s first, 0.43 s second)
  double demonstration_step = 0.0017;  // T_b: per step of pi_b kept
  double airl_step = 0.00036;          // pi_ab: per PPO step, D included
  double switch_attempt = 0.09;        // q_ab: per attempt, the margin's check included
  double lee_step = 0.0015;            // Lee et al.: per PPO step, pi_b's run after each hand-over included
  double eval_episode = 0.5;           // per episode of a method
};

// Every part of the run, in the order the stages run them.
void plan_job(const CompositeRecipe& r, JobPlan& plan) {
  const Costs c;
  const int n = int(r.meta.transitions().size());
  const PipelineConfig& p = r.pipeline;
  for (int t = 0; t < n; ++t) {
    plan.add(r.transition_name(t) + " S_a", c.start_state * r.start_state_count(t));
    plan.add(r.transition_name(t) + " T_b", c.demonstration_step * p.collect.demonstrations);
    plan.add(r.transition_name(t) + " pi_ab", c.airl_step * double(p.transition.ppo.total_steps));
  }
  for (int t = 0; t < n; ++t) plan.add(r.transition_name(t) + " q_ab", c.switch_attempt * p.switching.attempts);
  for (int t = 0; t < n && p.lee.enabled; ++t)
    plan.add(r.transition_name(t) + " Lee", c.lee_step * double(p.lee.transition(p.transition).ppo.total_steps));
  const int runs = int(method_names().size() * r.eval_seeds.size());
  plan.add("evaluate", c.eval_episode * runs * r.eval_episodes, runs);
}

}  // namespace

int run_pipeline(const CompositeRecipe& recipe, const PipelineOptions& o) {
  const std::string run = recipe.pipeline.run_dir;
  const Distributed& group = *o.group;
  if (group.leader()) RunDir(run, recipe.resolved, recipe.defaulted);
  group.leader_done("the run directory");
  const int n = int(recipe.meta.transitions().size());
  const bool lee = recipe.pipeline.lee.enabled;
  const int stages = (lee ? 4 : 3) * n + 1;
  JobPlan plan;
  plan_job(recipe, plan);
  int stage = 0;
  auto announce = [&](const std::string& what) {
    spdlog::info("[stage {}/{}] {}  (job: {})", ++stage, stages, what, plan.summary());
  };
  // Runs a training stage (the plan's `part`) unless its output exists; the signal number if it was stopped.
  auto stage_unless_done = [&](const std::string& part, const std::string& output, const std::function<int()>& train) {
    if (group.any(group.leader() && exists(output))) {
      spdlog::info("  done already: {}", output);
      plan.skip(part);
      return 0;
    }
    plan.begin(part);
    int stop = train();
    if (stop) spdlog::warn("interrupted: rerun the same command to resume from the stage's last checkpoint");
    return stop;
  };
  auto tdir = [&](int t) { return run + "/" + recipe.transition_name(t); };
  // Each transition's S_a, read from its folder once, after its collection.
  std::vector<std::optional<StartStates>> s_a(static_cast<size_t>(n));
  auto starts = [&](int t) -> const StartStates& {
    if (!s_a[t]) s_a[t] = starts_of(recipe, t, tdir(t));
    return *s_a[t];
  };
  // Every pi_ab first: S_a of a later transition is collected With TP through the earlier
  // ones, and switch training may carry episodes on through any of them (lookahead).
  for (int t = 0; t < n; ++t) {
    if (group.leader()) fs::create_directories(tdir(t));
    group.leader_done("the transition's folder");
    announce(recipe.transition_name(t) + ": collect S_a and T_b");
    if (int stop = collect(recipe, t, run, tdir(t), [&]() -> const StartStates& { return starts(t); }, o.stop, group,
                           o.threads, plan)) {
      spdlog::warn("interrupted: rerun the same command to resume (this collection starts over)");
      return stop;
    }
    announce(recipe.transition_name(t) + ": transition policy (AIRL, Algorithm 1)");
    if (int stop = stage_unless_done(recipe.transition_name(t) + " pi_ab", tdir(t) + "/policy.pt",
                                     [&] { return train_transition(recipe, t, starts(t), tdir(t), o); }))
      return stop;
  }
  for (int t = 0; t < n; ++t) {
    announce(recipe.transition_name(t) + ": switch Q-network (double DQN, Algorithm 2)");
    if (int stop = stage_unless_done(recipe.transition_name(t) + " q_ab", tdir(t) + "/q.pt",
                                     [&] { return train_switch(recipe, t, starts(t), run, tdir(t), o.stop, group, plan); }))
      return stop;
  }
  for (int t = 0; t < n && lee; ++t) {
    announce(recipe.transition_name(t) + ": Lee et al. 2019 baseline (proximity reward, termination head)");
    if (int stop = stage_unless_done(recipe.transition_name(t) + " Lee", tdir(t) + "/lee.pt",
                                     [&] { return train_lee(recipe, t, starts(t), tdir(t), o); }))
      return stop;
  }
  if (!group.leader()) return 0;  // rank 0 evaluates
  announce("evaluate every method");
  plan.begin("evaluate");
  for (int t = 0; t < n; ++t)
    if (!exists(tdir(t) + "/actions.csv")) write_actions(recipe, t, starts(t), tdir(t));
  const std::string table = run + "/" + recipe.task + ".json";
  if (exists(table)) {
    spdlog::info("  done already: {} (remove it to measure again)", table);
    plan.end();
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
  plan.end();
  spdlog::info("job done: {} in this run", format_duration(plan.elapsed_seconds()));
  return 0;
}

}  // namespace segue
