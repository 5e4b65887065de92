#include "algorithms/evaluate.h"

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

EvalResult evaluate_policy(const Policy& policy, const std::function<std::unique_ptr<Env>()>& make,
                           int episodes, uint64_t seed, int threads) {
  const int slots = std::max(1, std::min(episodes, 32));
  std::vector<std::unique_ptr<Env>> envs;
  for (int i = 0; i < slots; ++i) envs.push_back(make());
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
  std::vector<int> episode_of(slots, -1);
  int next = 0;
  auto start = [&](int s) {
    if (next >= episodes) {
      episode_of[s] = -1;
      return;
    }
    episode_of[s] = next;
    envs[s]->reset(mix_seed(seed, next), &obs[size_t(s) * D]);
    ++next;
  };
  for (int s = 0; s < slots; ++s) start(s);

  ThreadPool pool(threads);
  auto step_block = [&](int begin, int end) {
    for (int s = begin; s < end; ++s) {
      int e = episode_of[s];
      if (e < 0) continue;
      StepResult sr = envs[s]->step(&act[size_t(s) * A], &obs[size_t(s) * D]);
      r.returns[e] += sr.reward;
      r.lengths[e] += 1;
      for (int k = 0; k < K; ++k) r.metric_means[k][e] += sr.info.metrics[k];
      if (sr.done()) {
        r.successes[e] = sr.info.success;
        r.success_counts[e] = sr.info.success_count;
        for (int k = 0; k < K; ++k) r.metric_means[k][e] /= r.lengths[e];
        episode_of[s] = -2;  // finished; a new episode is started outside the parallel loop
      }
    }
  };
  for (;;) {
    bool any = false;
    for (int s = 0; s < slots; ++s) any |= episode_of[s] >= 0;
    if (!any) break;
    policy.act(obs.data(), slots, act.data());
    pool.parallel_for(slots, step_block);
    for (int s = 0; s < slots; ++s)
      if (episode_of[s] == -2) start(s);
  }
  return r;
}

}  // namespace segue
