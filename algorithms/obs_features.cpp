#include "algorithms/obs_features.h"

#include <string>

#include "core/recipe.h"

namespace segue {

ObsFeatures ObsFeatures::read(const Section& f, int obs_dim) {
  ObsFeatures o;
  o.inputs = f.require<std::vector<int>>("inputs", Range::non_negative());
  o.periods = f.require<std::vector<double>>("periods", Range::positive());
  for (int i : o.inputs)
    if (i >= obs_dim) throw f.error("inputs", "must be observation indices in [0, " + std::to_string(obs_dim) + ")");
  if (o.empty()) throw f.error("inputs", "needs at least one input and one period");
  return o;
}

}  // namespace segue
