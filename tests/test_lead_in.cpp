// The lead-in (hrl/lead_in.h): a skill's training episode that begins where another
// skill hands over to it, at a state of that skill's own run inside the interval.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/assets.h"
#include "environments/walker_obstacles.h"
#include "hrl/lead_in.h"
#include "task_fixture.h"

namespace segue {
namespace {

const char* kWalk = "assets/policies/walker/walker_forward.pt";
const char* kJumpEnv = "{push_prob: 0}";  // no pushes: the walk reaches every curb

LeadIn walk_lead_in(const std::string& section) {
  Recipe r = Recipe::parse("lead_in: " + section, "lead.yaml");
  return LeadIn::read(r.root().sub("lead_in"), make_task("walker_jump", kJumpEnv)->spec());
}

double curb_ahead(const Env& env) {
  double f[2];
  env.features(f);
  return f[0];
}

TEST(LeadIn, JumpFeaturesMeasureTheNearestCurbFromTheRearmostPoint) {
  auto env = make_task("walker_jump", "{curbs: 2, curb_spacing: 8, curb_x: 3, curb_noise: 0}");
  std::vector<float> obs(env->spec().obs_dim);
  env->reset(3, obs.data());
  const auto& jump = dynamic_cast<const WalkerJump&>(*env);
  ASSERT_EQ(env->spec().feature_names, (std::vector<std::string>{"curb_ahead", "curb_behind"}));
  double f[2];
  env->features(f);
  EXPECT_DOUBLE_EQ(f[0], jump.obstacles()[0].start - jump.min_x());
  EXPECT_EQ(f[1], WalkerObstacleEnv::kFar);  // no curb behind at the start
  EXPECT_NEAR(f[0], obs[26], 1e-5);          // the observed pair (within 5 m) measures from the same x
  EXPECT_NEAR(f[0], 3.0 - jump.min_x(), 1e-12);
}

// The crawl declares the Obstacle course's ceiling features, so the walk can lead into it
// where that course hands over: measured from the rearmost point, "far" where there is none.
TEST(LeadIn, WalkLeadsIntoTheCrawlBeforeItsCeiling) {
  const char* env_keys = "{push_prob: 0, ceiling_start: 8, ceiling_end: 11}";
  Recipe r = Recipe::parse("lead_in: {policy: " + std::string(kWalk) + ", when: {ceiling_ahead: [2, 3]}}", "lead.yaml");
  auto crawl = make_task("walker_crawl", env_keys);
  ASSERT_EQ(crawl->spec().feature_names, (std::vector<std::string>{"ceiling_ahead", "ceiling_behind"}));
  std::vector<float> obs(crawl->spec().obs_dim);
  crawl->reset(3, obs.data());
  const auto& start = dynamic_cast<const WalkerObstacleEnv&>(*crawl);
  double f[2];
  crawl->features(f);
  EXPECT_NEAR(f[0], 8.0 - start.min_x(), 1e-12);
  EXPECT_EQ(f[1], WalkerObstacleEnv::kFar);

  LeadInEnv env(make_task("walker_crawl", env_keys), LeadIn::read(r.root().sub("lead_in"), crawl->spec()));
  env.reset(3, obs.data());
  ASSERT_GT(env.lead_in_steps(), 100);  // the walk covers 5 m of the 8 first
  env.features(f);
  EXPECT_GE(f[0], 2.0);
  EXPECT_LE(f[0], 3.0);
  EXPECT_EQ(f[1], WalkerObstacleEnv::kFar);
}

// The hand-over state is one the walk itself passes through: replaying the walk for
// lead_in_steps() from the same start reproduces it exactly, and it lies in the interval.
TEST(LeadIn, HandsOverAtAStateOfTheLeadInSkillsOwnRun) {
  LeadInEnv env(make_task("walker_jump", kJumpEnv), walk_lead_in("{policy: " + std::string(kWalk) +
                                                                  ", when: {curb_ahead: [3, 4]}}"));
  std::vector<float> obs(env.spec().obs_dim);
  env.reset(11, obs.data());
  const int n = env.lead_in_steps();
  ASSERT_GT(n, 20);  // the curb is 5.5-8.5 m away: the walk takes a while to be 4 m short of it
  EXPECT_GE(curb_ahead(env), 3.0);
  EXPECT_LE(curb_ahead(env), 4.0);

  auto replay = make_task("walker_jump", kJumpEnv);
  Policy walk = Policy::load(repo_path(kWalk));
  std::vector<float> replay_obs(obs.size()), action(env.spec().act_dim);
  replay->reset(11, replay_obs.data());
  for (int t = 0; t < n; ++t) {
    walk.act(replay_obs.data(), 1, action.data());
    ASSERT_FALSE(replay->step(action.data(), replay_obs.data()).done());
  }
  std::vector<double> a, b;
  env.save_state(a);
  replay->save_state(b);
  EXPECT_EQ(a, b);
  // A restored state's observation is computed afresh from the positions (the curb pair
  // differs from the stepped one in the last float digits); the steps after it are the same.
  for (size_t i = 0; i < obs.size(); ++i) EXPECT_NEAR(obs[i], replay_obs[i], 1e-4) << i;
  for (int t = 0; t < 20; ++t) {
    walk.act(obs.data(), 1, action.data());
    env.step(action.data(), obs.data());
    replay->step(action.data(), replay_obs.data());
  }
  EXPECT_EQ(obs, replay_obs);
}

// The hand-over point is spread over the whole interval, and `share` of the episodes
// begin with the lead-in; the rest begin at the task's own start (step 0).
TEST(LeadIn, SpreadsHandOversOverTheIntervalForItsShareOfEpisodes) {
  LeadInEnv env(make_task("walker_jump", kJumpEnv), walk_lead_in("{policy: " + std::string(kWalk) +
                                                                  ", when: {curb_ahead: [3, 4]}, share: 0.5}"));
  std::vector<float> obs(env.spec().obs_dim);
  env.reset(5, obs.data());
  int led = 0;
  double lo = 1e9, hi = -1e9;
  const int episodes = 200;
  for (int e = 0; e < episodes; ++e) {
    if (e > 0) env.reset(obs.data());
    if (env.lead_in_steps() == 0) {
      EXPECT_GT(curb_ahead(env), 4.0);  // the task's start: 5.5-8.5 m before the curb
      continue;
    }
    ++led;
    lo = std::min(lo, curb_ahead(env)), hi = std::max(hi, curb_ahead(env));
  }
  EXPECT_GE(led, 70);  // Binomial(200, 0.5): 100 +- 7
  EXPECT_LE(led, 130);
  EXPECT_GE(lo, 3.0);
  EXPECT_LT(lo, 3.2);  // ~100 draws from a stretch of ~30 walk steps reach both ends
  EXPECT_GT(hi, 3.8);
  EXPECT_LE(hi, 4.0);
}

TEST(LeadIn, RefusesWhatCannotLeadIn) {
  const std::string walk = std::string(kWalk);
  auto message = [](const std::string& section) {
    try {
      walk_lead_in(section);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("{policy: " + walk + "}"),
            "lead.yaml: key 'lead_in.when': give the interval the lead-in hands over in, e.g. {curb_ahead: [3, 4]}");
  EXPECT_EQ(message("{policy: " + walk + ", when: {curb_ahead: [3, 4]}, share: 0}"),
            "lead.yaml: key 'lead_in.share' must be in (0, 1], got 0");
  // The jump's policy sees 28 numbers: it cannot lead into the 26 of walker_forward.
  Recipe wide = Recipe::parse("lead_in: {policy: assets/policies/walker/walker_jump.pt, when: {steps: 1}}", "w.yaml");
  try {
    LeadIn::read(wide.root().sub("lead_in"), make_task("walker_forward")->spec());
    ADD_FAILURE() << "a policy wider than the task was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("w.yaml: key 'lead_in.policy': 'assets/policies/walker/walker_jump.pt'"),
              std::string::npos)
        << e.what();
  }
  // An interval the walk never enters (the episode ends at x = 15, long before any curb
  // is 100 m behind) is refused after kAttempts episodes, not looped on.
  LeadInEnv never(make_task("walker_jump", kJumpEnv),
                  walk_lead_in("{policy: " + walk + ", when: {curb_behind: [100, 200]}}"));
  std::vector<float> obs(never.spec().obs_dim);
  try {
    never.reset(1, obs.data());
    ADD_FAILURE() << "an unreachable lead-in was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("did not reach its interval in 100 episodes"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace segue
