#pragma once
// Runs the segue binary with `args` and returns its exit code and everything it printed
// (stdout and stderr together).
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace segue {

struct CliRun {
  int code;
  std::string output;
};

inline CliRun run_cli(const std::string& args) {
  std::string cmd = std::string(SEGUE_BINARY) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  int status = pclose(p);
  return {WEXITSTATUS(status), out};
}

}  // namespace segue
