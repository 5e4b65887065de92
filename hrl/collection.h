#pragma once
// Algorithm 1, lines 3-4: the data a transition policy pi_ab is trained from.
//   S_a: full simulator states of pi_a at the start of the transition interval, so a
//        training episode can start exactly there. Collected at the step where the
//        meta-controller enters the interval a->b, in episodes that join the skills with
//        the transition policies trained so far (Without TP where there are none): a
//        later interval is only reached as often as the earlier transitions succeed.
//   T_b: pi_b's own (s, a, s') inside its interval: episodes that pi_b runs from the start,
//        recorded while the transition's `expert.when` holds (with `expert.successful`,
//        only windows after which pi_b succeeds, so T_b may overshoot its count by part of
//        a window). Observations are in pi_b's slice of the task observation. With
//        `expert.after_handover`, episodes start instead at S_a's states, one each, and
//        T_b is as large as they give (at most `count`).
// Both are collected in the transition's training env (its `training.env`; by default the
// task as evaluated), e.g. with the sub-tasks' random pushes as the reference collects them.
// Both are stored as tensors in a .pt file (torch.load-able) that later stages read back,
// with the task and transition they were collected for (`source`), so a file copied into
// another transition's folder is refused rather than trained on.
#include <algorithm>
#include <atomic>
#include <string>
#include <vector>

#include "hrl/composite_recipe.h"

namespace segue {

struct StartStates {
  std::string source;          // CompositeRecipe::transition_source; empty in older files
  int state_dim = 0, obs_dim = 0;
  std::vector<double> states;  // [N, state_dim], Env::save_state snapshots
  std::vector<float> obs;      // [N, obs_dim], the task observation there
  int size() const { return state_dim ? int(states.size() / state_dim) : 0; }
  // Copies snapshot i into `out` (resized), ready for Env::restore_state.
  void state(int i, std::vector<double>& out) const {
    out.assign(states.begin() + size_t(i) * state_dim, states.begin() + size_t(i + 1) * state_dim);
  }
  void append(const StartStates& o) {
    states.insert(states.end(), o.states.begin(), o.states.end());
    obs.insert(obs.end(), o.obs.begin(), o.obs.end());
  }
  // Keeps the first n states (all if there are fewer).
  void keep_first(int n) {
    n = std::max(0, std::min(n, size()));
    states.resize(size_t(n) * state_dim), obs.resize(size_t(n) * obs_dim);
  }
};

struct Demonstrations {
  std::string source;                     // as StartStates::source
  int obs_dim = 0, act_dim = 0;
  std::vector<float> obs, act, next_obs;  // [M, obs_dim], [M, act_dim], [M, obs_dim]
  std::vector<uint8_t> done;              // 1 where the episode truly ended
  int size() const { return obs_dim ? int(obs.size() / obs_dim) : 0; }
  void clear() { obs.clear(), act.clear(), next_obs.clear(), done.clear(); }
  // Keeps the first n rows (all if there are fewer).
  void keep_first(int n) {
    n = std::max(0, std::min(n, size()));
    obs.resize(size_t(n) * obs_dim), act.resize(size_t(n) * act_dim), next_obs.resize(size_t(n) * obs_dim);
    done.resize(size_t(n));
  }
  void append(const Demonstrations& d) {
    obs.insert(obs.end(), d.obs.begin(), d.obs.end());
    act.insert(act.end(), d.act.begin(), d.act.end());
    next_obs.insert(next_obs.end(), d.next_obs.begin(), d.next_obs.end());
    done.insert(done.end(), d.done.begin(), d.done.end());
  }
};

// Runs seeded episodes (episode i from mix_seed(seed, i)) until `count` items are found;
// throws segue::Error if `max_episodes` pass without enough, or as soon as
// kEmptyEpisodes pass without a single one (a window the episodes never reach: say so
// at once rather than after max_episodes).
// `trained`: per transition of the recipe, its pi_ab and q_ab where already trained (or
// empty). Episodes use q_ab where there is one, else switch at the interval's end.
// `stop` (a signal's flag): when set, both return at the next episode with what they have.
// `threads` run episodes side by side; the result is the one-thread loop's.
constexpr int kStartStateEpisodes = 20000, kDemonstrationEpisodes = 100000;  // default max_episodes
constexpr int kEmptyEpisodes = 1000;
StartStates collect_start_states(const CompositeRecipe& recipe, int transition, int count, uint64_t seed,
                                 const std::vector<TransitionArtefacts>& trained = {},
                                 int max_episodes = kStartStateEpisodes, const std::atomic<int>* stop = nullptr,
                                 int threads = 1);
// `handovers`: S_a's training states, required with expert.after_handover.
Demonstrations collect_demonstrations(const CompositeRecipe& recipe, int transition, int count, uint64_t seed,
                                      int max_episodes = kDemonstrationEpisodes, const std::atomic<int>* stop = nullptr,
                                      const StartStates* handovers = nullptr, int threads = 1);

void save(const StartStates& s, const std::string& path);
void save(const Demonstrations& d, const std::string& path);
StartStates load_start_states(const std::string& path);
Demonstrations load_demonstrations(const std::string& path);

}  // namespace segue
