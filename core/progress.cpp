#include "core/progress.h"

#include <algorithm>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>

namespace segue {

std::string format_duration(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  char buf[32];
  long t = std::lround(s);
  if (t >= 3600) std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, (t / 60) % 60);
  else if (t >= 60) std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  else std::snprintf(buf, sizeof buf, "%lds", t);
  return buf;
}

Progress::Progress(std::string label, long total, long start, std::string unit)
    : label_(std::move(label)), unit_(std::move(unit)), total_(total), start_(start), tty_(isatty(STDERR_FILENO)),
      t0_(std::chrono::steady_clock::now()), last_print_(t0_) {}

void Progress::update(long steps, double ret, double success) {
  auto now = std::chrono::steady_clock::now();
  double since = std::chrono::duration<double>(now - last_print_).count();
  if (!tty_ && since < 5.0 && steps < total_) return;
  last_print_ = now;
  double elapsed = std::chrono::duration<double>(now - t0_).count();
  double sps = elapsed > 0 ? (steps - start_) / elapsed : 0.0;
  // The last rollout may overshoot the budget: the line ends at the budget, 100%.
  steps = std::min(steps, total_);
  double eta = steps >= total_ ? 0.0 : sps > 0 ? (total_ - steps) / sps : NAN;
  char rate[48];
  if (sps >= 10) std::snprintf(rate, sizeof rate, "%.0f %ss/s", sps, unit_.c_str());
  else std::snprintf(rate, sizeof rate, "%.1f %ss/min", 60 * sps, unit_.c_str());
  // Return and success where there are any (a collection has neither).
  char outcome[64] = "";
  if (std::isfinite(ret)) std::snprintf(outcome, sizeof outcome, "  return %.1f", ret);
  if (std::isfinite(success))
    std::snprintf(outcome + std::strlen(outcome), sizeof outcome - std::strlen(outcome), "  success %.0f%%",
                  100.0 * success);
  std::fprintf(stderr, "%s[%s] %s %ld/%ld (%.0f%%)  %s%s  ETA %s%s", tty_ ? "\r\033[K" : "", label_.c_str(),
               unit_.c_str(), steps, total_, 100.0 * steps / total_, rate, outcome, format_duration(eta).c_str(),
               tty_ ? "" : "\n");
  open_ = tty_;
  std::fflush(stderr);
}

void Progress::finish() {
  if (open_) std::fprintf(stderr, "\n");
  open_ = false;
}

}  // namespace segue
