#pragma once
// Runs the segue binary with `args` and returns its exit code and everything it printed
// (stdout and stderr together).
#include <sys/wait.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>
#include <thread>

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

// Waits until `reached()` holds or the child `pid` exits, whichever comes first, and
// returns whether it is still running. Tests wait on a run's own progress (a metrics row,
// a checkpoint), never on the clock, so they pass on a machine of any speed. `status`
// receives the exit status where the child has ended.
inline bool wait_until(pid_t pid, const std::function<bool()>& reached, int* status = nullptr) {
  int st = 0;
  while (!reached()) {
    if (::waitpid(pid, &st, WNOHANG) == pid) {
      if (status) *status = st;
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));  // a poll, not a deadline
  }
  return true;
}

}  // namespace segue
