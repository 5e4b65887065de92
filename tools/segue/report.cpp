// segue report TASK: the paper's table row by row, measured. For each method, 50 episodes
// (recipe eval.episodes) for each evaluation seed; mean +- std of the success count over
// all of them, with per-seed means. Writes experiments/results/TASK.md and TASK.json.
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/run_dir.h"
#include "core/thread_pool.h"
#include "hrl/composite_recipe.h"
#include "tools/segue/cli.h"

namespace segue::cli {
namespace {

const Command kReport{
    "report",
    "TASK [--methods a,b] [--recipe FILE] [--out DIR]",
    "Evaluates methods of the paper on a composite task over the recipe's evaluation seeds\n"
    "and episodes, and writes DIR/TASK.md (a table in the paper's layout) and DIR/TASK.json\n"
    "(method -> mean, std, per_seed_means, per_seed_stds, episodes, seeds).",
    {"TASK"},
    {{"methods", "a,b", "methods to run (default: every method whose artefacts exist)"},
     {"recipe", "FILE", "composite recipe (default experiments/TASK.yaml)"},
     {"out", "DIR", "output folder (default experiments/results in the source tree)"},
     {"threads", "N", "threads stepping environments (default 0 = all cores)"}}};

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string p; std::getline(ss, p, ',');)
    if (!p.empty()) out.push_back(p);
  return out;
}

const char* row_name(const std::string& m) {
  if (m == "single") return "Single";
  if (m == "without-tp") return "Without TP";
  if (m == "tp") return "With TP";
  if (m == "lee") return "Lee et al. 2019";
  return "With TP + Q";
}

}  // namespace

int report_main(int argc, char** argv) {
  Args args(kReport, argc, argv);
  if (args.help()) return print_help(kReport);
  const std::string task = args.positional(0);
  CompositeRecipe r = CompositeRecipe::load(args.get("recipe", CompositeRecipe::default_file(task)));
  const int threads = resolve_threads(args.get_int("threads", 0));
  set_torch_threads(1);
  std::vector<std::pair<std::string, ControllerFactory>> methods;
  std::vector<std::pair<std::string, std::string>> skipped;  // method, why
  if (args.has("methods")) {
    for (const auto& m : split(args.get("methods", ""))) methods.push_back({m, method_controllers(r, m)});
  } else {
    for (const auto& m : method_names()) try {
        methods.push_back({m, method_controllers(r, m)});
      } catch (const Error& e) {
        std::fprintf(stderr, "skipping %s: %s\n", m.c_str(), e.what());
        std::string why = e.what();  // the table should not name this machine's paths
        const std::string tree = std::string(SEGUE_SOURCE_DIR) + "/";
        for (size_t at; (at = why.find(tree)) != std::string::npos;) why.erase(at, tree.size());
        skipped.push_back({m, why});
      }
  }
  std::ostringstream json, md;
  json.precision(6);
  md.precision(3);
  json << "{\n";
  md << "# " << task << ": success count\n\n"
     << "Mean +- std of the success count over " << r.eval_episodes << " episodes for each of "
     << r.eval_seeds.size() << " evaluation seeds (pooled), with per-seed means.\n"
     << "Measured with `segue report " << task << "` (recipe " << std::filesystem::path(r.file).filename().string()
     << ").\n\n| method | success count | per-seed means |\n|---|---|---|\n";
  for (size_t i = 0; i < methods.size(); ++i) {
    const auto& [name, controllers] = methods[i];
    std::vector<double> all, seed_means, seed_stds;
    for (int seed : r.eval_seeds) {
      EvalResult e = evaluate(r.make_env, controllers, r.eval_episodes, uint64_t(seed), threads);
      Summary s = summarize(e.success_counts);
      seed_means.push_back(s.mean);
      seed_stds.push_back(s.std);
      all.insert(all.end(), e.success_counts.begin(), e.success_counts.end());
    }
    Summary s = summarize(all);
    auto list = [](const std::vector<double>& v) {
      std::ostringstream o;
      o.precision(6);
      for (size_t k = 0; k < v.size(); ++k) o << (k ? ", " : "") << v[k];
      return o.str();
    };
    std::vector<double> seeds(r.eval_seeds.begin(), r.eval_seeds.end());
    json << "  \"" << name << "\": {\"mean\": " << s.mean << ", \"std\": " << s.std
         << ", \"per_seed_means\": [" << list(seed_means) << "], \"per_seed_stds\": [" << list(seed_stds)
         << "], \"episodes\": " << r.eval_episodes << ", \"seeds\": [" << list(seeds) << "]}"
         << (i + 1 < methods.size() ? "," : "") << "\n";
    char cell[64];
    std::snprintf(cell, sizeof cell, "%.2f +- %.2f", s.mean, s.std);
    md << "| " << row_name(name) << " | " << cell << " | " << list(seed_means) << " |\n";
    std::printf("%-16s %s\n", row_name(name), cell);
  }
  for (const auto& [name, why] : skipped) md << "| " << row_name(name) << " | not measured | " << why << " |\n";
  json << "}\n";
  std::string out = args.get("out", std::string(SEGUE_SOURCE_DIR) + "/experiments/results");
  std::filesystem::create_directories(out);
  write_file_atomic(out + "/" + task + ".json", json.str());
  write_file_atomic(out + "/" + task + ".md", md.str());
  std::printf("wrote %s/%s.md and .json\n", out.c_str(), task.c_str());
  return 0;
}

}  // namespace segue::cli
