#pragma once
// Deterministic randomness. Every environment and every trainer owns one Rng seeded
// from the run seed, so a run is a pure function of its seed, whatever the thread count.
#include <cstdint>
#include <random>
#include <sstream>
#include <string>

namespace segue {

// SplitMix64: turns (seed, stream) into well-spread seeds for independent streams.
inline uint64_t mix_seed(uint64_t seed, uint64_t stream = 0) {
  uint64_t z = seed + 0x9E3779B97F4A7C15ULL * (stream + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

class Rng {
 public:
  explicit Rng(uint64_t seed = 0) : engine_(seed) {}
  void seed(uint64_t s) { engine_.seed(s); }
  // Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit_(engine_); }
  // U(a) of docs/reference/ (e.g. tasks.md#conventions): uniform in [-a, a].
  double symmetric(double a) { return uniform(-a, a); }
  double normal() { return normal_(engine_); }
  bool bernoulli(double p) { return unit_(engine_) < p; }
  int integer(int lo, int hi_inclusive) {
    return std::uniform_int_distribution<int>(lo, hi_inclusive)(engine_);
  }
  std::mt19937_64& engine() { return engine_; }
  // The stream's position as text (the standard library's format), for checkpoints.
  std::string state() const {
    std::ostringstream s;
    s << engine_ << ' ' << normal_;
    return s.str();
  }
  void set_state(const std::string& text) {
    std::istringstream s(text);
    s >> engine_ >> normal_;
  }

 private:
  std::mt19937_64 engine_;
  std::uniform_real_distribution<double> unit_{0.0, 1.0};
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace segue
