#pragma once
// Runs the segue binary with `args` and returns its exit code and everything it printed
// (stdout and stderr together).
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

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

// `segue train FILE` in the background, all it prints discarded; returns its pid.
inline pid_t start_train(const std::string& file) {
  const pid_t pid = fork();
  if (pid == 0) {
    freopen("/dev/null", "w", stdout);
    freopen("/dev/null", "w", stderr);
    execl(SEGUE_BINARY, SEGUE_BINARY, "train", file.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

// The inode of `file`, 0 if there is none: write_file_atomic renames a new file in, so a
// checkpoint's inode changes with every checkpoint written.
inline ino_t inode(const std::string& file) {
  struct stat st {};
  return ::stat(file.c_str(), &st) == 0 ? st.st_ino : 0;
}

// Starts `segue train FILE` and kills it (SIGKILL) once it has written a checkpoint after
// the one at `checkpoint` now, i.e. in the rollout after it. False if the run ended first.
inline bool kill_after_next_checkpoint(const std::string& file, const std::string& checkpoint) {
  const ino_t before = inode(checkpoint);
  const pid_t pid = start_train(file);
  if (!wait_until(pid, [&] { return inode(checkpoint) != before && inode(checkpoint) != 0; })) return false;
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return true;
}

}  // namespace segue
