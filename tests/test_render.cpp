// segue render --method (tools/segue/render.cpp): one episode of a composite task's method,
// a frame per control step at --fps 125 (the walker's 0.008 s step), each labelled with who
// is in control; the labels are those the controller gives on the same episode run here.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "hrl/composite_recipe.h"
#include "tests/cli_run.h"
#include "tests/csv.h"
#include "tests/temp_dir.h"
#include "tests/tiny_patrol.h"

namespace segue {
namespace {

class Render : public TempDirTest {
 protected:
  Render() : TempDirTest("render") {}
};

TEST_F(Render, AMethodsFramesNameWhoIsInControl) {
  // Tiny Patrol with forward->balance's interval at steps 20 to 120 of the episode: Without
  // TP hands over to balance as it begins.
  const std::string file = path("tiny.yaml");
  std::ofstream(file) << tiny_patrol_by_steps();
  const int steps = 60;
  uint64_t seed = 0;
  CompositeRecipe r = CompositeRecipe::load(file, {"run_dir=" + path("run")});
  auto env = r.make_env();
  std::vector<float> obs(r.spec.obs_dim), act(r.spec.act_dim);
  std::vector<std::string> expected;
  for (;; ++seed) {  // an episode that starts walking forward, so that the hand-over shows
    auto c = method_controllers(r, "without-tp")();
    env->reset(seed, obs.data());
    c->reset(*env, obs.data(), seed);
    expected.clear();
    for (int t = 0; t <= steps; ++t) {
      c->act(*env, obs.data(), act.data());
      expected.push_back(c->in_control());
      if (t == steps || env->step(act.data(), obs.data()).done()) break;
    }
    if (expected.front() == "forward") break;
    ASSERT_LT(seed, 20u);
  }
  ASSERT_EQ(expected.size(), size_t(steps + 1)) << "the episode ended early";
  ASSERT_EQ(expected[19], "forward");
  ASSERT_EQ(expected[20], "balance");

  const CliRun out = run_cli("render --task patrol --method without-tp --recipe " + file + " --seed " +
                             std::to_string(seed) + " --steps " + std::to_string(steps) +
                             " --fps 125 --width 64 --height 48 --frames " + path("frames"));
  if (out.code != 0 && out.output.find("EGL") != std::string::npos) GTEST_SKIP() << "no headless OpenGL: " << out.output;
  ASSERT_EQ(out.code, 0) << out.output;
  const auto rows = csv(path("frames/control.csv"));
  ASSERT_EQ(rows.size(), expected.size() + 1);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"frame", "step", "in_control"}));
  for (size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(rows[k + 1][0], std::to_string(k));
    EXPECT_EQ(rows[k + 1][1], std::to_string(k));
    EXPECT_EQ(rows[k + 1][2], expected[k]) << "frame " << k;
    EXPECT_TRUE(std::filesystem::exists(path("frames/frame_" + std::string(5 - std::to_string(k).size(), '0') +
                                             std::to_string(k) + ".png")))
        << k;
  }
  EXPECT_FALSE(std::filesystem::exists(path("frames/frame_" + std::to_string(100000 + expected.size()).substr(1) + ".png")));

  // A method needs a composite task; a policy and a method together are refused.
  const CliRun both = run_cli("render assets/policies/walker/walker_forward.pt --task patrol --method tp --frames " +
                              path("x"));
  EXPECT_NE(both.code, 0);
  EXPECT_NE(both.output.find("give a POLICY or --method, not both"), std::string::npos) << both.output;
}

}  // namespace
}  // namespace segue
