#include "core/run_dir.h"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/error.h"

namespace fs = std::filesystem;

namespace segue {

void write_file_atomic(const std::string& path, const std::string& bytes) {
  std::string tmp = path + ".tmp";
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw Error(path + ": cannot write");
  size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n <= 0) {
      ::close(fd);
      throw Error(path + ": write failed (disk full?)");
    }
    done += size_t(n);
  }
  ::fsync(fd);
  ::close(fd);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw Error(path + ": cannot replace file");
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
// The recipe without its top-level `threads:` line: the thread count does not change
// what a run computes, so a run may resume with another one.
std::string without_threads(const std::string& yaml) {
  std::stringstream in(yaml);
  std::string out;
  for (std::string line; std::getline(in, line);)
    if (line.rfind("threads:", 0) != 0) out += line + "\n";
  return out;
}
}  // namespace

RunDir::RunDir(const std::string& dir, const std::string& resolved) : dir_(dir) {
  fs::create_directories(dir);
  std::string recipe = file("recipe.yaml");
  if (fs::exists(recipe)) {
    if (without_threads(read_file(recipe)) != without_threads(resolved))
      throw Error(recipe + ": this run directory was started with a different recipe; "
                  "choose another run_dir or remove the directory");
  } else {
    write_file_atomic(recipe, resolved);
  }
}

bool RunDir::has_checkpoint() const { return fs::exists(checkpoint()); }

}  // namespace segue
