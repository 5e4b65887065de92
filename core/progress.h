#pragma once
// The console progress line: steps (or another unit: generations), rate, recent return, ETA. Redrawn in place on a
// terminal, printed as plain lines (at most every few seconds) into logs.
#include <chrono>
#include <string>

namespace segue {

class Progress {
 public:
  Progress(std::string label, long total_steps, long start_steps = 0, std::string unit = "step");
  void update(long steps, double recent_return, double success_rate);
  void finish();
  ~Progress() { finish(); }  // a line left open on a terminal is closed

 private:
  std::string label_, unit_;
  long total_, start_;
  bool tty_, open_ = false;  // open_: a line drawn on the terminal and not yet ended
  std::chrono::steady_clock::time_point t0_, last_print_;
};

std::string format_duration(double seconds);

}  // namespace segue
