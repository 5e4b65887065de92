// What a composite recipe reads for `segue run` (hrl/composite_recipe.h, with the stages'
// settings of hrl/pipeline_config.h): a transition's own start_states overrides
// collect.start_states.
#include <gtest/gtest.h>

#include <string>

#include "hrl/composite_recipe.h"
#include "tests/transition_fixture.h"

namespace segue {

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
