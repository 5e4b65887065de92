#pragma once
// A run directory: the resolved recipe it was started with, metrics.csv (one row per
// iteration), and checkpoints. Files are replaced atomically (write, fsync, rename), so
// a run killed at any moment leaves either the old checkpoint or the new one.
#include <fstream>
#include <set>
#include <string>
#include <vector>

namespace segue {

// Writes `bytes` to `path` via a temporary file and rename().
void write_file_atomic(const std::string& path, const std::string& bytes);
std::string read_file(const std::string& path);

// Appends rows to a CSV whose header is fixed by the first call. On resume, rows past
// the checkpointed iteration are dropped so the file matches the restored state.
class MetricsCsv {
 public:
  MetricsCsv(const std::string& path, const std::vector<std::string>& columns, long keep_rows);
  void write(const std::vector<double>& values);

 private:
  std::string path_;
  std::ofstream out_;
};

// The first key (in dotted form, `threads` aside) whose value differs between two resolved
// recipes, as "key 'ppo.lr': A against B"; empty if they agree.
std::string recipe_difference(const std::string& a, const std::string& b, const std::string& file);
// With several ranks (Distributed::world()): every rank must run the same resolved recipe
// as rank 0; a difference is refused on every rank, naming the first key that differs.
void require_same_recipe(const std::string& resolved, const std::string& file);

// {"k": v, ...} with numbers printed to full precision (integers without decimals), and
// null for what is not finite.
std::string json_object(const std::vector<std::pair<std::string, double>>& fields);

class RunDir {
 public:
  // Opens or creates DIR. A DIR holding a different resolved recipe is refused, naming
  // the first key that differs. Two differences are let through: `threads`, which does
  // not change results; and a key the stored recipe lacks that `defaulted` holds, i.e. a
  // setting added to the code since the run started and left at its default (the old
  // behaviour). The run then resumes and the stored recipe is rewritten with the key.
  RunDir(const std::string& dir, const std::string& resolved_recipe,
         const std::set<std::string>& defaulted = {});
  const std::string& path() const { return dir_; }
  std::string file(const std::string& name) const { return dir_ + "/" + name; }
  std::string checkpoint() const { return file("checkpoint.pt"); }
  bool has_checkpoint() const;

 private:
  std::string dir_;
};

}  // namespace segue
