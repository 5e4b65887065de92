// The whole job's ETA (JobPlan) on a clock the test moves: each figure by hand.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "core/progress.h"

namespace segue {
namespace {

struct FakeClock {
  double t = 0;
  JobPlan::Clock clock() {
    return [this] { return t; };
  }
};

TEST(JobPlan, BeforeAMinuteHasRunTheCostModelStands) {
  FakeClock c;
  JobPlan plan(c.clock());
  plan.add("a", 1000);
  plan.add("b", 2000);
  EXPECT_DOUBLE_EQ(plan.eta_seconds(), 3000);
  plan.begin("a");
  c.t = 40;
  plan.report(0.04, 0, NAN);  // 40 model-seconds done: below a minute, speed 1
  EXPECT_DOUBLE_EQ(plan.eta_seconds(), 960 + 2000);
}

TEST(JobPlan, AMachineTwiceAsSlowDoublesWhatIsLeft) {
  FakeClock c;
  JobPlan plan(c.clock());
  plan.add("a", 1000);
  plan.add("b", 2000);
  plan.begin("a");
  c.t = 1000;
  plan.report(0.5, 0, NAN);  // half of a's 1000 s in 1000 s: speed 2
  EXPECT_DOUBLE_EQ(plan.eta_seconds(), 500 * 2 + 2000 * 2);
  plan.report(0.5, 0, 900);  // the running line's own ETA replaces the model's for its part
  EXPECT_DOUBLE_EQ(plan.eta_seconds(), 900 + 2000 * 2);
  c.t = 1800;
  plan.begin("b");  // a done: 1800 s for 1000 expected
  c.t = 1800 + 360;
  plan.report(0.1, 0, NAN);  // 2160 s taken for 1200 expected: speed 1.8
  EXPECT_NEAR(plan.eta_seconds(), 1800 * 1.8, 1e-9);
  EXPECT_EQ(plan.summary(), "36m00s so far, ETA ~54m00s");
}

TEST(JobPlan, SkippedPartsCostNothingAndAResumedPartOnlyItsRest) {
  FakeClock c;
  JobPlan plan(c.clock());
  plan.add("collect", 500);
  plan.add("train", 1000);
  plan.add("evaluate", 300);
  plan.skip("collect");
  plan.begin("train");
  c.t = 500;
  plan.report(0.75, 0.5, NAN);  // resumed at half: 250 model-seconds in 500, speed 2
  EXPECT_DOUBLE_EQ(plan.eta_seconds(), 250 * 2 + 300 * 2);
}

TEST(JobPlan, APartOfSeveralLinesCountsTheLinesDone) {
  FakeClock c;
  JobPlan plan(c.clock());
  plan.add("evaluate", 900, 3);  // three lines of 300 s each
  plan.begin("evaluate");
  plan.piece_began();
  c.t = 300;
  plan.report(1.0, 0, 0);
  plan.piece_began();
  c.t = 450;
  plan.report(0.5, 0, NAN);  // 1.5 of 3 lines (450 model-seconds) in 450 s: speed 1
  EXPECT_DOUBLE_EQ(plan.eta_seconds(), 150 + 300);
  plan.piece_began();
  plan.piece_began();  // a line past the plan (a closing evaluation) is not followed
  plan.report(0.1, 0, 1e6);
  EXPECT_DOUBLE_EQ(plan.eta_seconds(), 0);
}

TEST(JobPlan, ProgressLinesFeedTheCurrentPlan) {
  FakeClock c;
  {
    JobPlan plan(c.clock());
    EXPECT_EQ(JobPlan::current(), &plan);
    plan.add("train", 1000);
    plan.add("evaluate", 500);
    plan.begin("train");
    Progress line("train", 100, 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // the line's own rate is then finite
    c.t = 800;
    line.update(40, NAN, NAN);  // 40% of the part (400 model-seconds) in 800 s: speed 2
    // The line's own ETA for the rest of it (60 steps at its real rate: milliseconds), then evaluate's 500 x 2.
    EXPECT_NEAR(plan.eta_seconds(), 1000, 0.5);
  }
  EXPECT_EQ(JobPlan::current(), nullptr);
}

}  // namespace
}  // namespace segue
