#include "hrl/lead_in.h"

#include <filesystem>

#include "core/assets.h"

namespace segue {

LeadIn LeadIn::read(const Section& s, const EnvSpec& task) {
  LeadIn l;
  l.policy_path = s.require<std::string>("policy");
  const std::string file = repo_path(l.policy_path);
  if (!std::filesystem::exists(file)) throw s.error("policy", "no such policy '" + l.policy_path + "'");
  try {
    l.policy = Policy::load(file);
    l.policy.check_fits(task, "'" + l.policy_path + "'", /*prefix=*/true);
  } catch (const Error& e) {
    throw s.error("policy", e.what());
  }
  l.when = read_when(s, task.feature_names);
  if (l.when.empty()) throw s.error("when", "give the interval the lead-in hands over in, e.g. {curb_ahead: [3, 4]}");
  l.share = s.get("share", l.share, Range::open_closed(0, 1));
  return l;
}

LeadInEnv::LeadInEnv(std::unique_ptr<Env> task, LeadIn lead_in)
    : task_(std::move(task)), lead_in_(std::move(lead_in)) {
  action_.resize(task_->spec().act_dim);
  features_.resize(task_->spec().feature_names.size());
}

void LeadInEnv::reset(uint64_t seed, float* obs) {
  rng_.seed(mix_seed(seed, 1));
  task_->reset(seed, obs);
  begin(obs);
}

void LeadInEnv::reset(float* obs) {
  task_->reset(obs);
  begin(obs);
}

void LeadInEnv::begin(float* obs) {
  lead_in_steps_ = 0;
  if (!rng_.bernoulli(lead_in_.share)) return;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    if (attempt > 0) task_->reset(obs);
    if (run_lead_in(obs)) return;
  }
  throw Error(task_->spec().name + ": the lead-in skill '" + lead_in_.policy_path + "' did not reach its interval in " +
              std::to_string(kAttempts) + " episodes");
}

bool LeadInEnv::run_lead_in(float* obs) {
  size_t inside = 0;
  for (int t = 0;; ++t) {
    task_->features(features_.data());
    if (MetaController::holds(lead_in_.when, features_.data())) {
      if (inside == inside_.size()) inside_.emplace_back(), inside_steps_.push_back(0);
      task_->save_state(inside_[inside]);
      inside_steps_[inside++] = t;
    } else if (inside > 0) {
      break;  // through the interval
    }
    lead_in_.policy.act(obs, 1, action_.data());
    if (task_->step(action_.data(), obs).done()) break;
  }
  if (inside == 0) return false;
  const int pick = rng_.integer(0, int(inside) - 1);
  task_->restore_state(inside_[pick], obs);
  lead_in_steps_ = inside_steps_[pick];
  return true;
}

std::function<std::unique_ptr<Env>()> with_lead_in(std::function<std::unique_ptr<Env>()> make_env, LeadIn lead_in) {
  return [make_env = std::move(make_env), lead_in = std::move(lead_in)]() -> std::unique_ptr<Env> {
    return std::make_unique<LeadInEnv>(make_env(), lead_in);
  };
}

}  // namespace segue
