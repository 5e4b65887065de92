// `segue run`'s pipeline (hrl/pipeline.h): it writes every artefact and resumes, stopped
// stages resume to the unbroken run, S_a and T_b of another transition or width are
// refused, and Lee's stage trains for its own budget.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "core/run_dir.h"
#include "hrl/collection.h"
#include "hrl/composite_recipe.h"
#include "hrl/pipeline.h"
#include "hrl/switch_training.h"
#include "tests/csv.h"
#include "tests/transition_fixture.h"

namespace segue {
namespace {

namespace fs = std::filesystem;

}  // namespace

// S_a or T_b copied in from another task's run is refused, naming the file.
TEST_F(TransitionTraining, PipelineRefusesStartStatesAndDemonstrationsOfAnotherTransitionOrWidth) {
  CompositeRecipe r = tiny();
  PipelineOptions o;
  o.command = "test";
  const std::string t = path("run/forward-balance/");
  fs::create_directories(t);
  StartStates s = collect_start_states(r, 0, r.pipeline.collect.start_states, 1);
  Demonstrations d = collect_demonstrations(r, 0, 50, 2);
  StartStates narrow = s;
  narrow.obs_dim = s.obs_dim - 1;
  narrow.obs.resize(size_t(narrow.size()) * narrow.obs_dim);
  save(narrow, t + "start_states.pt");
  save(d, t + "demonstrations.pt");
  auto message = [&] {
    try {
      run_pipeline(r, o);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(), t + "start_states.pt: S_a of observations " + std::to_string(s.obs_dim - 1) +
                           " wide, but task 'patrol' has " + std::to_string(s.obs_dim));
  save(s, t + "start_states.pt");
  Demonstrations wide = d;
  wide.act_dim = d.act_dim + 1;
  wide.act.resize(size_t(wide.size()) * wide.act_dim);
  save(wide, t + "demonstrations.pt");
  EXPECT_NE(message().find(t + "demonstrations.pt: T_b of (s, a) "), std::string::npos) << message();
  std::ofstream(t + "demonstrations.pt") << "garbage";
  EXPECT_EQ(message().rfind(t + "demonstrations.pt: not a file of demonstrations (T_b) (", 0), 0u) << message();
  // Files of the right widths collected for another transition (copied between folders).
  ASSERT_EQ(s.source, "patrol forward-balance");
  ASSERT_EQ(r.transition_source(0), s.source);
  ASSERT_EQ(d.source, s.source);
  save(d, t + "demonstrations.pt");
  // Saves `data` relabelled as collected for `source` in place of `file`, expects the run
  // refused, and puts the right file back.
  auto refused = [&](auto data, const std::string& file, const std::string& what, const std::string& source) {
    const auto right = data;
    data.source = source;
    save(data, t + file);
    EXPECT_EQ(message(), t + file + ": " + what + " collected for '" + source +
                             "', but this folder is 'patrol forward-balance'");
    save(right, t + file);
  };
  refused(s, "start_states.pt", "S_a", "patrol backward-balance");
  refused(d, "demonstrations.pt", "T_b", "hurdle walk-jump");
}

TEST_F(TransitionTraining, PipelineWritesEveryArtefactAndResumes) {
  CompositeRecipe r = tiny();
  PipelineOptions o;
  o.command = "test";
  // Stopped at once: the collection keeps nothing and the run returns the signal.
  std::atomic<int> stop{15};
  o.stop = &stop;
  EXPECT_EQ(run_pipeline(r, o), 15);
  const std::string t = path("run/forward-balance/");
  EXPECT_FALSE(fs::exists(t + "start_states.pt"));
  // With S_a and T_b in place, the transition stage checkpoints after one iteration.
  save(collect_start_states(r, 0, r.pipeline.collect.start_states, 1), t + "start_states.pt");
  save(collect_demonstrations(r, 0, r.pipeline.collect.demonstrations, 2), t + "demonstrations.pt");
  EXPECT_EQ(run_pipeline(r, o), 15);
  EXPECT_TRUE(fs::exists(t + "transition_checkpoint.pt"));
  EXPECT_FALSE(fs::exists(t + "policy.pt"));
  // Each rerun while stopped goes one iteration on; the one that finishes pi_ab goes on
  // to the switch stage, which checkpoints after its first report (a tenth of the attempts).
  for (int run = 0; run < 10 && !fs::exists(t + "policy.pt"); ++run) EXPECT_EQ(run_pipeline(r, o), 15);
  ASSERT_TRUE(fs::exists(t + "policy.pt"));
  EXPECT_TRUE(fs::exists(t + "switch_checkpoint.pt"));
  EXPECT_FALSE(fs::exists(t + "q.pt"));
  auto lines_of = [](const std::string& file) {
    std::ifstream in(file);
    int n = 0;
    for (std::string line; std::getline(in, line);) ++n;
    return n;
  };
  EXPECT_EQ(lines_of(t + "switch.csv"), 1 + 1);
  // The stage resumes from the checkpoint it finds: one written after 20 attempts leaves
  // 4 to run (2 reports after the stopped run's one).
  {
    SwitchTrainer later =
        switch_trainer(r, 0, load_start_states(t + "start_states.pt"), Policy::load(t + "policy.pt"), 4);
    later.run(20);
    later.save(t + "switch_checkpoint.pt");
  }
  // Resumed: every stage finishes, each iteration logged once.
  stop = 0;
  EXPECT_EQ(run_pipeline(r, o), 0);
  for (const char* f : {"start_states.pt", "demonstrations.pt", "policy.pt", "q.pt", "lee.pt", "transition.csv",
                        "switch.csv", "lee.csv", "actions.csv"})
    EXPECT_TRUE(fs::exists(t + f)) << f;
  EXPECT_EQ(lines_of(t + "transition.csv"), 1 + 4);  // header + 2048 / (4 x 128) iterations
  EXPECT_EQ(lines_of(t + "switch.csv"), 1 + 1 + 2);
  EXPECT_FALSE(fs::exists(t + "switch_checkpoint.pt")) << "kept after q.pt was written";
  const std::string text = read_file(path("run/patrol.json"));
  for (const char* m : {"\"without-tp\"", "\"tp\"", "\"tp+q\"", "\"lee\""}) EXPECT_NE(text.find(m), std::string::npos) << m;
  // A finished run skips every stage: their outputs are left as they were.
  std::vector<std::string> outputs{t + "policy.pt", t + "q.pt", t + "lee.pt", t + "actions.csv", path("run/patrol.json")};
  std::vector<fs::file_time_type> before;
  for (const auto& f : outputs) before.push_back(fs::last_write_time(f));
  EXPECT_EQ(run_pipeline(r, o), 0);
  for (size_t i = 0; i < outputs.size(); ++i) EXPECT_EQ(fs::last_write_time(outputs[i]), before[i]) << outputs[i];
  // Each exported file says what it is for, and one made for another transition is refused.
  for (const char* f : {"policy.pt", "q.pt", "lee.pt"})
    EXPECT_EQ(Policy::load(t + f).source(), std::string("patrol forward-balance ") + f);
  Policy other = Policy::load(t + "policy.pt");
  other.set_source("patrol backward-balance policy.pt");
  other.export_torchscript(t + "policy.pt");
  try {
    load_transition_artefacts(r, path("run"), "policy.pt", /*with_q=*/true);
    ADD_FAILURE() << "a policy.pt made for another transition was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), t + "policy.pt: made for 'patrol backward-balance policy.pt', but this is "
                                         "'patrol forward-balance policy.pt'");
  }
}

// The transition stage and Lee's, stopped after every iteration and resumed, write the rows
// and the policies of the unbroken run: their checkpoints carry the episodes in flight
// (TransitionEnv and LeeTransitionEnv save theirs), not only the networks.
TEST_F(TransitionTraining, StoppedPpoStagesResumeToTheUnbrokenRun) {
  tiny();  // writes the recipe file
  auto prepared = [&](const std::string& run) {
    CompositeRecipe r = CompositeRecipe::load(path("tiny_patrol.yaml"), {"lee.enabled=true", "run_dir=" + path(run)});
    const std::string t = path(run + "/forward-balance/");
    fs::create_directories(t);
    save(collect_start_states(r, 0, r.pipeline.collect.start_states, 1), t + "start_states.pt");
    save(collect_demonstrations(r, 0, r.pipeline.collect.demonstrations, 2), t + "demonstrations.pt");
    return r;
  };
  PipelineOptions o;
  o.command = "test";
  const CompositeRecipe unbroken = prepared("unbroken");
  ASSERT_EQ(run_pipeline(unbroken, o), 0);
  const CompositeRecipe stopped = prepared("stopped");
  std::atomic<int> stop{15};
  o.stop = &stop;
  const std::string t = path("stopped/forward-balance/"), u = path("unbroken/forward-balance/");
  for (int run = 0; run < 60 && !fs::exists(t + "lee.pt"); ++run) {
    const int rc = run_pipeline(stopped, o);  // stopped, but for the run that finishes the last stage
    EXPECT_TRUE(rc == 15 || fs::exists(t + "lee.pt")) << rc;
  }
  ASSERT_TRUE(fs::exists(t + "lee.pt"));
  auto rows = [](const std::string& file) {
    std::ifstream in(file);
    std::vector<std::string> out;
    for (std::string line; std::getline(in, line);) out.push_back(line.substr(0, line.rfind(',')));  // less wall_seconds
    return out;
  };
  for (const char* csv : {"transition.csv", "lee.csv"}) {
    ASSERT_EQ(rows(t + csv).size(), 1u + 2048 / 512) << csv;
    EXPECT_EQ(rows(t + csv), rows(u + csv)) << csv;
  }
  const std::vector<float> obs = random_obs(8, unbroken.skills[2].policy.obs_dim(), 4);
  for (const char* f : {"policy.pt", "lee.pt"}) {
    Policy a = Policy::load(t + f), b = Policy::load(u + f);
    std::vector<float> ya(8 * a.act_dim()), yb(8 * b.act_dim());
    a.act(obs.data(), 8, ya.data());
    b.act(obs.data(), 8, yb.data());
    EXPECT_EQ(ya, yb) << f;
  }
}

// Lee's policy trains with pi_ab's settings, but for its own budget when lee.total_steps
// is given: here 1024 steps (two iterations of 4 x 128) against pi_ab's 2048 (four).
TEST_F(TransitionTraining, LeeTrainsForItsOwnBudgetWhenGiven) {
  tiny();  // writes the recipe file
  CompositeRecipe r = CompositeRecipe::load(path("tiny_patrol.yaml"),
                                            {"lee.enabled=true", "lee.total_steps=1024", "run_dir=" + path("run")});
  EXPECT_EQ(r.pipeline.lee.transition(r.pipeline.transition).ppo.total_steps, 1024);
  EXPECT_EQ(r.pipeline.lee.transition(r.pipeline.transition).ppo.gamma, r.pipeline.transition.ppo.gamma);
  const std::string t = path("run/forward-balance/");
  fs::create_directories(t);
  save(collect_start_states(r, 0, r.pipeline.collect.start_states, 1), t + "start_states.pt");
  save(collect_demonstrations(r, 0, r.pipeline.collect.demonstrations, 2), t + "demonstrations.pt");
  PipelineOptions o;
  o.command = "test";
  ASSERT_EQ(run_pipeline(r, o), 0);
  auto steps = [](const std::string& file) {  // iterations, and the last row's global_step
    const auto rows = csv(file);
    return std::make_pair(int(rows.size()) - 1, std::stod(rows.back()[1]));
  };
  EXPECT_EQ(steps(t + "transition.csv"), std::make_pair(4, 2048.0));
  EXPECT_EQ(steps(t + "lee.csv"), std::make_pair(2, 1024.0));
}

}  // namespace segue
