// What a composite recipe reads for `segue run` (hrl/composite_recipe.h, with the stages'
// settings of hrl/pipeline_config.h): the keys for periodic features of the observation
// are checked against the task's, and a transition's own start_states overrides
// collect.start_states.
#include <gtest/gtest.h>

#include <string>

#include "hrl/composite_recipe.h"
#include "tests/transition_fixture.h"

namespace segue {

// Both recipe keys for periodic features of the task's observation, q_ab's and D's, are
// read the same way and refuse an input past the observation, naming the key.
TEST_F(TransitionTraining, PeriodicFeatureKeysAreReadAgainstTheObservation) {
  const int D = tiny().spec.obs_dim;
  for (std::string key : {"switch.fourier", "transition.discriminator.fourier"}) {
    SCOPED_TRACE(key);
    CompositeRecipe r = tiny({key + "={inputs: [0, 3], periods: [0.5, 2]}"});
    const ObsFeatures& read =
        key == "switch.fourier" ? r.pipeline.switching.features : r.pipeline.transition.discriminator.features;
    EXPECT_EQ(read, (ObsFeatures{{0, 3}, {0.5, 2}}));
    try {
      tiny({key + "={inputs: [" + std::to_string(D) + "], periods: [1]}"});
      ADD_FAILURE() << "an input past the observation was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("key '" + key + ".inputs': must be observation indices in [0, " +
                                           std::to_string(D) + ")"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST_F(TransitionTraining, ATransitionsOwnStartStatesOverrideTheCollectSize) {
  EXPECT_EQ(tiny().start_state_count(0), 12);  // collect.start_states
  EXPECT_EQ(tiny({"transitions.0.start_states=5"}).start_state_count(0), 5);
  try {
    tiny({"transitions.0.start_states=0"});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("key 'transitions.0.start_states' must be > 0, got 0"), std::string::npos)
        << e.what();
  }
}

}  // namespace segue
