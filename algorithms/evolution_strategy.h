#pragma once
// Evolution strategies in parameter space (Salimans et al. 2017, "Evolution Strategies as
// a Scalable Alternative to Reinforcement Learning"), used here to fine-tune a trained
// policy on the very number it is judged by: deterministic success over seeded episodes.
//
// Each generation draws `pairs` Gaussian directions eps_i and scores theta + sigma eps_i
// and theta - sigma eps_i on the same episode seeds (common random numbers: a pair's
// difference is the direction's effect, not the luck of the curb's placement). Fitness
// is shaped to centred ranks u in [-0.5, 0.5], and the search gradient
//   g = 1 / (2 pairs sigma) sum_i (u_i+ - u_i-) eps_i
// estimates the gradient of E_eps F(theta + sigma eps); theta climbs it with Adam.
//
// Why a second learner: PPO explores with noise drawn afresh each step, which averages
// out over a stance, so it never tries a hop that is longer or shorter as a whole (the
// jump's failure: docs/history.md, the jump). A perturbed parameter vector changes the policy for a
// whole episode, so the comparison within a pair is between two gaits.
#include <cstdint>
#include <string>
#include <vector>

#include "algorithms/policy.h"
#include "core/recipe.h"

namespace segue {

struct EsConfig {
  int generations = 100;
  int pairs = 32;       // population 2 * pairs
  int episodes = 16;    // per candidate, on the generation's common seeds
  double sigma = 0.02;  // perturbation scale, in parameter units
  double lr = 0.01;     // Adam step size
  // Search only the first layer's weights from these network inputs [begin, end),
  // e.g. the jump's obstacle pair: the gait stays, and how it depends on the curb's
  // distance is what moves. Empty: every parameter.
  std::vector<int> inputs;
  // What a candidate scores: "success" (the fraction of its episodes that succeed: the
  // number the skill is judged by) or "return" (the mean episode return: graded, so a
  // near miss scores above a far one when the task's reward says so).
  std::string fitness = "success";
  static EsConfig read(const Section& s);
};

// Centred ranks: the lowest fitness maps to -0.5, the highest to +0.5, evenly spaced in
// between; ties share the mean of their ranks. Invariant to any increasing transform of
// the fitness, so a rare large score cannot dominate a generation.
std::vector<double> centred_ranks(const std::vector<double>& fitness);

// The parameters a run searches: all of a policy's network, or only the first layer's
// weights from network inputs [inputs[0], inputs[1]); the rest stay as trained.
class SearchedParameters {
 public:
  // Throws segue::Error when `inputs` lies outside the network's inputs (the
  // observation, then any periodic features).
  SearchedParameters(Policy start, const std::vector<int>& inputs);
  std::vector<float> initial() const;                // the start policy's values
  Policy policy_at(const std::vector<float>& theta) const;
  size_t size() const { return index_.size(); }

 private:
  Policy start_;
  std::vector<float> full_;     // every parameter of the start policy
  std::vector<size_t> index_;   // where the searched ones sit in full_
};

class EvolutionStrategy {
 public:
  EvolutionStrategy(const EsConfig& config, std::vector<float> theta, uint64_t seed);

  // The generation's candidates: theta + sigma eps_i at 2i, theta - sigma eps_i at 2i + 1.
  // The directions depend only on (seed, generation), so a resumed run draws the same.
  std::vector<std::vector<float>> ask();
  // The fitness of each candidate from ask(), same order; one Adam step on theta.
  // Returns the search gradient's norm.
  double tell(const std::vector<double>& fitness);

  const std::vector<float>& theta() const { return theta_; }
  int generation() const { return generation_; }
  // The seed the generation's episodes start from (fresh each generation, so the
  // policy is not fitted to a fixed set of curbs).
  uint64_t episode_seed() const;

  // theta, Adam's moments and the generation, written atomically, with `note` (the
  // resolved recipe) and `counters` (the caller's: steps, wall time) in the same file.
  // load() refuses a checkpoint of another size and returns the counters.
  void save(const std::string& path, const std::string& note = "", const std::vector<int64_t>& counters = {}) const;
  std::vector<int64_t> load(const std::string& path);

 private:
  EsConfig cfg_;
  std::vector<float> theta_;
  std::vector<double> m_, v_;  // Adam's first and second moments
  std::vector<float> eps_;     // [pairs, n]: this generation's directions
  uint64_t seed_;
  int generation_ = 0;
};

}  // namespace segue
