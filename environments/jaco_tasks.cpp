#include "environments/jaco_tasks.h"

#include <cmath>

namespace segue {
namespace {

constexpr double kFar = 1e6;  // a "steps since" feature before the event first happened

StepResult composite_result(double reward, bool failed, int successes, int goal) {
  StepResult r;
  r.reward = reward;
  r.info.success = successes >= goal;
  r.info.success_count = successes;
  r.terminated = failed || r.info.success;
  return r;
}

}  // namespace

// ---- Repetitive picking up ----------------------------------------------------------------

JacoRepetitivePick::Config JacoRepetitivePick::Config::read(const Section& env) {
  Config k;
  k.successes = env.get("successes", k.successes, Range::at_least(1));
  k.pick_steps = env.get("pick_steps", k.pick_steps, Range::at_least(1));
  k.unwind_arm = env.get("unwind_arm", k.unwind_arm);
  k.pick = PickRule::Config::read(env);
  return k;
}

JacoRepetitivePick::JacoRepetitivePick(const std::string& name, const JacoConfig& c, const Config& k)
    : JacoEnv(name, c, "jaco/jaco_box.xml", /*with_rotation=*/true), k_(k) {
  pick_.cfg = k.pick;
  spec_.feature_names.insert(spec_.feature_names.end(), {"successes", "since_success", "pick_steps"});
}

void JacoRepetitivePick::features(double* out) const {
  JacoEnv::features(out);
  out[2] = n_.successes, out[3] = n_.since_success, out[4] = n_.pick_t;
}

void JacoRepetitivePick::place_task_object() { pick_.place(*this, rng_); }

void JacoRepetitivePick::begin_task() {
  pick_.begin(*this);
  n_ = Count();
  n_.since_success = kFar;
}

StepResult JacoRepetitivePick::score(const float* action) {
  n_.pick_t += 1;
  n_.since_success = std::min(kFar, n_.since_success + 1);
  RuleStep rs = pick_.step(*this, int(n_.pick_t), k_.pick_steps);
  if (rs.success) {
    n_.successes += 1;
    n_.since_success = 0;
    n_.pick_t = 0;
    if (n_.successes < k_.successes) {
      // The next box, on the tile again. (The reference returns the observation from before
      // this; ours shows the new box, which is what the next pick, or pi_ab, works from.)
      pick_.place(*this, rng_);
      if (k_.unwind_arm) unwind_arm();
      mj_forward(model_, data_);
      pick_.begin(*this);
    }
  }
  const bool timed_out = !rs.success && n_.pick_t >= k_.pick_steps;
  return composite_result(control_cost(action) + rs.reward, rs.failed || timed_out, int(n_.successes), k_.successes);
}

void JacoRepetitivePick::save_task_state(std::vector<double>& out) const { append_state(out, pick_.s, n_); }
void JacoRepetitivePick::restore_task_state(const double* in, size_t n) {
  read_state(in, n, spec_.name, pick_.s, n_);
}

// ---- Repetitive catching ------------------------------------------------------------------

JacoRepetitiveCatch::Config JacoRepetitiveCatch::Config::read(const Section& env) {
  Config k;
  k.successes = env.get("successes", k.successes, Range::at_least(1));
  k.pin_steps = env.get("pin_steps", k.pin_steps, Range::non_negative());
  k.fall_steps = env.get("fall_steps", k.fall_steps, Range::non_negative());
  k.unwind_arm = env.get("unwind_arm", k.unwind_arm);
  k.catching = CatchRule::Config::read(env, /*hold_target=*/{0.0, 0.2, 0.2});
  return k;
}

JacoRepetitiveCatch::JacoRepetitiveCatch(const std::string& name, const JacoConfig& c, const Config& k)
    : JacoEnv(name, c, "jaco/jaco_box.xml", /*with_rotation=*/true), k_(k) {
  catch_.cfg = k.catching;
  spec_.feature_names.insert(spec_.feature_names.end(), {"successes", "since_success", "since_throw", "waiting"});
}

void JacoRepetitiveCatch::features(double* out) const {
  JacoEnv::features(out);
  out[2] = n_.successes, out[3] = n_.since_success, out[4] = n_.since_throw, out[5] = n_.wait > 0 ? 1 : 0;
}

void JacoRepetitiveCatch::place_task_object() { catch_.place(*this, rng_); }

void JacoRepetitiveCatch::begin_task() {
  catch_.begin(*this);
  n_ = Count();
  n_.since_success = kFar;
}

void JacoRepetitiveCatch::after_random_steps() { catch_.throw_box(*this, rng_); }

StepResult JacoRepetitiveCatch::score(const float* action) {
  n_.since_success = std::min(kFar, n_.since_success + 1);
  n_.since_throw += 1;
  double reward = control_cost(action);
  bool failed = false;
  if (n_.wait > 0) {  // the next box: held at the start, then falling, then thrown
    n_.wait += 1;
    if (n_.wait <= k_.pin_steps) {
      catch_.pin_at_start(*this);
      mj_kinematics(model_, data_);
    } else if (n_.wait > k_.pin_steps + k_.fall_steps) {
      catch_.throw_box(*this, rng_);
      mj_kinematics(model_, data_);
      n_.wait = 0;
      n_.since_throw = 0;
    }
  } else {
    RuleStep rs = catch_.step(*this);
    reward += rs.reward;
    failed = rs.failed;
    if (rs.success) {
      n_.successes += 1;
      n_.since_success = 0;
      catch_.begin(*this);
      if (n_.successes < k_.successes) {
        catch_.pin_at_start(*this);
        if (k_.unwind_arm) unwind_arm();
        mj_kinematics(model_, data_);
        n_.wait = 1;
      }
    }
  }
  return composite_result(reward, failed, int(n_.successes), k_.successes);
}

void JacoRepetitiveCatch::save_task_state(std::vector<double>& out) const { append_state(out, catch_.s, n_); }
void JacoRepetitiveCatch::restore_task_state(const double* in, size_t n) {
  read_state(in, n, spec_.name, catch_.s, n_);
}

// ---- Serve --------------------------------------------------------------------------------

// The toss's and the hit's rules read the same `start`, `start_noise` and `vel_noise`; Serve
// places its ball by the toss's (on the ground).
JacoServe::Config JacoServe::Config::read(const Section& env) {
  Config k;
  k.judge_height = env.get("judge_height", k.judge_height, Range::non_negative());
  k.toss_bonus = env.get("toss_bonus", k.toss_bonus, Range::non_negative());
  k.toss_tolerance = env.get("toss_tolerance", k.toss_tolerance, Range::non_negative());
  k.toss = TossRule::Config::read(env);
  k.hit = HitRule::Config::read(env);
  return k;
}

JacoServe::JacoServe(const std::string& name, const JacoConfig& c, const Config& k)
    : JacoEnv(name, c, "jaco/jaco_ball.xml", /*with_rotation=*/false), k_(k) {
  toss_.cfg = k.toss;
  toss_.judge_landing = false;
  hit_.cfg = k.hit;
  spec_.feature_names.insert(spec_.feature_names.end(), {"since_release", "falling", "judged", "hit"});
}

void JacoServe::features(double* out) const {
  JacoEnv::features(out);
  out[2] = n_.since_release, out[3] = toss_.s.falling, out[4] = n_.judged, out[5] = hit_.s.hit;
}

void JacoServe::place_task_object() {
  toss_.place(*this, rng_);
  hit_.place_target(*this);
}

void JacoServe::begin_task() {
  toss_.begin(*this);
  hit_.begin(*this);
  n_ = Count();
  n_.since_release = kFar;
}

StepResult JacoServe::score(const float* action) {
  double reward = control_cost(action);
  bool failed = false, success = false;
  const bool was_falling = toss_.falling();
  if (!hit_.hit()) {  // the toss's terms (its stability term among them) stop at the hit
    RuleStep rs = toss_.step(*this);
    reward += rs.reward;
    failed = rs.failed;
  }
  const Vec3 ball = object_pos();
  if (n_.since_release >= kFar && ball[2] > toss_.cfg.release_height) n_.since_release = 0;
  else n_.since_release = std::min(kFar, n_.since_release + 1);
  if (toss_.falling() && !failed) {
    if (!was_falling) hit_.begin(*this);  // the hit's clock (its x velocity) starts at the apex
    RuleStep rs = hit_.step(*this);
    reward += rs.reward;
    failed = rs.failed;
    success = rs.success;
    if (!n_.judged && (ball[2] < k_.judge_height || hit_.hit())) {
      n_.judged = 1;
      if (std::abs(ball[0] - toss_.cfg.land_x) < k_.toss_tolerance &&
          std::abs(ball[1] - toss_.cfg.land_y) < k_.toss_tolerance)
        reward += k_.toss_bonus;
    }
  }
  return composite_result(reward, failed, success ? 1 : 0, 1);
}

void JacoServe::save_task_state(std::vector<double>& out) const { append_state(out, toss_.s, hit_.s, n_); }
void JacoServe::restore_task_state(const double* in, size_t n) {
  read_state(in, n, spec_.name, toss_.s, hit_.s, n_);
}

}  // namespace segue
