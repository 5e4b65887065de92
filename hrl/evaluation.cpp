#include "hrl/evaluation.h"

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

EvalResult evaluate(const EnvFactory& make_env, const ControllerFactory& make_controller, int episodes,
                    uint64_t seed, int threads) {
  const int slots = std::max(1, std::min(episodes, 32));
  std::vector<std::unique_ptr<Env>> envs;
  std::vector<std::unique_ptr<Controller>> controllers;
  for (int i = 0; i < slots; ++i) {
    envs.push_back(make_env());
    controllers.push_back(make_controller());
  }
  const EnvSpec& spec = envs[0]->spec();
  const int D = spec.obs_dim, A = spec.act_dim, K = static_cast<int>(spec.metric_names.size());

  EvalResult r;
  r.returns.assign(episodes, 0.0);
  r.success_counts.assign(episodes, 0.0);
  r.lengths.assign(episodes, 0.0);
  r.successes.assign(episodes, 0);
  r.metric_names = spec.metric_names;
  r.metric_means.assign(K, std::vector<double>(episodes, 0.0));

  std::vector<float> obs(size_t(slots) * D), act(size_t(slots) * A);
  std::vector<int> episode_of(slots, -1);  // -1 idle, -2 just finished
  int next = 0;
  auto start = [&](int s) {
    episode_of[s] = next < episodes ? next++ : -1;
    if (episode_of[s] < 0) return;
    envs[s]->reset(mix_seed(seed, episode_of[s]), &obs[size_t(s) * D]);
    controllers[s]->reset(*envs[s], &obs[size_t(s) * D]);
  };
  for (int s = 0; s < slots; ++s) start(s);

  ThreadPool pool(threads);
  std::function<void(int, int)> step_block = [&](int begin, int end) {
    for (int s = begin; s < end; ++s) {
      int e = episode_of[s];
      if (e < 0) continue;
      float* o = &obs[size_t(s) * D];
      float* a = &act[size_t(s) * A];
      controllers[s]->act(*envs[s], o, a);
      StepResult sr = envs[s]->step(a, o);
      r.returns[e] += sr.reward;
      r.lengths[e] += 1;
      for (int k = 0; k < K; ++k) r.metric_means[k][e] += sr.info.metrics[k];
      if (sr.done()) {
        r.successes[e] = sr.info.success;
        r.success_counts[e] = sr.info.success_count;
        for (int k = 0; k < K; ++k) r.metric_means[k][e] /= r.lengths[e];
        episode_of[s] = -2;
      }
    }
  };
  for (;;) {
    bool any = false;
    for (int s = 0; s < slots; ++s) any |= episode_of[s] >= 0;
    if (!any) break;
    pool.parallel_for(slots, step_block);
    for (int s = 0; s < slots; ++s)
      if (episode_of[s] == -2) start(s);
  }
  return r;
}

EvalResult evaluate_policy(const Policy& policy, const EnvFactory& make_env, int episodes, uint64_t seed,
                           int threads) {
  return evaluate(make_env, [&] { return std::make_unique<PolicyController>(policy); }, episodes, seed, threads);
}

}  // namespace segue
