#pragma once
// The walker among curbs and ceilings (assets/walker/walker_obstacles.xml). The model
// carries five of each, parked behind the start; a task lays out the ones it uses at
// reset. Obstacle observations follow the reference: (start - x, end - x) of the next
// obstacle, x the smallest x of torso and feet, or fixed "far" values when the next
// obstacle is beyond the detection distance. Here: that base (WalkerObstacleEnv) and the
// jump and crawl sub-tasks; the courses of several obstacles are walker_course.h.
#include <array>
#include <vector>

#include "environments/walker.h"

namespace segue {

enum class ObstacleKind { Curb = 1, Ceiling = 2 };

struct Obstacle {
  ObstacleKind kind;
  double start, end;  // x extent
};

struct ObstacleConfig {
  double detect_distance = 5.0;
  double curb_far_start = 5.1, curb_far_end = 5.2;
  double ceiling_far_start = 5.1, ceiling_far_end = 6.0;
  double pass_margin = 1.5;      // an obstacle counts as passed when x > end + pass_margin
  double ceiling_pass_margin = 1.5;  // for a ceiling (the reference code counts it at end + 0.15)
  double contact_penalty = 10.0; // reward on touching an obstacle (the episode ends)
  double curb_width = 0.2;       // curb thickness along x (the model's box is 0.2)
  double ceiling_length = 3.0;   // ceiling length in composite courses

  static ObstacleConfig read(const Section& env, ObstacleConfig defaults);
  static ObstacleConfig read(const Section& env) { return read(env, ObstacleConfig()); }
};

class WalkerObstacleEnv : public WalkerEnv {
 public:
  // observe_obstacle: append the (start - x, end - x) pair to the 26 base numbers.
  WalkerObstacleEnv(const std::string& name, const WalkerConfig& walker, const ObstacleConfig& obstacles,
                    bool observe_obstacle);

  const std::vector<Obstacle>& obstacles() const { return obstacles_; }
  // The first obstacle whose end is still ahead of x, or -1.
  int next_obstacle() const;
  int passed() const { return passed_; }
  // Any contact between the walker and an obstacle of that kind (0 = any kind).
  bool touching(int kind = 0) const;
  // The observation pair for the next obstacle (far values if none is near).
  void obstacle_observation(double& start, double& end) const;
  // The first obstacle whose start is still ahead of x, and the last whose end is behind
  // it (nullptr when there is none): what the tasks' features measure from.
  const Obstacle* obstacle_ahead() const;
  const Obstacle* obstacle_behind() const;
  // The sub-tasks' two features (a course's own are split by kind): metres from x to the
  // start of the obstacle ahead, and past the end of the one behind (kFar where none).
  void ahead_and_behind(double* out) const;
  static constexpr double kFar = 1e6;  // a feature's value when no obstacle is there
  // The three points of a curb crossing bonuses are paid at: its start, centre and end.
  static std::array<double, 3> curb_marks(const Obstacle& c) { return {c.start, 0.5 * (c.start + c.end), c.end}; }

 protected:
  // Moves the model's obstacle geoms to this layout; unused ones are parked.
  void set_obstacles(const std::vector<Obstacle>& layout);
  // Refuses, when the task is built, a layout that needs more obstacles than the model holds.
  void require_obstacles(size_t curbs, size_t ceilings, const std::string& key) const;
  // Resizes the index-th curb of the layout to this height (it stands on the floor).
  void set_curb_height(size_t index, double height);
  // Counts obstacles newly passed this step (in course order); returns how many.
  int update_passed();
  void observe(float* obs) const override;
  void save_task_state(std::vector<double>& out) const override;
  void restore_task_state(const double* in, size_t n) override;
  // Subclasses with state of their own extend these.
  virtual void save_extra(std::vector<double>& out) const {}
  virtual void restore_extra(const double* in, size_t n) {}

  ObstacleConfig ocfg_;
  std::vector<Obstacle> obstacles_;
  int passed_ = 0;

 private:
  bool observe_obstacle_;
  std::vector<int> curb_geoms_, ceiling_geoms_;
  std::vector<double> parked_pos_, parked_size_;  // [ngeom * 3] as in the XML
  std::vector<uint8_t> geom_kind_;                // ObstacleKind per geom, 0 for the rest
};

// Jump: one curb at curb_x + U(curb_noise); pass it without touching it. Training may
// lay out several curbs, curb_spacing apart, so an episode holds several jump attempts.
class WalkerJump : public WalkerObstacleEnv {
 public:
  struct Config {
    double curb_x = 7.0, curb_noise = 1.5;
    double cross_bonus = 10.0;  // once each for the trailing foot passing start, centre, end
    double upward_weight = 1.0; // + upward_weight max(vz, 0) while over the curb
    // The reference's height term, - height_weight |1.1 - delta_h|. delta_h is the torso's
    // height over the higher foot, so the term charges lifting either foot: it pays a
    // straight-legged, two-footed hop (the gait every reference-weighted run found) and
    // charges the alternating, knee-lifting steps a run-up to a jump is made of.
    double height_weight = 2.0;
    double end_x = 15.0;        // the episode ends past this x
    // Curb height, drawn per episode from [curb_height_min, curb_height]. The task is
    // the 0.4 m curb; a lower minimum is a curriculum that lets training find jumping
    // by first stepping over low curbs (a policy only ever meeting 0.4 m runs into it).
    double curb_height = 0.4, curb_height_min = 0.4;
    int curbs = 1;               // the task has one; more give more attempts per episode
    double curb_spacing = 8.0;   // nominal distance between successive curbs' starts
    // + mark_upward_weight clip(vz, -2, 2) once as the torso passes each curb's start,
    // centre and end (vz the torso's vertical speed): the reference's jump term, which
    // pays rising, and charges falling, at the moments that decide a clearance.
    double mark_upward_weight = 0.0;
    // false (training only): touching a curb costs contact_penalty each step instead of
    // ending the episode, and that curb's crossing bonuses are forfeit. A near miss then
    // still shows what follows a crossing, and a clean crossing is worth the bonuses more
    // than a touched one; the reference task ends on the first touch.
    bool contact_ends = true;
    // Reads `env`, refusing curbs laid out so close that they overlap.
    static Config read(const Section& env, const ObstacleConfig& obstacles);
  };
  WalkerJump(const std::string& name, const WalkerConfig& w, const ObstacleConfig& o, const Config& c);
  // Features, as Hurdle's: curb_ahead (metres from x to the next curb's start, far when
  // none) and curb_behind (metres past the last curb's end). A skill recipe's lead_in
  // reads them (hrl/lead_in.h).
  void features(double* out) const override { ahead_and_behind(out); }

 protected:
  void reset_task() override;
  StepResult evaluate(const float* action) override;
  void save_extra(std::vector<double>& out) const override;
  void restore_extra(const double* in, size_t n) override;

 private:
  Config jcfg_;
  int crossed_ = 0;              // marks (start, centre, end of each curb) the trailing foot has crossed
  uint32_t touched_ = 0;         // bit k: curb k was touched (only with contact_ends false)
  std::vector<double> heights_;  // per curb
};

// Crawl: survive under a long ceiling (x from ceiling_start to ceiling_end).
class WalkerCrawl : public WalkerObstacleEnv {
 public:
  struct Config {
    double ceiling_start = 2.0, ceiling_end = 14.0;
    // - crouch_weight |torso z - crouch_height|: the reference has no height term, and
    // without one PPO finds diving flat and dragging itself along (the torso then sits at
    // the 0.3 m fall line: 25-35% success from 5M to 11M steps). 0 = the reference reward.
    double crouch_weight = 0.0, crouch_height = 0.6;
    static Config read(const Section& env);
  };
  WalkerCrawl(const std::string& name, const WalkerConfig& w, const ObstacleConfig& o, const Config& c);

  // Features: ceiling_ahead and ceiling_behind (ahead_and_behind), as the Obstacle course
  // declares them, so that a lead-in can hand over to the crawl where that course does.
  void features(double* out) const override { ahead_and_behind(out); }

 protected:
  void reset_task() override;
  StepResult evaluate(const float* action) override;

 private:
  Config ccfg_;
};

}  // namespace segue
