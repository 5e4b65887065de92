#include "algorithms/obs_features.h"

#include <string>

#include "core/recipe.h"

namespace segue {

ObsFeatures ObsFeatures::read(const Section& f, int obs_dim) {
  ObsFeatures o;
  o.inputs = f.require<std::vector<int>>("inputs");
  o.periods = f.require<std::vector<double>>("periods");
  for (int i : o.inputs)
    if (i < 0 || i >= obs_dim)
      throw f.error("inputs", "must be observation indices in [0, " + std::to_string(obs_dim) + ")");
  for (double p : o.periods)
    if (!(p > 0)) throw f.error("periods", "must be positive");
  if (o.empty()) throw f.error("inputs", "needs at least one input and one period");
  return o;
}

}  // namespace segue
