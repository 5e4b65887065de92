#include "core/progress.h"

#include <algorithm>
#include <atomic>

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
      t0_(std::chrono::steady_clock::now()), last_print_(t0_) {
  if (JobPlan* job = JobPlan::current()) job->piece_began();
}

void Progress::update(long steps, double ret, double success) {
  auto now = std::chrono::steady_clock::now();
  double elapsed = std::chrono::duration<double>(now - t0_).count();
  double sps = elapsed > 0 ? (steps - start_) / elapsed : 0.0;
  // The last rollout may overshoot the budget: the line ends at the budget, 100%.
  steps = std::min(steps, total_);
  double eta = steps >= total_ ? 0.0 : sps > 0 ? (total_ - steps) / sps : NAN;
  JobPlan* plan = JobPlan::current();
  if (plan) plan->report(total_ > 0 ? double(steps) / total_ : 1.0, total_ > 0 ? double(start_) / total_ : 0.0, eta);
  double since = std::chrono::duration<double>(now - last_print_).count();
  if (!tty_ && since < 5.0 && steps < total_) return;
  last_print_ = now;
  const std::string job = plan ? "  job ETA ~" + format_duration(plan->eta_seconds()) : "";
  char rate[48];
  if (sps >= 10) std::snprintf(rate, sizeof rate, "%.0f %ss/s", sps, unit_.c_str());
  else std::snprintf(rate, sizeof rate, "%.1f %ss/min", 60 * sps, unit_.c_str());
  // Return and success where there are any (a collection has neither).
  char outcome[64] = "";
  if (std::isfinite(ret)) std::snprintf(outcome, sizeof outcome, "  return %.1f", ret);
  if (std::isfinite(success))
    std::snprintf(outcome + std::strlen(outcome), sizeof outcome - std::strlen(outcome), "  success %.0f%%",
                  100.0 * success);
  std::fprintf(stderr, "%s[%s] %s %ld/%ld (%.0f%%)  %s%s  ETA %s%s%s", tty_ ? "\r\033[K" : "", label_.c_str(),
               unit_.c_str(), steps, total_, 100.0 * steps / total_, rate, outcome, format_duration(eta).c_str(),
               job.c_str(), tty_ ? "" : "\n");
  open_ = tty_;
  std::fflush(stderr);
}

void Progress::finish() {
  if (open_) std::fprintf(stderr, "\n");
  open_ = false;
}

namespace {
// One plan per process, fed from the thread that drives the job (Progress lines are too).
std::atomic<JobPlan*> current_plan{nullptr};
}

double JobPlan::steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

JobPlan::JobPlan(Clock now) : now_(std::move(now)), t0_(now_()) { current_plan = this; }
JobPlan::~JobPlan() {
  JobPlan* self = this;
  current_plan.compare_exchange_strong(self, nullptr);
}
JobPlan* JobPlan::current() { return current_plan.load(); }

void JobPlan::add(std::string part, double seconds, int pieces) {
  parts_.push_back({std::move(part), std::max(0.0, seconds), std::max(1, pieces)});
}

JobPlan::Part& JobPlan::find(const std::string& part) {
  for (Part& p : parts_)
    if (p.name == part) return p;
  add(part, 0.0);  // a part the plan did not foresee: it adds its time, not its estimate
  return parts_.back();
}

double JobPlan::elapsed_seconds() const { return now_() - t0_; }

void JobPlan::end() {
  if (running_ < 0) return;
  Part& p = parts_[size_t(running_)];
  p.state = State::Done;
  p.actual = elapsed_seconds() - p.began;
  p.expected *= 1.0 - p.start_fraction;  // a resumed part did only the rest of its work here
  running_ = -1;
}

void JobPlan::begin(const std::string& part) {
  end();
  Part& p = find(part);
  p.state = State::Running;
  p.began = elapsed_seconds();
  running_ = int(&p - parts_.data());
}

void JobPlan::skip(const std::string& part) { find(part).state = State::Skipped; }

void JobPlan::piece_began() {
  if (running_ < 0) return;
  Part& p = parts_[size_t(running_)];
  ++p.piece;  // lines past the planned pieces (a skill's closing evaluation) are not followed
  p.piece_fraction = 0, p.piece_eta = NAN;
}

void JobPlan::report(double fraction, double start_fraction, double piece_eta) {
  if (running_ < 0) return;
  Part& p = parts_[size_t(running_)];
  if (p.piece >= p.pieces) return;
  p.piece_fraction = std::clamp(fraction, 0.0, 1.0);
  if (p.piece <= 0 && p.pieces == 1) p.start_fraction = std::clamp(start_fraction, 0.0, 1.0);
  p.piece_eta = piece_eta;
}

double JobPlan::speed() const {
  double expected = 0, actual = 0, planned = 0;
  for (const Part& p : parts_) {
    if (p.state != State::Skipped) planned += p.expected;
    if (p.state == State::Done) expected += p.expected, actual += p.actual;
  }
  if (running_ >= 0) {
    const Part& p = parts_[size_t(running_)];
    expected += p.expected * std::max(0.0, p.done() - p.start_fraction);
    actual += elapsed_seconds() - p.began;
  }
  // Until a minute of the plan (a twentieth of a shorter one) has run here, the cost model's own figures.
  return expected >= std::min(60.0, planned / 20) && expected > 0 ? actual / expected : 1.0;
}

double JobPlan::eta_seconds() const {
  const double k = speed();
  double left = 0;
  for (const Part& p : parts_)
    if (p.state == State::Pending) left += p.expected * k;
  if (running_ >= 0 && parts_[size_t(running_)].piece < parts_[size_t(running_)].pieces) {
    const Part& p = parts_[size_t(running_)];
    const int piece = std::max(0, p.piece);
    const double rest_pieces = double(p.pieces - piece - 1) / p.pieces;
    // The running line's own ETA where it has one; it knows its rate better than the model.
    const double this_piece = std::isfinite(p.piece_eta) ? p.piece_eta
                                                        : p.expected / p.pieces * (1 - p.piece_fraction) * k;
    left += this_piece + p.expected * rest_pieces * k;
  }
  return left;
}

std::string JobPlan::summary() const {
  return format_duration(elapsed_seconds()) + " so far, ETA ~" + format_duration(eta_seconds());
}

}  // namespace segue
