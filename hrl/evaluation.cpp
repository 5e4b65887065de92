#include "hrl/evaluation.h"

#include <optional>

#include "core/progress.h"

#include <algorithm>
#include <cmath>

#include "core/rng.h"
#include "core/thread_pool.h"

namespace segue {

Summary summarize(const std::vector<double>& xs) {
  Summary s;
  if (xs.empty()) return s;
  for (double x : xs) s.mean += x;
  s.mean /= xs.size();
  for (double x : xs) s.std += (x - s.mean) * (x - s.mean);
  s.std = std::sqrt(s.std / xs.size());
  return s;
}

namespace {

// Environments stepped side by side for `jobs` episodes; controllers are kept per slot.
int slot_count(int jobs) { return std::max(1, std::min(jobs, 32)); }

// The episode loop: job j starts from seed seed_of(j) and is played by the controller
// controller_for(slot, j) returns, slot < slot_count(jobs).
EvalResult run_jobs(const EnvFactory& make_env, int jobs, const std::function<uint64_t(int)>& seed_of,
                    const std::function<Controller&(int slot, int job)>& controller_for, int threads,
                    const std::string& label = "") {
  const int slots = slot_count(jobs);
  std::vector<std::unique_ptr<Env>> envs;
  for (int i = 0; i < slots; ++i) envs.push_back(make_env());
  const EnvSpec& spec = envs[0]->spec();
  const int D = spec.obs_dim, A = spec.act_dim, K = static_cast<int>(spec.metric_names.size());

  EvalResult r;
  r.returns.assign(jobs, 0.0);
  r.success_counts.assign(jobs, 0.0);
  r.lengths.assign(jobs, 0.0);
  r.successes.assign(jobs, 0);
  r.terminated.assign(jobs, 0);
  r.ended_under.assign(jobs, "");
  r.metric_names = spec.metric_names;
  r.metric_means.assign(K, std::vector<double>(jobs, 0.0));

  std::vector<float> obs(size_t(slots) * D), act(size_t(slots) * A);
  std::vector<int> job_of(slots, -1);  // -1 idle, -2 just finished
  std::vector<int> done_job(slots, -1);  // the job a slot just finished
  std::vector<Controller*> controller(slots, nullptr);
  int next = 0;
  auto start = [&](int s) {
    job_of[s] = next < jobs ? next++ : -1;
    if (job_of[s] < 0) return;
    controller[s] = &controller_for(s, job_of[s]);
    envs[s]->reset(seed_of(job_of[s]), &obs[size_t(s) * D]);
    controller[s]->reset(*envs[s], &obs[size_t(s) * D], seed_of(job_of[s]));
  };
  for (int s = 0; s < slots; ++s) start(s);
  std::optional<Progress> progress;
  if (!label.empty()) progress.emplace(label, jobs, 0, "episode");
  int finished = 0;
  double return_sum = 0, success_sum = 0;

  ThreadPool pool(threads);
  std::function<void(int, int)> step_block = [&](int begin, int end) {
    for (int s = begin; s < end; ++s) {
      int e = job_of[s];
      if (e < 0) continue;
      float* o = &obs[size_t(s) * D];
      float* a = &act[size_t(s) * A];
      controller[s]->act(*envs[s], o, a);
      StepResult sr = envs[s]->step(a, o);
      r.returns[e] += sr.reward;
      r.lengths[e] += 1;
      for (int k = 0; k < K; ++k) r.metric_means[k][e] += sr.info.metrics[k];
      if (sr.done()) {
        r.successes[e] = sr.info.success;
        r.terminated[e] = sr.terminated;
        r.ended_under[e] = controller[s]->in_control();
        r.success_counts[e] = sr.info.success_count;
        for (int k = 0; k < K; ++k) r.metric_means[k][e] /= r.lengths[e];
        job_of[s] = -2, done_job[s] = e;
      }
    }
  };
  for (;;) {
    bool any = false;
    for (int s = 0; s < slots; ++s) any |= job_of[s] >= 0;
    if (!any) break;
    pool.parallel_for(slots, step_block);
    for (int s = 0; s < slots; ++s)
      if (job_of[s] == -2) {
        const int e = done_job[s];
        ++finished, return_sum += r.returns[e], success_sum += r.successes[e];
        if (progress) progress->update(finished, return_sum / finished, success_sum / finished);
        start(s);
      }
  }
  if (progress) progress->finish();
  return r;
}

}  // namespace

double EvalResult::success_rate() const {
  return successes.empty() ? 0.0 : double(std::count(successes.begin(), successes.end(), 1)) / successes.size();
}

void EvalResult::append(const EvalResult& more) {
  auto add = [](auto& to, const auto& from) { to.insert(to.end(), from.begin(), from.end()); };
  add(returns, more.returns), add(success_counts, more.success_counts), add(lengths, more.lengths);
  add(successes, more.successes), add(terminated, more.terminated), add(ended_under, more.ended_under);
  if (metric_names.empty()) metric_names = more.metric_names, metric_means.resize(more.metric_means.size());
  for (size_t k = 0; k < metric_means.size() && k < more.metric_means.size(); ++k) add(metric_means[k], more.metric_means[k]);
}

EvalResult evaluate(const EnvFactory& make_env, const ControllerFactory& make_controller, int episodes,
                    uint64_t seed, int threads, const std::string& progress) {
  std::vector<std::unique_ptr<Controller>> controllers;
  for (int i = 0; i < slot_count(episodes); ++i)
    controllers.push_back(make_controller());
  return run_jobs(
      make_env, episodes, [seed](int e) { return mix_seed(seed, e); },
      [&](int slot, int) -> Controller& { return *controllers[slot]; }, threads, progress);
}

EvalResult evaluate_policy(const Policy& policy, const EnvFactory& make_env, int episodes, uint64_t seed,
                           int threads, const std::string& progress) {
  return evaluate(make_env, [&] { return std::make_unique<PolicyController>(policy); }, episodes, seed, threads,
                  progress);
}

}  // namespace segue
