// segue bench: throughput on the walker, in physics steps per second so every number is
// comparable with mujoco-testspeed (Debian's libmujoco-samples) on the same XML.
#include <mujoco/mujoco.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <regex>

#include "algorithms/skill_recipe.h"
#include "core/assets.h"
#include "core/mujoco_env.h"
#include "core/rng.h"
#include "core/thread_pool.h"
#include "tools/segue/cli.h"

namespace segue::cli {
namespace {

const Command kBench{
    "bench",
    "[--json] [--recipe FILE] [--iterations K]",
    "Measures on the walker model, in physics steps per second: mujoco-testspeed, our raw\n"
    "physics loop, rollouts with policy inference, and the full PPO loop (rollout and\n"
    "update), single-threaded and on every core, with the recipe's PPO settings. Every\n"
    "mj_step counts, episode resets included.",
    {},
    {{"json", "", "print one JSON object"},
     {"recipe", "FILE", "skill recipe whose settings to use (default experiments/primitives/walker_forward.yaml)"},
     {"iterations", "K", "PPO iterations per measurement (default 5)"},
     {"steps", "N", "physics steps for the raw measurements (default 100000)"}}};

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// mujoco-testspeed MODEL NSTEP 1 0.01, parsed from its "Steps per second" line.
double testspeed(const std::string& xml, int steps) {
  std::string cmd = "mujoco-testspeed '" + xml + "' " + std::to_string(steps) + " 1 0.01 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return NAN;
  std::string out;
  char buf[512];
  while (fgets(buf, sizeof buf, p)) out += buf;
  pclose(p);
  std::smatch m;
  if (std::regex_search(out, m, std::regex("Steps per second\\s*:\\s*([0-9.]+)"))) return std::stod(m[1]);
  return NAN;
}

// The same loop testspeed runs (mj_step with control noise), through our model loading.
double physics(const std::string& xml, int steps) {
  char err[1000] = "";
  mjModel* m = mj_loadXML(xml.c_str(), nullptr, err, sizeof err);
  if (!m) throw Error(xml + ": " + err);
  mjData* d = mj_makeData(m);
  Rng rng(1);
  auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) {
    for (int j = 0; j < m->nu; ++j) d->ctrl[j] = 0.01 * rng.normal();
    mj_step(m, d);
  }
  double sps = steps / seconds_since(t0);
  mj_deleteData(d);
  mj_deleteModel(m);
  return sps;
}

struct LoopRates {
  double rollout, ppo;
};

// Every mj_step the environments ran, episode resets included.
int64_t physics_steps(VectorEnv& envs) {
  int64_t n = 0;
  for (int i = 0; i < envs.size(); ++i) n += dynamic_cast<MujocoEnv&>(envs.env(i)).physics_steps();
  return n;
}

LoopRates loop_rates(const SkillRecipe& s, int threads, int iterations) {
  set_torch_threads(1);  // as segue train: environments get the threads, LibTorch one
  VectorEnv envs(s.make_env, s.ppo.num_envs, threads);
  PPO ppo(s.ppo, s.net, envs, s.seed);
  IterationStats warm;
  ppo.collect_rollout(warm);  // first-touch allocations and caches
  int64_t n0 = physics_steps(envs);
  auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < iterations; ++i) {
    IterationStats st;
    ppo.collect_rollout(st);
  }
  double rollout = (physics_steps(envs) - n0) / seconds_since(t0);
  n0 = physics_steps(envs);
  t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < iterations; ++i) ppo.iterate();
  double full = (physics_steps(envs) - n0) / seconds_since(t0);
  return {rollout, full};
}

}  // namespace

int bench_main(int argc, char** argv) {
  Args args(kBench, argc, argv);
  if (args.help()) return print_help(kBench);
  std::string recipe_path = args.get("recipe", std::string(SEGUE_SOURCE_DIR) + "/experiments/primitives/walker_forward.yaml");
  const int iterations = args.get_int("iterations", 5), steps = args.get_int("steps", 100000);
  if (iterations <= 0 || steps <= 0) throw Error("segue bench: --iterations and --steps must be positive");
  Recipe recipe = Recipe::load(recipe_path);
  SkillRecipe s = SkillRecipe::read(recipe, "runs/bench");
  recipe.reject_unknown();
  const std::string xml = asset_path("walker/walker.xml");
  const int cores = resolve_threads(0);

  double ts = testspeed(xml, steps);
  set_torch_threads(1);
  double ph = physics(xml, steps);
  LoopRates one = loop_rates(s, 1, iterations);
  LoopRates all = loop_rates(s, cores, iterations);

  if (args.has("json")) {
    std::printf("%s\n", json_object({{"testspeed_sps", ts},
                                     {"physics_sps", ph},
                                     {"rollout_sps", one.rollout},
                                     {"ppo_sps", one.ppo},
                                     {"rollout_sps_all_cores", all.rollout},
                                     {"ppo_sps_all_cores", all.ppo},
                                     {"cores", double(cores)}})
                            .c_str());
  } else {
    std::printf("walker (%s), physics steps per second; recipe %s\n", xml.c_str(), recipe_path.c_str());
    std::printf("  mujoco-testspeed (1 thread)   %10.0f\n", ts);
    std::printf("  segue raw physics (1 thread)  %10.0f  %5.1f%% of testspeed\n", ph, 100 * ph / ts);
    std::printf("  rollout + inference (1 thr)   %10.0f  %5.1f%%  (target >= 85%%)\n", one.rollout, 100 * one.rollout / ts);
    std::printf("  full PPO loop (1 thread)      %10.0f  %5.1f%%  (target >= 50%%)\n", one.ppo, 100 * one.ppo / ts);
    std::printf("  rollout, %d cores             %10.0f  %5.2fx one core\n", cores, all.rollout, all.rollout / one.rollout);
    std::printf("  full PPO loop, %d cores       %10.0f  %5.2fx one core  (target >= 1.7x)\n", cores, all.ppo, all.ppo / one.ppo);
  }
  return 0;
}

}  // namespace segue::cli
