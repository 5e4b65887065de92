#pragma once
// The console progress line: steps (or another unit: episodes), rate, recent return, ETA. Redrawn in place on a
// terminal, printed as plain lines (at most every few seconds) into logs.
//
// A job of several parts (`segue run`: collection, training and evaluation per transition; a curriculum's
// stages) keeps a JobPlan: each part's expected seconds from the caller's cost model, rescaled by how long
// the parts take on this machine (one twice as slow doubles the ETA after its first minutes). While a
// JobPlan lives, every Progress line feeds it and ends with the whole job's ETA.
#include <algorithm>
#include <chrono>
#include <functional>
#include <string>
#include <vector>

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

class JobPlan {
 public:
  using Clock = std::function<double()>;  // seconds
  explicit JobPlan(Clock now = steady_seconds);  // becomes the current plan (one at a time)
  ~JobPlan();
  JobPlan(const JobPlan&) = delete;
  JobPlan& operator=(const JobPlan&) = delete;

  // A part expected to take `seconds` on the machine the cost model was measured on, run as `pieces`
  // Progress lines of equal weight (evaluation: one per method and seed).
  void add(std::string part, double seconds, int pieces = 1);
  void begin(const std::string& part);  // starts it; the part running before is finished
  void skip(const std::string& part);   // done already: costs nothing
  void end();                           // finishes the running part
  // From the running part's Progress: a line began; the fraction of its piece done, the fraction it
  // started at (a resumed stage), and the line's own ETA (NaN: not known yet).
  void piece_began();
  void report(double fraction, double start_fraction, double piece_eta);

  double elapsed_seconds() const;
  double eta_seconds() const;  // NaN until something has run
  // "41m12s so far, ETA ~1h20m"
  std::string summary() const;
  static JobPlan* current();
  static double steady_seconds();

 private:
  enum class State { Pending, Running, Done, Skipped };
  struct Part {
    std::string name;
    double expected;
    int pieces;
    State state = State::Pending;
    double actual = 0, began = 0;      // seconds: taken (once done); job clock when it began
    int piece = -1;                    // the piece running (-1 before the first line)
    double piece_fraction = 0, start_fraction = 0, piece_eta = 0;
    double done() const { return piece >= pieces ? 1.0 : (std::max(0, piece) + piece_fraction) / pieces; }
  };
  Part& find(const std::string& part);
  double speed() const;  // seconds taken here per expected second
  std::vector<Part> parts_;
  int running_ = -1;
  Clock now_;
  double t0_;
};

std::string format_duration(double seconds);

}  // namespace segue
