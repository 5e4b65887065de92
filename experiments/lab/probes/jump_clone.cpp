// Developer probe (not part of `segue`): search, then clone (expert iteration). The jump's
// failure is a gait blind to the curb (experiments/results/NOTES.md, Jump, stage 11); exploration noise from a
// failing approach clears ~1% of the time, too rarely for PPO to learn from. Here search
// pays that price on purpose: each round, for each of N episodes, the policy runs
// deterministically until the curb's start is D m ahead; if it then fails, up to K
// continuations are tried (action noise of std SIGMA held HOLD steps; with SIGMA <= 0,
// pauses of 1..K steps, see `run`), and the first that clears is kept. The cleared
// episodes (nominal or searched), from reset to their end, are cloned into the policy's
// mean by regression (the normaliser stays), and the result is scored deterministically
// on 100 held-out episodes and written to OUT_r<round>.pt.
// Build: cmake --build build --target probe_jump_clone
// usage: build/probe_jump_clone POLICY OUT N SEED D K SIGMA HOLD ROUNDS EPOCHS LR [key=value ...]
#include <torch/torch.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "algorithms/policy.h"
#include "environments/walker_obstacles.h"
#include "experiments/lab/probes/jump_env.h"

using namespace segue;

namespace {

struct Demos {
  std::vector<float> obs, act;
  void add(const std::vector<float>& o, const std::vector<float>& a) {
    obs.insert(obs.end(), o.begin(), o.end());
    act.insert(act.end(), a.begin(), a.end());
  }
  void append(const Demos& d) {
    obs.insert(obs.end(), d.obs.begin(), d.obs.end());
    act.insert(act.end(), d.act.begin(), d.act.end());
  }
};

// Least squares of the policy's (clamped) mean on the demonstrated actions, from its current
// weights.
Policy clone(const Policy& pi, const Demos& d, int epochs, double lr, uint64_t seed) {
  torch::manual_seed(seed);
  const int in_dim = pi.in_dim(), act_dim = pi.act_dim();
  const int64_t n = int64_t(d.act.size()) / act_dim;
  std::vector<float> x(size_t(n) * in_dim);
  pi.normalize(d.obs.data(), int(n), x.data());
  const torch::Tensor X = torch::from_blob(x.data(), {n, in_dim}).clone();
  const torch::Tensor Y = torch::from_blob(const_cast<float*>(d.act.data()), {n, act_dim}).clone();
  std::vector<torch::Tensor> ws, bs;
  for (size_t i = 0; i < pi.mlp().weights().size(); ++i) {
    const auto& w = pi.mlp().weights()[i];
    const auto& b = pi.mlp().biases()[i];
    ws.push_back(
        torch::from_blob(const_cast<float*>(w.data()), {w.rows(), w.cols()}).clone().requires_grad_());
    bs.push_back(torch::from_blob(const_cast<float*>(b.data()), {b.size()}).clone().requires_grad_());
  }
  const Activation activation = pi.mlp().activation();
  auto mean = [&](torch::Tensor h) {
    for (size_t i = 0; i < ws.size(); ++i) {
      h = torch::addmm(bs[i], h, ws[i].t());
      if (i + 1 < ws.size()) h = activation == Activation::Tanh ? torch::tanh(h) : torch::relu(h);
    }
    return h;
  };
  std::vector<torch::Tensor> params = ws;
  params.insert(params.end(), bs.begin(), bs.end());
  torch::optim::Adam adam(params, torch::optim::AdamOptions(lr));
  const int64_t batch = 256;
  for (int e = 0; e < epochs; ++e) {
    const torch::Tensor order = torch::randperm(n, torch::kLong);
    double sum = 0;
    for (int64_t b = 0; b + batch <= n; b += batch) {
      const torch::Tensor idx = order.slice(0, b, b + batch);
      // The env sees the mean clamped to the walker's bounds [-1, 1]; so does the loss, else
      // a saturated output would be pulled back inside and the gait would drift.
      const torch::Tensor fit = mean(X.index_select(0, idx)).clamp(-1, 1);
      const torch::Tensor loss = (fit - Y.index_select(0, idx)).pow(2).mean();
      adam.zero_grad();
      loss.backward();
      adam.step();
      sum += loss.item<double>() * batch;
    }
    if (e == 0 || e + 1 == epochs) std::printf("  clone epoch %d: mse %.4f\n", e + 1, sum / n);
  }
  return pi.with_parameters(EigenMlp(ws, bs, activation).parameters());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 12) {
    std::fprintf(stderr, "usage: %s POLICY OUT N SEED D K SIGMA HOLD ROUNDS EPOCHS LR [key=value ...]\n",
                 argv[0]);
    return 2;
  }
  at::set_num_threads(1);
  const std::unique_ptr<Env> env = jump_env_from_args(12, argc, argv);
  const auto& task = dynamic_cast<const WalkerJump&>(*env);
  Policy pi = Policy::load(argv[1]);
  const std::string out = argv[2];
  const int n = std::atoi(argv[3]), k = std::atoi(argv[6]), hold = std::atoi(argv[8]);
  const int rounds = std::atoi(argv[9]), epochs = std::atoi(argv[10]);
  const uint64_t seed = std::strtoull(argv[4], nullptr, 10);
  const double dist = std::atof(argv[5]), sigma = std::atof(argv[7]), lr = std::atof(argv[11]);
  const int obs_dim = env->spec().obs_dim, act_dim = env->spec().act_dim;
  std::vector<float> obs(obs_dim), act(act_dim), noise(act_dim);
  std::vector<double> state;
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> normal(0.f, sigma > 0 ? float(sigma) : 1.f);  // unused for pauses

  // Runs pi from the current state to the episode's end, appending what it saw and did.
  // Continuation `branch` > 0 perturbs it: with SIGMA > 0 by held noise; with SIGMA <= 0 it
  // holds pi's first action for `branch` steps (a pause that shifts the gait's phase, tried
  // from the shortest, so the demonstrated pause is a function of the state).
  auto run = [&](const Policy& p, int branch, Demos* d) {
    for (int t = 0;; ++t) {
      if (branch == 0 || sigma > 0 || t == 0 || t > branch) p.act(obs.data(), 1, act.data());
      if (branch > 0 && sigma > 0) {
        if (t % hold == 0)
          for (auto& z : noise) z = normal(rng);
        for (int i = 0; i < act_dim; ++i) act[i] = std::clamp(act[i] + noise[i], -1.f, 1.f);
      }
      if (d) d->add(obs, act);
      StepResult r = env->step(act.data(), obs.data());
      if (r.done()) return r.info.success;
    }
  };
  // Deterministic success on 100 held-out episodes, and on those whose curb starts in the
  // band stage 3's jump never clears (6.75-7.5 m).
  auto score = [&](const Policy& p) {
    int wins = 0, band = 0, band_wins = 0;
    for (int e = 0; e < 100; ++e) {
      env->reset(900000 + e, obs.data());
      const double c = task.obstacles()[0].start;
      const bool ok = run(p, 0, nullptr);
      wins += ok;
      if (c >= 6.75 && c < 7.5) band += 1, band_wins += ok;
    }
    std::printf("  held-out: %d of 100 clear; band %d of %d\n", wins, band_wins, band);
  };
  score(pi);
  for (int round = 0; round < rounds; ++round) {
    Demos all;
    int nominal = 0, searched = 0, tries = 0;
    for (int e = 0; e < n; ++e) {
      Demos prefix;
      env->reset(seed + uint64_t(round) * n + e, obs.data());
      bool ended = false;
      while (obs[obs_dim - 2] > dist && !ended) {  // (start - x, end - x) close the observation
        pi.act(obs.data(), 1, act.data());
        prefix.add(obs, act);
        ended = env->step(act.data(), obs.data()).done();
      }
      if (ended) continue;
      env->save_state(state);
      Demos rest;
      if (run(pi, 0, &rest)) {
        ++nominal;
      } else {
        bool found = false;
        for (int b = 0; b < k && !found; ++b, ++tries) {
          rest = Demos{};
          env->restore_state(state, obs.data());
          found = run(pi, b + 1, &rest);
        }
        if (!found) continue;
        ++searched;
      }
      all.append(prefix);
      all.append(rest);
    }
    std::printf("round %d: %d episodes; nominal clears %d, search clears %d more (%d tries); %zu samples\n",
                round, n, nominal, searched, tries, all.act.size() / act_dim);
    std::fflush(stdout);
    pi = clone(pi, all, epochs, lr, seed + round);
    score(pi);
    pi.export_torchscript(out + "_r" + std::to_string(round) + ".pt");
    std::fflush(stdout);
  }
}
