#include "core/run_dir.h"

#include <fcntl.h>
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "core/distributed.h"
#include "core/error.h"

namespace fs = std::filesystem;

namespace segue {

namespace {
// Why a file could not be written, from errno: "the folder 'x' does not exist",
// "permission denied", ...
std::string write_failure(const std::string& path, int error) {
  const fs::path folder = fs::path(path).parent_path();
  std::error_code ec;
  if (error == ENOENT && !folder.empty() && !fs::exists(folder, ec))
    return "the folder '" + folder.string() + "' does not exist";
  if (error == ENOTDIR && !folder.empty() && fs::exists(folder, ec) && !fs::is_directory(folder, ec))
    return "'" + folder.string() + "' is not a folder";
  std::string why = std::strerror(error);
  if (!why.empty()) why[0] = char(std::tolower(static_cast<unsigned char>(why[0])));
  return why;
}
}  // namespace

void write_file_atomic(const std::string& path, const std::string& bytes) {
  std::string tmp = path + ".tmp";
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) {
    const int e = errno;
    throw Error(path + ": cannot write: " + write_failure(path, e));
  }
  size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n <= 0) {
      const int e = n < 0 ? errno : ENOSPC;
      ::close(fd);
      throw Error(path + ": write failed: " + write_failure(path, e));
    }
    done += size_t(n);
  }
  ::fsync(fd);
  ::close(fd);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    throw Error(path + ": cannot replace file: " + write_failure(path, e));
  }
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot read file");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

MetricsCsv::MetricsCsv(const std::string& path, const std::vector<std::string>& columns,
                       long keep_rows)
    : path_(path) {
  std::string header;
  for (size_t i = 0; i < columns.size(); ++i) header += (i ? "," : "") + columns[i];
  std::string kept = header + "\n";
  if (fs::exists(path) && keep_rows > 0) {
    std::ifstream in(path);
    std::string line;
    std::getline(in, line);  // old header
    for (long r = 0; r < keep_rows && std::getline(in, line); ++r) kept += line + "\n";
  }
  write_file_atomic(path, kept);
  out_.open(path, std::ios::app);
}

void MetricsCsv::write(const std::vector<double>& values) {
  for (size_t i = 0; i < values.size(); ++i) out_ << (i ? "," : "") << values[i];
  out_ << "\n";
  out_.flush();
}

namespace {
// Every leaf of a YAML tree by its dotted path ("ppo.lr", "policy.pi_hidden.0"), as text.
void flatten(const YAML::Node& node, const std::string& path, std::map<std::string, std::string>& out) {
  auto child = [&](const std::string& key) { return path.empty() ? key : path + "." + key; };
  if (node.IsMap()) {
    for (const auto& kv : node) flatten(kv.second, child(kv.first.Scalar()), out);
  } else if (node.IsSequence()) {
    for (size_t i = 0; i < node.size(); ++i) flatten(node[i], child(std::to_string(i)), out);
    if (node.size() == 0) out[path] = "[]";
  } else {
    out[path] = node.IsScalar() ? node.Scalar() : "~";
  }
}

std::map<std::string, std::string> leaves(const std::string& yaml, const std::string& file) {
  std::map<std::string, std::string> out;
  try {
    flatten(YAML::Load(yaml), "", out);
  } catch (const YAML::Exception& e) {
    throw Error(file + ": unreadable recipe (" + e.msg + ")");
  }
  out.erase("threads");  // the thread count does not change what a run computes
  return out;
}
}  // namespace

std::string recipe_difference(const std::string& a, const std::string& b, const std::string& file) {
  auto la = leaves(a, file), lb = leaves(b, file);
  for (const auto& [key, value] : la) {
    auto it = lb.find(key);
    if (it == lb.end() || it->second != value)
      return "key '" + key + "': " + value + " against " + (it == lb.end() ? "absent" : it->second);
  }
  for (const auto& [key, value] : lb)
    if (!la.count(key)) return "key '" + key + "': absent against " + value;
  return "";
}

namespace {
// Settings Segue no longer has, each with the value at which it left the computation alone.
// A run directory started before one was dropped records it: the run resumes where it had
// that value (the code computes what it did), and is refused, naming the key, where not.
const std::map<std::string, std::string>& retired_keys() {
  static const std::map<std::string, std::string> keys{
      {"ppo.noise_repeat", "1"}, {"trpo.noise_repeat", "1"}, {"transition.ppo.noise_repeat", "1"},
      {"switch.ensemble", "1"}, {"switch.interval_features", "false"},
      {"transition.discriminator.gradient_penalty", "0"},
      {"env.ghost_curbs", "false"}, {"env.ghost_depth_cost", "0"}, {"env.takeoff_bonus", "0"},
      {"env.close_stance_cost", "0"}, {"env.stance_height", "0.08"}, {"env.placement_bonus", "0"},
      {"env.placement_target", "-0.8"}, {"env.placement_width", "0.3"}, {"env.approach_speed", "0"},
      {"env.approach_from", "3"}, {"env.approach_to", "1.5"}, {"env.clearance_weight", "0"},
      {"env.clearance_before", "0.3"}, {"env.peak_weight", "0"}, {"env.center_weight", "0"},
      {"env.push_weight", "0"}};
  return keys;
}

bool same_value(const std::string& a, const std::string& b) {
  try {
    size_t na = 0, nb = 0;
    const double x = std::stod(a, &na), y = std::stod(b, &nb);
    if (na == a.size() && nb == b.size()) return x == y;
  } catch (const std::exception&) {
  }
  return a == b;
}
}  // namespace

RunDir::RunDir(const std::string& dir, const std::string& resolved,
               const std::set<std::string>& defaulted)
    : dir_(dir) {
  fs::create_directories(dir);
  std::string recipe = file("recipe.yaml");
  if (!fs::exists(recipe)) {
    write_file_atomic(recipe, resolved);
    return;
  }
  auto then = leaves(read_file(recipe), recipe), now = leaves(resolved, recipe);
  auto refuse = [&](const std::string& key, const std::string& was, const std::string& is) {
    return Error(recipe + ": this run directory was started with a different recipe (key '" + key +
                 "': " + was + " there, " + is + " now); choose another run_dir or remove the directory");
  };
  bool changed = false;
  for (const auto& [key, value] : then) {
    auto it = now.find(key);
    if (it == now.end()) {
      const auto retired = retired_keys().find(key);
      if (retired == retired_keys().end()) throw refuse(key, value, "absent");
      if (!same_value(value, retired->second))
        throw Error(recipe + ": this run directory was started with key '" + key + "': " + value +
                    ", a setting Segue no longer has (only runs at " + retired->second +
                    " resume); choose another run_dir or remove the directory");
      changed = true;  // dropped from the recorded recipe
      continue;
    }
    if (it->second != value) throw refuse(key, value, it->second);
  }
  for (const auto& [key, value] : now)
    if (!then.count(key)) {
      if (!defaulted.count(key)) throw refuse(key, "absent", value);
      changed = true;
    }
  if (changed) write_file_atomic(recipe, resolved);
}

bool RunDir::has_checkpoint() const { return fs::exists(checkpoint()); }

void require_same_recipe(const std::string& resolved, const std::string& file) {
  const Distributed& group = Distributed::world();
  if (group.single()) return;
  const std::string diff = recipe_difference(group.broadcast(resolved), resolved, file);
  const std::vector<std::string> all = group.gather(diff);
  for (size_t r = 0; r < all.size(); ++r)
    if (!all[r].empty())
      throw Error(file + ": rank " + std::to_string(r) + " was started with another recipe than rank 0 (" + all[r] + ")");
}

std::string json_object(const std::vector<std::pair<std::string, double>>& fields) {
  std::ostringstream o;
  o.precision(10);
  o << "{";
  for (size_t i = 0; i < fields.size(); ++i) {
    o << (i ? ", " : "") << "\"" << fields[i].first << "\": ";
    const double v = fields[i].second;
    if (!std::isfinite(v)) o << "null";
    else o << v;
  }
  o << "}";
  return o.str();
}

}  // namespace segue
