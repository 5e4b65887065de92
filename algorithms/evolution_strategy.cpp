#include "algorithms/evolution_strategy.h"

#include <torch/torch.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "algorithms/ppo.h"  // kMaxEnvs
#include "core/error.h"
#include "core/rng.h"
#include "core/run_dir.h"

namespace segue {

EsConfig EsConfig::read(const Section& s) {
  EsConfig c;
  c.generations = s.get("generations", c.generations, Range::positive());
  c.pairs = s.get("pairs", c.pairs, Range::closed(1, kMaxEnvs));  // each pair is two environments
  c.episodes = s.get("episodes", c.episodes, Range::positive());
  c.sigma = s.get("sigma", c.sigma, Range::positive());
  c.lr = s.get("lr", c.lr, Range::positive());
  c.inputs = s.get("inputs", c.inputs, Range::non_negative());
  c.fitness = s.choice("fitness", c.fitness, {"success", "return"});
  if (!c.inputs.empty() && (c.inputs.size() != 2 || c.inputs[0] >= c.inputs[1]))
    throw s.error("inputs", "must be [begin, end) with 0 <= begin < end");
  return c;
}

std::vector<double> centred_ranks(const std::vector<double>& fitness) {
  const size_t n = fitness.size();
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return fitness[a] < fitness[b]; });
  std::vector<double> u(n, 0.0);
  if (n < 2) return u;
  for (size_t i = 0; i < n;) {
    size_t j = i;
    while (j < n && fitness[order[j]] == fitness[order[i]]) ++j;
    const double rank = 0.5 * double(i + j - 1);  // mean of ranks i..j-1
    for (size_t k = i; k < j; ++k) u[order[k]] = rank / double(n - 1) - 0.5;
    i = j;
  }
  return u;
}

SearchedParameters::SearchedParameters(Policy start, const std::vector<int>& inputs)
    : start_(std::move(start)), full_(start_.mlp().parameters()) {
  if (inputs.empty()) {
    index_.resize(full_.size());
    std::iota(index_.begin(), index_.end(), size_t(0));
  } else {
    if (inputs.size() != 2 || inputs[0] < 0 || inputs[0] >= inputs[1] || inputs[1] > start_.in_dim())
      throw Error("inputs must be [begin, end) within the policy's " + std::to_string(start_.in_dim()) +
                  " network inputs (observation, then any periodic features)");
    index_ = start_.mlp().input_weight_indices(inputs[0], inputs[1]);
  }
}

std::vector<float> SearchedParameters::initial() const {
  std::vector<float> theta;
  for (size_t k : index_) theta.push_back(full_[k]);
  return theta;
}

Policy SearchedParameters::policy_at(const std::vector<float>& theta) const {
  std::vector<float> p = full_;
  for (size_t i = 0; i < index_.size(); ++i) p[index_[i]] = theta.at(i);
  return start_.with_parameters(p);
}

EvolutionStrategy::EvolutionStrategy(const EsConfig& config, std::vector<float> theta, uint64_t seed)
    : cfg_(config), theta_(std::move(theta)), m_(theta_.size(), 0.0), v_(theta_.size(), 0.0), seed_(seed) {}

uint64_t EvolutionStrategy::episode_seed() const { return mix_seed(seed_, 2 * uint64_t(generation_) + 1); }

std::vector<std::vector<float>> EvolutionStrategy::ask() {
  const size_t n = theta_.size();
  Rng rng(mix_seed(seed_, 2 * uint64_t(generation_)));
  eps_.resize(size_t(cfg_.pairs) * n);
  for (float& e : eps_) e = float(rng.normal());
  std::vector<std::vector<float>> out;
  for (int i = 0; i < cfg_.pairs; ++i) {
    const float* e = &eps_[size_t(i) * n];
    for (float sign : {1.0f, -1.0f}) {
      std::vector<float> c(theta_);
      for (size_t k = 0; k < n; ++k) c[k] += sign * float(cfg_.sigma) * e[k];
      out.push_back(std::move(c));
    }
  }
  return out;
}

double EvolutionStrategy::tell(const std::vector<double>& fitness) {
  const size_t n = theta_.size();
  if (fitness.size() != size_t(2 * cfg_.pairs) || eps_.size() != size_t(cfg_.pairs) * n)
    throw Error("evolution strategy: tell() needs one fitness per candidate of the last ask()");
  for (double f : fitness)
    if (!std::isfinite(f)) throw Error("evolution strategy: a candidate's fitness is not finite");
  const std::vector<double> u = centred_ranks(fitness);
  std::vector<double> g(n, 0.0);
  for (int i = 0; i < cfg_.pairs; ++i) {
    const double w = (u[2 * i] - u[2 * i + 1]) / (2.0 * cfg_.pairs * cfg_.sigma);
    const float* e = &eps_[size_t(i) * n];
    for (size_t k = 0; k < n; ++k) g[k] += w * e[k];
  }
  // Adam (Kingma & Ba 2015), ascending.
  constexpr double b1 = 0.9, b2 = 0.999, tiny = 1e-8;
  ++generation_;
  const double c1 = 1.0 - std::pow(b1, generation_), c2 = 1.0 - std::pow(b2, generation_);
  double norm = 0.0;
  for (size_t k = 0; k < n; ++k) {
    m_[k] = b1 * m_[k] + (1 - b1) * g[k];
    v_[k] = b2 * v_[k] + (1 - b2) * g[k] * g[k];
    theta_[k] += float(cfg_.lr * (m_[k] / c1) / (std::sqrt(v_[k] / c2) + tiny));
    norm += g[k] * g[k];
  }
  eps_.clear();
  return std::sqrt(norm);
}

namespace {

torch::Tensor doubles(const std::vector<double>& v) { return torch::tensor(v, torch::kFloat64); }

}  // namespace

void EvolutionStrategy::save(const std::string& path, const std::string& note,
                             const std::vector<int64_t>& counters) const {
  torch::serialize::OutputArchive ar;
  ar.write("theta", torch::tensor(theta_, torch::kFloat32));
  ar.write("adam_m", doubles(m_));
  ar.write("adam_v", doubles(v_));
  ar.write("generation", torch::tensor(std::vector<int64_t>{generation_}, torch::kLong));
  ar.write("counters", torch::tensor(counters, torch::kLong));
  ar.write("meta_note", text_tensor(note));
  std::ostringstream bytes;
  ar.save_to(bytes);
  write_file_atomic(path, bytes.str());
}

std::vector<int64_t> EvolutionStrategy::load(const std::string& path) {
  torch::serialize::InputArchive ar;
  try {
    ar.load_from(path);
  } catch (const c10::Error&) {
    throw Error(path + ": not an evolution-strategy checkpoint");
  }
  torch::Tensor theta, m, v, generation, counters;
  ar.read("theta", theta);
  ar.read("adam_m", m);
  ar.read("adam_v", v);
  ar.read("generation", generation);
  ar.read("counters", counters);
  if (size_t(theta.numel()) != theta_.size() || m.numel() != theta.numel() || v.numel() != theta.numel())
    throw Error(path + ": checkpoint has " + std::to_string(theta.numel()) + " parameters, the policy " +
                std::to_string(theta_.size()));
  theta_ = to_floats(theta);
  m_ = to_doubles(m);
  v_ = to_doubles(v);
  generation_ = int(generation.item<int64_t>());
  return to_int64s(counters);
}

}  // namespace segue
