// Evolution strategies: centred ranks and the first Adam step by hand, convergence on a
// quadratic, improvement of a walker policy's return, and a resumed run drawing the same
// directions; the flat parameter view of a network; population evaluation on common seeds.
#include <gtest/gtest.h>

#include <cmath>

#include "algorithms/evolution_strategy.h"
#include "algorithms/ppo.h"
#include "environments/registry.h"
#include "hrl/evaluation.h"
#include "tests/temp_dir.h"

namespace segue {
namespace {

EsConfig config(int pairs, double sigma, double lr) {
  EsConfig c;
  c.pairs = pairs, c.sigma = sigma, c.lr = lr;
  return c;
}

double distance(const std::vector<float>& a, const std::vector<float>& b) {
  double d = 0;
  for (size_t k = 0; k < a.size(); ++k) d += (a[k] - b[k]) * (a[k] - b[k]);
  return std::sqrt(d);
}

}  // namespace

TEST(CentredRanks, SpreadEvenlyFromMinusToPlusHalfAndShareTies) {
  EXPECT_EQ(centred_ranks({3.0, 1.0, 2.0}), (std::vector<double>{0.5, -0.5, 0.0}));
  // Ranks 0..3; the two 1s share ranks 1 and 2, i.e. 1.5 -> 1.5 / 3 - 0.5 = 0.
  EXPECT_EQ(centred_ranks({1.0, 1.0, 2.0, 0.0}), (std::vector<double>{0.0, 0.0, 0.5, -0.5}));
  // Any increasing transform leaves them unchanged.
  EXPECT_EQ(centred_ranks({1.0, 1000.0, 2.0}), centred_ranks({1.0, 3.0, 2.0}));
  EXPECT_EQ(centred_ranks({5.0}), (std::vector<double>{0.0}));
}

TEST(EvolutionStrategy, FirstStepIsLrTimesTheSignOfTheWinningDirection) {
  // One pair, fitness (1, 0): u = (0.5, -0.5), g = (0.5 + 0.5) / (2 sigma) eps. Adam's
  // bias-corrected first step is lr g / |g| per coordinate: theta + lr sign(eps).
  const std::vector<float> theta0{0.5f, -1.0f, 2.0f};
  EvolutionStrategy es(config(1, 0.1, 0.01), theta0, 5);
  auto cands = es.ask();
  ASSERT_EQ(cands.size(), 2u);
  std::vector<float> eps(3);
  for (int k = 0; k < 3; ++k) {
    eps[k] = (cands[0][k] - theta0[k]) / 0.1f;
    EXPECT_NEAR(cands[1][k], theta0[k] - 0.1f * eps[k], 1e-6f);  // antithetic
  }
  double norm = es.tell({1.0, 0.0});
  double eps_norm = std::sqrt(eps[0] * eps[0] + eps[1] * eps[1] + eps[2] * eps[2]);
  EXPECT_NEAR(norm, eps_norm / 0.2, 1e-3 * norm);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(es.theta()[k], theta0[k] + 0.01f * (eps[k] > 0 ? 1 : -1), 1e-5f);
  EXPECT_EQ(es.generation(), 1);
}

TEST(EvolutionStrategy, ClimbsAQuadratic) {
  // F(theta) = -|theta - target|^2 in 10 dimensions, from 2.0 away.
  std::vector<float> target(10), theta(10, 0.0f);
  for (int k = 0; k < 10; ++k) target[k] = (k % 2 ? 0.6f : -0.7f);
  EvolutionStrategy es(config(10, 0.05, 0.05), theta, 11);
  const double before = distance(es.theta(), target);
  for (int g = 0; g < 150; ++g) {
    std::vector<double> f;
    for (const auto& c : es.ask()) f.push_back(-distance(c, target));
    es.tell(f);
  }
  EXPECT_LT(distance(es.theta(), target), 0.2 * before) << "from " << before;
}

TEST(EvolutionStrategy, RejectsAMismatchedTellAndNonFiniteFitness) {
  EvolutionStrategy es(config(2, 0.1, 0.01), {0.0f, 1.0f}, 1);
  es.ask();
  EXPECT_THROW(es.tell({1.0, 2.0}), Error);
  EXPECT_THROW(es.tell({1.0, 2.0, NAN, 0.0}), Error);
}

class EsCheckpoint : public TempDirTest {
 protected:
  EsCheckpoint() : TempDirTest("es") {}
};

TEST_F(EsCheckpoint, AResumedRunDrawsTheSameDirectionsAndTakesTheSameSteps) {
  const std::vector<float> theta0{0.1f, 0.2f, 0.3f, 0.4f};
  auto fitness = [](const std::vector<std::vector<float>>& cands) {
    std::vector<double> f;
    for (const auto& c : cands) f.push_back(c[0] - c[1] * c[1] + 0.5 * c[3]);
    return f;
  };
  EvolutionStrategy a(config(3, 0.1, 0.02), theta0, 9);
  for (int g = 0; g < 2; ++g) a.tell(fitness(a.ask()));
  a.save(path("es.pt"), "note", {1234, 5678});
  EvolutionStrategy b(config(3, 0.1, 0.02), theta0, 9);
  EXPECT_EQ(b.load(path("es.pt")), (std::vector<int64_t>{1234, 5678}));
  EXPECT_EQ(b.generation(), 2);
  EXPECT_EQ(b.theta(), a.theta());
  EXPECT_EQ(b.episode_seed(), a.episode_seed());
  for (int g = 0; g < 2; ++g) {
    auto ca = a.ask(), cb = b.ask();
    EXPECT_EQ(ca, cb);
    a.tell(fitness(ca));
    b.tell(fitness(cb));
  }
  EXPECT_EQ(b.theta(), a.theta());  // Adam's moments came back too
  EvolutionStrategy wrong(config(3, 0.1, 0.02), {0.0f, 0.0f}, 9);
  EXPECT_THROW(wrong.load(path("es.pt")), Error);
}

TEST(EigenMlp, FlatParametersRoundTripAndChangeTheOutput) {
  torch::manual_seed(4);
  EigenMlp mlp(make_mlp(5, {7}, 2, Activation::Tanh, 1.0), Activation::Tanh);
  ASSERT_EQ(mlp.parameter_count(), size_t(5 * 7 + 7 + 7 * 2 + 2));
  std::vector<float> theta = mlp.parameters();
  EXPECT_EQ(theta[5 * 7], mlp.biases()[0][0]);      // W_0 row-major, then b_0
  EXPECT_EQ(theta[5 * 7 + 7], mlp.weights()[1](0, 0));
  const float x[5] = {0.1f, -0.2f, 0.3f, 0.0f, 1.0f};
  float y0[2], y1[2];
  mlp.forward(x, 1, y0);
  theta.back() += 0.5f;  // the last bias: output 1 moves by exactly 0.5
  mlp.set_parameters(theta);
  mlp.forward(x, 1, y1);
  EXPECT_FLOAT_EQ(y1[0], y0[0]);
  EXPECT_NEAR(y1[1], y0[1] + 0.5f, 1e-6f);
  EXPECT_EQ(mlp.parameters(), theta);
  EXPECT_THROW(mlp.set_parameters(std::vector<float>(3)), Error);
  // The first layer's weights from inputs 3 and 4: two per hidden unit.
  const std::vector<size_t> idx = mlp.input_weight_indices(3, 5);
  ASSERT_EQ(idx.size(), 14u);
  for (int r = 0; r < 7; ++r)
    for (int j = 3; j < 5; ++j) EXPECT_EQ(theta[idx[2 * r + (j - 3)]], mlp.weights()[0](r, j));
}

TEST(SearchedParameters, MoveOnlyTheFirstLayerWeightsFromTheGivenInputs) {
  torch::manual_seed(6);
  EigenMlp mlp(make_mlp(4, {3}, 2, Activation::Tanh, 1.0), Activation::Tanh);
  Policy start(mlp, std::vector<float>(4, 0.0f), std::vector<float>(4, 1.0f), 10.0f, {-1, -1}, {1, 1});
  SearchedParameters all(start, {}), pair(start, {2, 4});
  EXPECT_EQ(all.initial(), start.mlp().parameters());
  ASSERT_EQ(pair.size(), 6u);  // 3 hidden units x inputs 2 and 3
  std::vector<float> theta = pair.initial();
  for (float& t : theta) t += 1.0f;
  const std::vector<float> before = start.mlp().parameters(), after = pair.policy_at(theta).mlp().parameters();
  int moved = 0;
  for (size_t k = 0; k < before.size(); ++k) moved += after[k] != before[k];
  EXPECT_EQ(moved, 6);
  for (int r = 0; r < 3; ++r)
    for (int j = 0; j < 4; ++j)
      EXPECT_FLOAT_EQ(pair.policy_at(theta).mlp().weights()[0](r, j), mlp.weights()[0](r, j) + (j >= 2 ? 1.0f : 0.0f));
  EXPECT_THROW(SearchedParameters(start, {2, 5}), Error);
}

namespace {

struct ShortWalker {
  Recipe recipe = Recipe::parse("{env: {max_episode_steps: 100, success_steps: 100}}", "test");
  EnvFactory make = task_factory("walker_forward", recipe.root().sub("env"));
};

Policy random_policy(const ShortWalker& w, uint64_t seed) {
  VectorEnv envs(w.make, 1, 1);
  ActorCriticSpec spec;
  spec.obs_dim = 26, spec.act_dim = 6;
  return PPO(PpoConfig(), spec, envs, seed).policy();
}

}  // namespace

TEST(EvaluatePopulation, EachCandidateMeetsTheSeedsEvaluatePolicyGivesIt) {
  at::set_num_threads(1);
  ShortWalker w;
  Policy p = random_policy(w, 1), q = random_policy(w, 2);
  auto both = evaluate_population({p, q}, w.make, 5, 77, 2);
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0].returns, evaluate_policy(p, w.make, 5, 77, 1).returns);
  EXPECT_EQ(both[1].returns, evaluate_policy(q, w.make, 5, 77, 1).returns);
  EXPECT_NE(both[0].returns, both[1].returns);
}

TEST(EvolutionStrategy, ImprovesAWalkerPolicysReturnOnAShortHorizon) {
  // From a random-init policy (falls within ~40 steps), ES on the mean return of 4
  // episodes: 12 generations of 16 candidates, ~70k steps.
  at::set_num_threads(1);
  ShortWalker w;
  const Policy start = random_policy(w, 3);
  auto mean_return = [&](const Policy& p) { return summarize(evaluate_policy(p, w.make, 16, 123, 2).returns).mean; };
  EvolutionStrategy es(config(8, 0.05, 0.03), start.mlp().parameters(), 5);
  const double before = mean_return(start);
  for (int g = 0; g < 12; ++g) {
    std::vector<Policy> cands;
    for (const auto& theta : es.ask()) cands.push_back(start.with_parameters(theta));
    std::vector<double> f;
    for (const auto& r : evaluate_population(cands, w.make, 4, es.episode_seed(), 2)) f.push_back(summarize(r.returns).mean);
    es.tell(f);
  }
  const double after = mean_return(start.with_parameters(es.theta()));
  EXPECT_GT(after, before + 30.0) << "before " << before << " after " << after;
}

}  // namespace segue
