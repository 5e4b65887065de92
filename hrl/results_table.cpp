#include "hrl/results_table.h"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/run_dir.h"

namespace segue {

const char* method_row_name(const std::string& m) {
  if (m == "single") return "Single";
  if (m == "without-tp") return "Without TP";
  if (m == "tp") return "With TP";
  if (m == "lee") return "Lee et al. 2019";
  if (m == "tp+q") return "With TP + Q";
  return m.c_str();
}

std::vector<std::pair<std::string, ControllerFactory>> available_methods(
    const CompositeRecipe& r, const std::vector<std::string>& wanted, bool skip_missing,
    std::vector<std::pair<std::string, std::string>>& skipped) {
  std::vector<std::pair<std::string, ControllerFactory>> methods;
  for (const auto& m : wanted) try {
      methods.push_back({m, method_controllers(r, m)});
    } catch (const Error& e) {
      if (!skip_missing) throw;
      std::fprintf(stderr, "skipping %s: %s\n", m.c_str(), e.what());
      std::string why = e.what();  // the table should not name this machine's paths
      const std::string tree = std::string(SEGUE_SOURCE_DIR) + "/";
      for (size_t at; (at = why.find(tree)) != std::string::npos;) why.erase(at, tree.size());
      skipped.push_back({m, why});
    }
  return methods;
}

std::vector<MethodResult> measure_methods(const CompositeRecipe& r,
                                          const std::vector<std::pair<std::string, ControllerFactory>>& methods,
                                          int threads) {
  std::vector<MethodResult> out;
  for (const auto& [name, controllers] : methods) {
    MethodResult m;
    m.method = name;
    std::vector<double> all;
    for (int seed : r.eval_seeds) {
      EvalResult e = evaluate(r.make_env, controllers, r.eval_episodes, uint64_t(seed), threads,
                              name + ", seed " + std::to_string(seed));
      Summary s = summarize(e.success_counts);
      m.seed_means.push_back(s.mean);
      m.seed_stds.push_back(s.std);
      all.insert(all.end(), e.success_counts.begin(), e.success_counts.end());
    }
    m.pooled = summarize(all);
    std::printf("%-16s %.2f +- %.2f\n", method_row_name(name), m.pooled.mean, m.pooled.std);
    std::fflush(stdout);
    out.push_back(m);
  }
  return out;
}

void write_results(const CompositeRecipe& r, const std::vector<MethodResult>& results,
                   const std::vector<std::pair<std::string, std::string>>& unmeasured, const std::string& command,
                   const std::string& dir) {
  auto list = [](const std::vector<double>& v) {
    std::ostringstream o;
    o.precision(6);
    for (size_t k = 0; k < v.size(); ++k) o << (k ? ", " : "") << v[k];
    return o.str();
  };
  std::ostringstream json, md;
  json.precision(6);
  json << "{\n";
  md << "# " << r.task << ": success count\n\n"
     << "Mean +- std of the success count over " << r.eval_episodes << " episodes for each of "
     << r.eval_seeds.size() << " evaluation seeds (pooled), with per-seed means. Without TP and With TP hand over "
     << (r.handover_point == HandOverPoint::Random
             ? "at a uniform random point of the interval, as the reference code evaluates them"
             : "as the interval begins and ends, as the paper's text says")
     << " (eval.handover_point).\n"
     << "Measured with `" << command << "` (recipe " << std::filesystem::path(r.file).filename().string()
     << ").\n\n| method | success count | per-seed means |\n|---|---|---|\n";
  std::vector<double> seeds(r.eval_seeds.begin(), r.eval_seeds.end());
  for (size_t i = 0; i < results.size(); ++i) {
    const MethodResult& m = results[i];
    json << "  \"" << m.method << "\": {\"mean\": " << m.pooled.mean << ", \"std\": " << m.pooled.std
         << ", \"per_seed_means\": [" << list(m.seed_means) << "], \"per_seed_stds\": [" << list(m.seed_stds)
         << "], \"episodes\": " << r.eval_episodes << ", \"seeds\": [" << list(seeds) << "]}"
         << (i + 1 < results.size() ? "," : "") << "\n";
    char cell[64];
    std::snprintf(cell, sizeof cell, "%.2f +- %.2f", m.pooled.mean, m.pooled.std);
    md << "| " << method_row_name(m.method) << " | " << cell << " | " << list(m.seed_means) << " |\n";
  }
  for (const auto& [name, why] : unmeasured) md << "| " << method_row_name(name) << " | not measured | " << why << " |\n";
  json << "}\n";
  std::filesystem::create_directories(dir);
  write_file_atomic(dir + "/" + r.task + ".json", json.str());
  write_file_atomic(dir + "/" + r.task + ".md", md.str());
}

}  // namespace segue
