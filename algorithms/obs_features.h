#pragma once
// Periodic ("Fourier") features of chosen raw observations, appended to a network's
// normalised input: for each input x_i and period P, sin(2 pi x_i / P), cos(2 pi x_i / P)
// (Tancik et al. 2020). A tanh MLP reading a distance d represents functions periodic in d
// poorly, e.g. where within its ~1.9 m hop a gait will meet a curb d ahead; these inputs
// hand it that phase directly.
#include <cmath>
#include <vector>

namespace segue {

class Section;

struct ObsFeatures {
  std::vector<int> inputs;       // raw observation indices
  std::vector<double> periods;   // in the observation's units (metres for a distance)

  int size() const { return 2 * static_cast<int>(inputs.size() * periods.size()); }
  bool empty() const { return size() == 0; }
  // out[2k], out[2k+1] = sin, cos of input inputs[k / |periods|] at period periods[k % |periods|].
  void write(const float* raw, float* out) const {
    constexpr double kTwoPi = 6.283185307179586476925;
    for (int i : inputs)
      for (double p : periods) {
        const double phase = kTwoPi * raw[i] / p;
        *out++ = static_cast<float>(std::sin(phase));
        *out++ = static_cast<float>(std::cos(phase));
      }
  }
  bool operator==(const ObsFeatures& o) const { return inputs == o.inputs && periods == o.periods; }
  // A recipe's `fourier: {inputs: [...], periods: [...]}` section, for observations of
  // width obs_dim (throws segue::Error naming the key).
  static ObsFeatures read(const Section& f, int obs_dim);
};

}  // namespace segue
