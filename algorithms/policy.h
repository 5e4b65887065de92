#pragma once
// A trained policy as a plain function of the observation, for evaluation and for
// composing skills: a = clamp(mu([clip((s - mean) * inv_std), features(s)]), low, high)
// (or squashed by tanh into [low, high]: tanh_output())
// (features: ObsFeatures, usually none). The same
// function is exported as TorchScript (runnable with torch.jit.load in Python) and read
// back from it; inference runs the Eigen mirror of the network.
#include <string>
#include <vector>

#include "algorithms/mlp.h"
#include "algorithms/obs_features.h"
#include "core/env.h"
#include "core/rng.h"

namespace segue {

class Policy {
 public:
  Policy() = default;
  Policy(EigenMlp mlp, std::vector<float> obs_mean, std::vector<float> obs_inv_std, float obs_clip,
         std::vector<float> act_low, std::vector<float> act_high, ObsFeatures features = {});

  int obs_dim() const { return static_cast<int>(obs_mean_.size()); }
  int in_dim() const { return obs_dim() + features_.size(); }  // the network's input
  const ObsFeatures& features() const { return features_; }
  int act_dim() const { return mlp_.out_dim(); }
  const EigenMlp& mlp() const { return mlp_; }
  const std::vector<float>& obs_mean() const { return obs_mean_; }
  const std::vector<float>& obs_inv_std() const { return obs_inv_std_; }
  // The same policy (normaliser, action bounds) with other network parameters, laid out
  // as EigenMlp::parameters().
  Policy with_parameters(const std::vector<float>& theta) const;
  // The network's input: [clip((s - mean) * inv_std), features(s)], [batch, obs_dim] ->
  // [batch, in_dim].
  void normalize(const float* obs, int batch, float* out) const;
  // obs: [batch, obs_dim] -> actions: [batch, act_dim], the mean action. With `noise`,
  // sampled from the Gaussian policy instead, mu + exp(log_std) * N(0, 1) before the bounds
  // (a policy without log_std() is refused). Allocates only when the batch grows.
  void act(const float* obs, int batch, float* actions, Rng* noise = nullptr) const;
  // A transition policy with its own termination (Lee et al.'s): the most steps it drives
  // before handing over, as it was trained (0: no cap).
  int max_steps() const { return max_steps_; }
  void set_max_steps(int steps) { max_steps_ = steps; }
  // The Gaussian policy's log standard deviation per action (empty: saved without it).
  const std::vector<float>& log_std() const { return log_std_; }
  void set_log_std(std::vector<float> log_std);

  // Squash the network's output into the bounds, low + (tanh(x) + 1) (high - low) / 2
  // (SAC's actor), instead of clamping it (PPO's and TRPO's).
  bool tanh_output() const { return tanh_output_; }
  void set_tanh_output(bool on) { tanh_output_ = on; }

  // What the policy is for, e.g. "hurdle walk-jump q.pt" (empty: not said). Kept in the
  // exported file so that a file copied into the wrong place can be refused.
  const std::string& source() const { return source_; }
  void set_source(std::string s) { source_ = std::move(s); }

  // Writes a TorchScript module with forward(obs[B, obs_dim]) -> actions[B, act_dim],
  // obs_dim() and act_dim(), and the attribute `source` where one is set.
  void export_torchscript(const std::string& path) const;
  // Reads an exported .pt or a training checkpoint; throws segue::Error naming the file.
  static Policy load(const std::string& path);
  // Refuses a policy whose sizes do not fit the task; with `prefix`, the policy may see
  // the first obs_dim() numbers of a longer observation.
  void check_fits(const EnvSpec& spec, const std::string& path, bool prefix = false) const;

 private:
  static Policy load_torchscript(const std::string& path);
  EigenMlp mlp_;
  std::vector<float> obs_mean_, obs_inv_std_, act_low_, act_high_, log_std_;
  float obs_clip_ = 10.0f;
  ObsFeatures features_;
  std::string source_;
  bool tanh_output_ = false;
  int max_steps_ = 0;
  mutable std::vector<float> normalized_;
};

}  // namespace segue
