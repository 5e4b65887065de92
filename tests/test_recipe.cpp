// Recipes: strict keys, types, overrides, and the CLI's one-line errors.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <tuple>

#include "core/mujoco_env.h"
#include "core/recipe.h"
#include "tests/cli_run.h"
#include "tests/temp_dir.h"

namespace segue {

TEST(Recipe, ReadsValuesDefaultsAndOverrides) {
  Recipe r = Recipe::parse("ppo: {lr: 0.001, total_steps: 2e6}\nseed: 3\n", "r.yaml",
                           {"ppo.epochs=4", "env.push_prob=0"});
  Section ppo = r.root().sub("ppo");
  EXPECT_DOUBLE_EQ(ppo.get("lr", 1.0), 0.001);
  EXPECT_EQ(ppo.get<int64_t>("total_steps", 0), 2000000);
  EXPECT_EQ(ppo.get("epochs", 10), 4);
  EXPECT_EQ(ppo.get("minibatch_size", 64), 64);  // default
  EXPECT_EQ(r.root().get("seed", 0), 3);
  EXPECT_DOUBLE_EQ(r.root().sub("env").get("push_prob", 0.2), 0.0);
  EXPECT_NO_THROW(r.reject_unknown());
  // The resolved recipe records defaults too, and which keys were left to them.
  EXPECT_NE(r.resolved_yaml().find("minibatch_size: 64"), std::string::npos);
  EXPECT_EQ(r.defaulted_keys(), (std::set<std::string>{"ppo.minibatch_size"}));
}

TEST(Recipe, UnknownKeyIsNamedWithASuggestion) {
  Recipe r = Recipe::parse("ppo: {lrr: 0.1}\n", "r.yaml");
  r.root().sub("ppo").get("lr", 1.0);
  try {
    r.reject_unknown();
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "r.yaml: unknown key 'ppo.lrr'; did you mean 'ppo.lr'?");
  }
}

// An integer key holds an integer its type can hold: 1e30 is refused, not cast (a cast out
// of range is undefined behaviour; the recipe fuzzer found it), and 2e6 is fine.
TEST(Recipe, IntegersOutOfTheirRangeAreRefused) {
  Recipe r = Recipe::parse("ppo: {total_steps: 1e30, num_envs: -1e300, epochs: 3e9, seed: 2e6, nan: .nan}\n", "r.yaml");
  const Section ppo = r.root().sub("ppo");
  auto message = [](auto&& read) {
    try {
      read();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message([&] { ppo.get<int64_t>("total_steps", 0); }), "r.yaml: key 'ppo.total_steps' expects an integer, got '1e30'");
  EXPECT_EQ(message([&] { ppo.get<int>("num_envs", 0); }), "r.yaml: key 'ppo.num_envs' expects an integer, got '-1e300'");
  EXPECT_EQ(message([&] { ppo.get<int>("epochs", 0); }), "r.yaml: key 'ppo.epochs' expects an integer, got '3e9'");
  EXPECT_EQ(ppo.get<int64_t>("epochs", 0), 3000000000);
  EXPECT_EQ(message([&] { ppo.get<int>("nan", 0); }), "r.yaml: key 'ppo.nan' expects an integer, got '.nan'");
  EXPECT_EQ(ppo.get<int>("seed", 0), 2000000);
}

TEST(Recipe, RangesAreCheckedWhereAKeyIsReadAndListed) {
  EXPECT_EQ(Range::positive().text(), "> 0");
  EXPECT_EQ(Range::non_negative().text(), ">= 0");
  EXPECT_EQ(Range::open_closed(0, 1).text(), "in (0, 1]");
  EXPECT_EQ(Range::closed(-1.5, 2).text(), "in [-1.5, 2]");
  EXPECT_EQ(Range::at_most(0).text(), "<= 0");
  EXPECT_EQ(Range::any().text(), "any");
  EXPECT_TRUE(Range::open_closed(0, 1).contains(1));
  EXPECT_FALSE(Range::open_closed(0, 1).contains(0));
  EXPECT_TRUE(Range::closed(0, 1).contains(0));
  Recipe r = Recipe::parse("a: -0.2\nb: [3, 0]\nc: 0.5\nd: relu\n", "r.yaml");
  auto message = [](const auto& read) {
    try {
      read();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message([&] { r.root().get("a", 1.0, Range::positive()); }), "r.yaml: key 'a' must be > 0, got -0.2");
  EXPECT_EQ(message([&] { r.root().get("b", std::vector<int>{}, Range::at_least(1)); }),
            "r.yaml: key 'b' must hold numbers >= 1, got 0");
  EXPECT_EQ(r.root().get("c", 1.0, Range::open_closed(0, 1)), 0.5);
  EXPECT_EQ(message([&] { r.root().choice("d", "tanh", {"tanh", "elu"}); }),
            "r.yaml: key 'd' must be one of tanh, elu, got 'relu'");
  // A default is the code's own: NaN may stand for "not set" outside any range.
  EXPECT_TRUE(std::isnan(r.root().get("e", double(NAN), Range::any())));
  const auto& rules = r.key_rules();
  EXPECT_EQ(rules.at("c").type, "a number");
  EXPECT_EQ(rules.at("c").accepts, "in (0, 1]");
  EXPECT_EQ(rules.at("e").accepts, "any");
  EXPECT_EQ(rules.at("d").accepts, "one of tanh, elu");
}

TEST(Recipe, WrongTypeAndMalformedYaml) {
  Recipe r = Recipe::parse("ppo: {epochs: many, lr: [1, 2]}\n", "r.yaml");
  try {
    r.root().sub("ppo").get("epochs", 10);
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "r.yaml: key 'ppo.epochs' expects an integer, got 'many'");
  }
  EXPECT_THROW(r.root().sub("ppo").get("lr", 1.0), Error);
  EXPECT_THROW(r.root().sub("ppo").get("epochs", 1.5) /* 'many' is not a number either */, Error);
  try {
    Recipe::parse("ppo: {lr: 1\n  bad", "m.yaml");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("m.yaml: malformed YAML at line", 0), 0u) << e.what();
  }
  EXPECT_THROW(Recipe::load("/nonexistent/recipe.yaml"), Error);
  // A key must be a plain name, in the file and in --set values (a crash the fuzzer found).
  for (const auto& [text, set] : std::vector<std::pair<std::string, std::string>>{
           {"ppo:\n  ? [1, 2]\n  : 3\n", ""}, {"{}", "ppo={? [1]: 2}"}}) {
    try {
      Recipe::parse(text, "k.yaml", set.empty() ? std::vector<std::string>{} : std::vector<std::string>{set});
      ADD_FAILURE() << text << set;
    } catch (const Error& e) {
      EXPECT_STREQ(e.what(), "k.yaml: a key under 'ppo' is not a plain name");
    }
  }
  // A node that holds itself through an alias is refused, naming where the loop closes
  // (every reader followed it until the stack ran out; found by the fuzzer in CI).
  for (const auto& [text, set, where] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"env: &x {push: *x}\n", "", "env.push"},
           {"stages: &s [{ppo: {lr: 1}}, *s]\n", "", "stages.1"},
           {"{}", "ppo=&x {a: [*x]}", "ppo.a.0"}}) {
    try {
      Recipe::parse(text, "c.yaml", set.empty() ? std::vector<std::string>{} : std::vector<std::string>{set});
      ADD_FAILURE() << text << set;
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()), "c.yaml: key '" + where + "' holds itself through a YAML alias");
    }
  }
  // Aliases of aliases multiply a few lines into 10^6 values: refused, not walked for minutes.
  std::string bomb = "l0: &l0 [1, 1, 1, 1, 1, 1, 1, 1, 1, 1]\n";
  for (int i = 1; i <= 6; ++i) {
    const std::string a = "*l" + std::to_string(i - 1);
    bomb += "l" + std::to_string(i) + ": &l" + std::to_string(i) + " [" + a;
    for (int j = 1; j < 10; ++j) bomb += ", " + a;
    bomb += "]\n";
  }
  try {
    Recipe::parse(bomb, "b.yaml");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "b.yaml: more than 100000 values once its aliases are expanded");
  }
  // --set into a list item that is not a section makes it one, as for a key's value
  // (it threw yaml-cpp's own exception; found by the fuzzer).
  Recipe item = Recipe::parse("stages: [plain]\n", "i.yaml", {"stages.0.ppo.lr=2e-4"});
  EXPECT_EQ(item.root().items("stages").at(0).sub("ppo").get("lr", 1.0), 2e-4);
  // A number too long for a list index is a key, never a list padded to it or an overflow.
  for (const std::string set : {"stages.99999999999999999999.ppo.lr=1", "stages.100000000.ppo.lr=1"}) {
    Recipe r = Recipe::parse("stages: [{ppo: {lr: 2}}]\n", "n.yaml", {set});
    EXPECT_FALSE(r.root().is_sequence("stages")) << set;  // now a section keyed 0 and the number
    EXPECT_EQ(r.root().sub("stages").sub(set.substr(7, set.find(".ppo") - 7)).sub("ppo").get("lr", 0.0), 1.0);
  }
  // A plain alias (the same settings used twice) still reads at both places.
  Recipe shared = Recipe::parse("a: &x {lr: 0.5}\nb: *x\n", "s.yaml");
  EXPECT_EQ(shared.root().sub("b").get("lr", 1.0), 0.5);
  EXPECT_EQ(shared.root().sub("a").get("lr", 1.0), 0.5);
  EXPECT_THROW(Recipe::parse("{}", "r", {"no_equals_sign"}), Error);
}

// The segue binary: each bad input gives exit code 1 and one "error: ..." line.
CliRun run(const std::string& args) { return run_cli(args); }

class CliErrors : public TempDirTest {
 protected:
  CliErrors() : TempDirTest("cli") {}
  std::string write(const std::string& name, const std::string& text) {
    auto p = path(name);
    std::ofstream(p) << text;
    return p;
  }
  void expect_one_line_error(const CliRun& r, const std::string& needle) {
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_EQ(r.output.rfind("error: ", 0), 0u) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos) << r.output;
  }
};

TEST_F(CliErrors, BadRecipes) {
  auto bad_yaml = write("bad.yaml", "task: walker_forward\nppo: {lr: 1\n");
  expect_one_line_error(run("train " + bad_yaml), "bad.yaml: malformed YAML");
  auto unknown = write("unknown.yaml", "task: walker_forward\nppo: {learning_rate: 0.1}\n");
  expect_one_line_error(run("train " + unknown), "unknown key 'ppo.learning_rate'");
  auto wrong = write("wrong.yaml", "task: walker_forward\nppo: {epochs: ten}\n");
  expect_one_line_error(run("train " + wrong), "key 'ppo.epochs' expects an integer, got 'ten'");
  auto task = write("task.yaml", "task: walker_sideways\n");
  expect_one_line_error(run("train " + task), "key 'task': unknown task 'walker_sideways'");
  expect_one_line_error(run("train " + (dir_ / "missing.yaml").string()), "missing.yaml: cannot read recipe");
  auto ok = write("ok.yaml", "task: walker_forward\n");
  expect_one_line_error(run("train " + ok + " --set ppo.lrr=1"), "unknown key 'ppo.lrr' (from --set)");
  auto close = write("close.yaml", "task: walker_jump\nenv: {curbs: 2, curb_spacing: 3}\n");
  expect_one_line_error(run("train " + close),
                        "close.yaml: key 'env.curb_spacing': must exceed 2 curb_noise + curb_width so curbs do not overlap");
  auto kinds = write("kinds.yaml", "task: hurdle\nenv: {kinds: [curb]}\n");
  expect_one_line_error(run("train " + kinds), "kinds.yaml: key 'env.kinds': needs one entry per position (5)");
  auto std_alone = write("std.yaml", "task: walker_forward\ninit_log_std: -1\n");
  expect_one_line_error(run("train " + std_alone), "key 'init_log_std': applies to a run that starts from init_from");
  auto restart = write("restart.yaml", "task: walker_forward\nrestart_lr_schedule: true\n");
  expect_one_line_error(run("train " + restart), "key 'restart_lr_schedule': applies to a run that starts from init_from");
  auto both = write("both.yaml", "task: walker_jump\ninit_from: a.pt\ninit_policy: b.pt\n");
  expect_one_line_error(run("train " + both), "key 'init_policy': a run starts from init_from or init_policy, not both");
  const std::string in_tmp = "run_dir: " + (dir_ / "start_run").string() + "\n";
  auto nowhere = write("nowhere.yaml", "task: walker_jump\ninit_policy: nowhere.pt\n" + in_tmp);
  expect_one_line_error(run("train " + nowhere), "nowhere.yaml: key 'init_policy': no such policy 'nowhere.pt'");
  EXPECT_FALSE(std::filesystem::exists(dir_ / "start_run")) << "a refused start left its run directory";
  auto wider = write("wider.yaml", "task: walker_forward\ninit_policy: assets/policies/walker/walker_jump.pt\n" + in_tmp);
  expect_one_line_error(run("train " + wider), "key 'init_policy': 'assets/policies/walker/walker_jump.pt': policy takes obs_dim 28");
  auto ignore = write("ignore.yaml", "task: walker_forward\npolicy: {ignore_obs: [17, 30]}\n");
  expect_one_line_error(run("train " + ignore), "key 'policy.ignore_obs': must be [begin, end) with 0 <= begin < end <= 26");
  auto fourier = write("fourier.yaml", "task: walker_jump\npolicy: {fourier: {inputs: [28], periods: [1.9]}}\n");
  expect_one_line_error(run("train " + fourier), "key 'policy.fourier.inputs': must be observation indices in [0, 28)");
  auto period = write("period.yaml", "task: walker_jump\npolicy: {fourier: {inputs: [26], periods: [0]}}\n");
  expect_one_line_error(run("train " + period), "key 'policy.fourier.periods' must hold numbers > 0, got 0");
  auto lead = write("lead.yaml", "task: walker_jump\nlead_in: {policy: nowhere.pt, when: {curb_ahead: [3, 4]}}\n");
  expect_one_line_error(run("train " + lead), "lead.yaml: key 'lead_in.policy': no such policy 'nowhere.pt'");
  expect_one_line_error(run("train " + lead + " --set lead_in.policy=assets/policies/walker/walker_forward.pt"
                                              " --set 'lead_in.when={hurdle_ahead: [3, 4]}'"),
                        "key 'lead_in.when.hurdle_ahead': the task has no feature 'hurdle_ahead' (features: curb_ahead, curb_behind)");
  auto arm = write("arm.yaml", "task: jaco_pick\nenv: {curb_x: 3}\n");
  expect_one_line_error(run("train " + arm), "arm.yaml: unknown key 'env.curb_x'");
  auto hold = write("hold.yaml", "task: jaco_catch\nenv: {hold_target: [1, 2]}\n");
  expect_one_line_error(run("train " + hold), "key 'env.hold_target': must be a list of 3 numbers");
  // Stages are all checked before the first runs: a bad key in the second stops the first.
  const std::string tiny_run = "run_dir: " + (dir_ / "staged").string() + "\n";
  auto staged = write("staged.yaml", "task: walker_forward\n" + tiny_run +
                                         "stages:\n  - {name: a}\n  - {name: b, ppo: {lrr: 1}}\n");
  expect_one_line_error(run("train " + staged), "staged.yaml (stage b): unknown key 'ppo.lrr'");
  EXPECT_FALSE(std::filesystem::exists(dir_ / "staged" / "1-a")) << "stage a ran";
  auto unnamed = write("unnamed.yaml", "task: walker_forward\nstages:\n  - {ppo: {lr: 1}}\n");
  expect_one_line_error(run("train " + unnamed), "key 'stages.0.name' is required");
  auto twice = write("twice.yaml", "task: walker_forward\nstages:\n  - {name: a}\n  - {name: a}\n");
  expect_one_line_error(run("train " + twice), "key 'stages.1.name' repeats the stage name 'a'");
  auto how = write("how.yaml", "task: walker_forward\nstages:\n  - {name: a}\n  - {name: b, continue: weights}\n");
  expect_one_line_error(run("train " + how), "key 'stages.1.continue' must be 'checkpoint' or 'policy'");
  auto curbs = write("curbs.yaml", "task: walker_jump\nenv: {curbs: 0}\n");
  expect_one_line_error(run("train " + curbs), "key 'env.curbs' must be >= 1, got 0");
  // A composite recipe's transition and switch keys are checked when it is read.
  const std::string patrol = "eval --task patrol --method tp --episodes 1 --recipe " + std::string(SEGUE_SOURCE_DIR) +
                             "/experiments/patrol.yaml --set ";
  expect_one_line_error(run(patrol + "switch.validation_starts=-1"), "key 'switch.validation_starts' must be >= 0, got -1");
  expect_one_line_error(run(patrol + "'switch.margins=[]'"), "key 'switch.margins': lists no margin");
  expect_one_line_error(run(patrol + "switch.gamma=1.5"), "key 'switch.gamma' must be in (0, 1], got 1.5");
  expect_one_line_error(run(patrol + "transition.discriminator.steps=-1"),
                        "key 'transition.discriminator.steps' must be >= 0, got -1");
  expect_one_line_error(run(patrol + "transitions.0.max_steps=0"), "key 'transitions.0.max_steps' must be > 0, got 0");
}

TEST_F(CliErrors, NonsenseRefusedBeforeWork) {
  // Checks that hold for every key of their kind, not case by case: numbers must be finite,
  // a key must have a value, a key may be given once, layer widths are positive.
  auto ok = write("ok.yaml", "task: walker_forward\n");
  expect_one_line_error(run("train " + ok + " --set env.push_prob=.nan"), "key 'env.push_prob' must be a finite number, got .nan");
  expect_one_line_error(run("train " + ok + " --set ppo.lr=.inf"), "key 'ppo.lr' must be a finite number, got .inf");
  expect_one_line_error(run("train " + ok + " --set ppo.total_steps="), "key 'ppo.total_steps' has no value");
  expect_one_line_error(run("train " + ok + " --set .ppo.total_steps=8192"), "'.ppo.total_steps' is not a key");
  auto twice = write("dup.yaml", "task: walker_forward\nppo: {lr: 0.1}\nppo: {lr: 0.2}\n");
  expect_one_line_error(run("train " + twice), "dup.yaml: key 'ppo' is given twice");
  expect_one_line_error(run("train " + ok + " --set 'policy.pi_hidden=[32, 0]'"),
                        "key 'policy.pi_hidden' must hold numbers >= 1, got 0");
  expect_one_line_error(run("train " + ok + " --set ppo.total_steps=0"), "key 'ppo.total_steps' must be > 0, got 0");
  expect_one_line_error(run("train " + ok + " --set ppo.num_envs=100000000"), "key 'ppo.num_envs' must be in [1, 4096], got 100000000");
  expect_one_line_error(run("train " + ok + " --set ppo.clip=-0.2"), "key 'ppo.clip' must be > 0, got -0.2");
  expect_one_line_error(run("train " + ok + " --set ppo.num_envs=2 --set ppo.steps_per_env=64"),
                        "key 'ppo.minibatch_size': 2048 is larger than a rollout (num_envs x steps_per_env = 128)");
  expect_one_line_error(run("train " + ok + " --set threads=-3"), "key 'threads' must be in [0, 1024], got -3");
  expect_one_line_error(run("train " + ok + " --set eval.episodes=0"), "key 'eval.episodes' must be > 0, got 0");
  const std::string serve = "eval --task serve --method tp --episodes 1 --recipe " + std::string(SEGUE_SOURCE_DIR) +
                            "/experiments/serve.yaml --set ";
  // Policy files: each failure names the key that gave the file.
  const std::string tiny = " --set run_dir=" + path("from_run") + " --set ppo.total_steps=2048";
  expect_one_line_error(run("train " + ok + tiny + " --set init_from=assets/policies/walker/walker_forward.pt"),
                        "walker_forward.pt: not a training checkpoint");
  EXPECT_FALSE(std::filesystem::exists(dir_ / "from_run")) << "a refused start left its run directory";
  auto garbage = write("garbage.pt", "not a policy\n");
  expect_one_line_error(run("train " + ok + tiny + " --set init_policy=" + garbage),
                        "key 'init_policy': " + garbage + ": not a TorchScript policy");
  expect_one_line_error(run("eval --task serve --method single --episodes 1 --set methods.single.policy=" + garbage),
                        "key 'methods.single.policy': " + garbage + ": not a TorchScript policy");
  // Flags and commands: the same one line and exit code 1.
  const std::string forward = " " + std::string(SEGUE_SOURCE_DIR) + "/assets/policies/walker/walker_forward.pt --task walker_forward";
  expect_one_line_error(run("eval" + forward + " --seed -1"), "segue eval: --seed must be >= 0, got -1");
  expect_one_line_error(run("eval" + forward + " --threads 100000"), "segue eval: --threads must be in [0, 1024], got 100000");
  expect_one_line_error(run("render" + forward + " --out " + path("missing/x.mp4")),
                        "segue render: --out " + path("missing/x.mp4") + ": no folder");
  expect_one_line_error(run("nosuchcommand"), "unknown command 'nosuchcommand' (commands: train, run,");
  expect_one_line_error(run("plot " + dir_.string()), "neither metrics.csv nor */transition.csv");
  // Settings the model cannot hold, found when the task is built.
  auto jump = write("jump.yaml", "task: walker_jump\n");
  expect_one_line_error(run("train " + jump + " --check --set env.curbs=100"),
                        "jump.yaml: key 'env': walker_jump: env.curbs asks for 100 curbs and 0 ceilings");
  expect_one_line_error(run("train " + ok + " --set policy.activation=elu"),
                        "key 'policy.activation' must be one of tanh, relu, got 'elu'");
  expect_one_line_error(run(serve + "'switch.hidden=[0]'"), "key 'switch.hidden' must hold numbers >= 1, got 0");
  expect_one_line_error(run(serve + "'eval.seeds=[]'"), "key 'eval.seeds': lists no seed");
  expect_one_line_error(run(serve + "'transitions=[]'"), "key 'transitions': lists no transition");
  expect_one_line_error(run(serve + "'transitions.1={from: toss, to: hit}'"),
                        "key 'transitions.1.to': a second transition toss -> hit");
  expect_one_line_error(run(serve + "'transitions.0.when.since_release=[.nan, 4]'"),
                        "key 'transitions.0.when.since_release' must hold finite numbers, got .nan");
  expect_one_line_error(run(serve + "'transition.policy.pi_hidden=[32, 32]'"),
                        "key 'transition.policy.pi_hidden': [32, 32], but pi_ab starts as skill 'hit' (init_from_next), "
                        "whose hidden layers are [64, 64]");
}

TEST(MuJoCo, ItsErrorsBecomeSegueErrors) {
  // MuJoCo's default handler would print "Press Enter to exit" and wait on stdin.
  install_mujoco_handlers();
  try {
    mju_error("a test error");
    ADD_FAILURE() << "mju_error returned";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), "MuJoCo: a test error");
  }
}

TEST_F(CliErrors, BadPoliciesAndFlags) {
  auto junk = write("junk.pt", "garbage");
  expect_one_line_error(run("eval " + junk + " --task walker_forward --episodes 1"), "junk.pt");
  expect_one_line_error(run("eval " + (dir_ / "nope.pt").string() + " --task walker_forward"),
                        "nope.pt: no such policy file");
  expect_one_line_error(run("eval x.pt --task walker_forward --episodes two"), "--episodes expects an integer");
  expect_one_line_error(run("eval x.pt --task walker_forward --bogus"), "unknown flag --bogus");
  // A walker skill on the arm.
  expect_one_line_error(run("eval " + std::string(SEGUE_SOURCE_DIR) + "/assets/policies/walker/walker_forward.pt"
                            " --task jaco_pick --episodes 1"),
                        "policy takes obs_dim 26 / act_dim 6, but task 'jaco_pick' has obs_dim 49 / act_dim 9");
  EXPECT_EQ(run("train --help").code, 0);
}

}  // namespace segue
