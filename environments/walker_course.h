#pragma once
// Hurdle and Obstacle course: the walker crosses a row of curbs and ceilings. Both are
// this one class with a different layout (recipe `env:` keys), as the reference describes
// (docs/reference/tasks.md#walker-tasks):
//   Hurdle:          curbs at 8, 18, ..., 48 (+ U(position_noise))
//   Obstacle course: 3 curbs and 2 ceilings in random order at 8, 19, ..., 52 (+ U(0.5))
// An obstacle counts when x is pass_margin past its end (a ceiling: ceiling_pass_margin).
// The episode ends on a fall, on touching an obstacle, or when every obstacle is passed.
#include "environments/walker_obstacles.h"

namespace segue {

class WalkerCourse : public WalkerObstacleEnv {
 public:
  struct Config {
    std::vector<double> positions;       // obstacle start x
    double position_noise = 0.5;         // + U(position_noise) each
    std::vector<std::string> kinds;      // "curb" or "ceiling" per obstacle
    bool shuffle = false;                // random order of `kinds` each episode
    double pass_bonus = 10.0;            // reward per obstacle passed
    // The reference code's Hurdle reward, which its Single baseline trains on (about 600
    // per curb with pass_bonus 200 and cross_bonus 200; docs/reference/tasks.md#hurdle):
    // the speed and height terms' weights (doubled there); once each as the trailing foot
    // (the reference's "rearmost foot", taken as the jump's) passes a curb's start, centre
    // and end, cross_bonus x 1/3, 2/3 and 1; and mark_upward_weight clip(vz, -2, 2) as the
    // torso passes each of them. Defaults: ours.
    double speed_weight = 1.0, height_weight = 1.0;
    // The height term's weight within ceiling_zone of a ceiling, where the crawl is low
    // (ours: none; the reference's Obstacle course reward charges it only there, at 2, and
    // height_weight 0 elsewhere).
    double ceiling_height_weight = 0.0;
    double cross_bonus = 0.0, mark_upward_weight = 0.0;
    double ceiling_zone = 3.0;           // within this of a ceiling, only a torso below
    double ceiling_fall_height = 0.3;    //   ceiling_fall_height is a fall (crawling is low)
    // Reads `env`, starting from `defaults` (Hurdle's or Obstacle course's layout).
    static Config read(const Section& env, Config defaults);
  };
  WalkerCourse(const std::string& name, const WalkerConfig& w, const ObstacleConfig& o, const Config& c);

  // Features: curb_ahead / ceiling_ahead (metres from x to the next obstacle's start when
  // it is of that kind, else "far"), curb_behind / ceiling_behind (metres past the end of
  // the last obstacle behind x when of that kind, else far), steps (since the episode
  // start) and distance (|torso x - its start x|).
  void features(double* out) const override;

 protected:
  void reset_task() override;
  StepResult evaluate(const float* action) override;

 private:
  bool near_ceiling() const;
  // cross_bonus and mark_upward_weight's terms earned this step.
  double mark_rewards();
  void save_extra(std::vector<double>& out) const override {
    out.push_back(start_x_);
    out.push_back(double(crossed_));
  }
  void restore_extra(const double* in, size_t n) override {
    start_x_ = n ? in[0] : 0.0;
    crossed_ = n > 1 ? uint32_t(in[1]) : 0u;
  }
  Config ccfg_;
  double start_x_ = 0.0;
  uint32_t crossed_ = 0;  // bit 3k + j: the trailing foot has passed mark j of obstacle k
  std::vector<ObstacleKind> kinds_;
};

}  // namespace segue
