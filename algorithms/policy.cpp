#include "algorithms/policy.h"

#include <torch/script.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "algorithms/on_policy.h"
#include "algorithms/sac.h"
#include "core/error.h"
#include "core/run_dir.h"

#include <fstream>

namespace segue {

Policy::Policy(EigenMlp mlp, std::vector<float> mean, std::vector<float> inv_std, float clip,
               std::vector<float> low, std::vector<float> high, ObsFeatures features)
    : mlp_(std::move(mlp)), obs_mean_(std::move(mean)), obs_inv_std_(std::move(inv_std)),
      act_low_(std::move(low)), act_high_(std::move(high)), obs_clip_(clip),
      features_(std::move(features)) {
  if (mlp_.in_dim() != in_dim())
    throw Error("policy: the network takes " + std::to_string(mlp_.in_dim()) +
                " inputs, the normaliser and features give " + std::to_string(in_dim()));
}

void Policy::normalize(const float* obs, int batch, float* out) const {
  const int d = obs_dim(), n = in_dim();
  for (int b = 0; b < batch; ++b) {
    const float* s = obs + size_t(b) * d;
    float* x = out + size_t(b) * n;
    for (int j = 0; j < d; ++j) x[j] = std::clamp((s[j] - obs_mean_[j]) * obs_inv_std_[j], -obs_clip_, obs_clip_);
    features_.write(s, x + d);
  }
}

void Policy::set_log_std(std::vector<float> log_std) {
  if (!log_std.empty() && int(log_std.size()) != act_dim())
    throw Error("policy: " + std::to_string(log_std.size()) + " log stds for " + std::to_string(act_dim()) + " actions");
  log_std_ = std::move(log_std);
}

void Policy::act(const float* obs, int batch, float* actions, Rng* noise) const {
  if (noise && log_std_.empty()) throw Error("policy: sampling asked of a policy saved without its log std");
  const int k = act_dim();
  normalized_.resize(size_t(batch) * in_dim());
  normalize(obs, batch, normalized_.data());
  mlp_.forward(normalized_.data(), batch, actions);
  for (int b = 0; b < batch; ++b)
    for (int j = 0; j < k; ++j) {
      float& a = actions[size_t(b) * k + j];
      if (noise) a += std::exp(log_std_[j]) * static_cast<float>(noise->normal());
      a = tanh_output_ ? act_low_[j] + 0.5f * (std::tanh(a) + 1.0f) * (act_high_[j] - act_low_[j])
                       : std::clamp(a, act_low_[j], act_high_[j]);
    }
}

Policy Policy::with_parameters(const std::vector<float>& theta) const {
  Policy p = *this;
  p.mlp_.set_parameters(theta);
  return p;
}

void Policy::check_fits(const EnvSpec& spec, const std::string& path, bool prefix) const {
  if ((prefix ? obs_dim() > spec.obs_dim : obs_dim() != spec.obs_dim) || act_dim() != spec.act_dim)
    throw Error(path + ": policy takes obs_dim " + std::to_string(obs_dim()) + " / act_dim " +
                std::to_string(act_dim()) + ", but task '" + spec.name + "' has obs_dim " +
                std::to_string(spec.obs_dim) + " / act_dim " + std::to_string(spec.act_dim));
}

namespace {

torch::Tensor vec(const std::vector<float>& v) {
  return torch::tensor(v, torch::TensorOptions().dtype(torch::kFloat32));
}
template <class M>
torch::Tensor mat(const M& m) {
  return torch::from_blob(const_cast<float*>(m.data()), {m.rows(), m.cols()}, torch::kFloat32).clone();
}

}  // namespace

void Policy::export_torchscript(const std::string& path) const {
  torch::jit::Module m("SeguePolicy");
  m.register_buffer("obs_mean", vec(obs_mean_));
  m.register_buffer("obs_inv_std", vec(obs_inv_std_));
  m.register_buffer("act_low", vec(act_low_));
  m.register_buffer("act_high", vec(act_high_));
  m.register_attribute("obs_clip", c10::FloatType::get(), double(obs_clip_));
  m.register_attribute("n_obs", c10::IntType::get(), int64_t(obs_dim()));
  m.register_attribute("n_act", c10::IntType::get(), int64_t(act_dim()));
  m.register_attribute("activation", c10::StringType::get(), activation_name(mlp_.activation()));
  if (!source_.empty()) m.register_attribute("source", c10::StringType::get(), source_);
  if (tanh_output_) m.register_attribute("tanh_output", c10::BoolType::get(), true);
  if (!log_std_.empty()) m.register_buffer("log_std", vec(log_std_));  // not used by forward (the mean)
  if (max_steps_ > 0) m.register_attribute("max_steps", c10::IntType::get(), int64_t(max_steps_));
  const size_t layers = mlp_.weights().size();
  std::ostringstream src;
  src << "def obs_dim(self) -> int:\n    return self.n_obs\n"
      << "def act_dim(self) -> int:\n    return self.n_act\n"
      << "def forward(self, obs: Tensor) -> Tensor:\n"
      << "    x = torch.clamp((obs - self.obs_mean) * self.obs_inv_std, -self.obs_clip, self.obs_clip)\n";
  // Periodic features in ObsFeatures::write's order: per input, per period, sin then cos.
  if (!features_.empty()) {
    std::vector<int64_t> inputs(features_.inputs.begin(), features_.inputs.end());
    m.register_buffer("feature_inputs", torch::tensor(inputs, torch::kLong));
    m.register_buffer("feature_periods", torch::tensor(features_.periods, torch::kFloat64));
    src << "    phase = 2.0 * 3.141592653589793 * obs.double().index_select(1, self.feature_inputs).unsqueeze(2)"
        << " / self.feature_periods\n"
        << "    f = torch.stack([torch.sin(phase), torch.cos(phase)], 3).reshape(obs.size(0), -1).float()\n"
        << "    x = torch.cat([x, f], 1)\n";
  }
  for (size_t i = 0; i < layers; ++i) {
    m.register_buffer("w" + std::to_string(i), mat(mlp_.weights()[i]));
    m.register_buffer("b" + std::to_string(i), mat(mlp_.biases()[i]).reshape({-1}));
    src << "    x = torch.matmul(x, self.w" << i << ".t()) + self.b" << i << "\n";
    if (i + 1 < layers) src << "    x = torch." << activation_name(mlp_.activation()) << "(x)\n";
  }
  if (tanh_output_)
    src << "    return self.act_low + 0.5 * (torch.tanh(x) + 1.0) * (self.act_high - self.act_low)\n";
  else
    src << "    return torch.max(torch.min(x, self.act_high), self.act_low)\n";
  m.define(src.str());
  std::ostringstream bytes;
  m.save(bytes);
  write_file_atomic(path, bytes.str());
}

Policy Policy::load_torchscript(const std::string& path) {
  torch::jit::Module m = torch::jit::load(path);
  std::vector<torch::Tensor> ws, bs;
  for (int i = 0; m.hasattr("w" + std::to_string(i)); ++i) {
    ws.push_back(m.attr("w" + std::to_string(i)).toTensor());
    bs.push_back(m.attr("b" + std::to_string(i)).toTensor());
  }
  if (ws.empty()) throw Error(path + ": not a Segue policy (no layers w0, b0, ...)");
  ObsFeatures features;
  if (m.hasattr("feature_inputs")) {
    features.inputs = to_ints(m.attr("feature_inputs").toTensor());
    features.periods = to_doubles(m.attr("feature_periods").toTensor());
  }
  Policy p(EigenMlp(ws, bs, parse_activation(m.attr("activation").toStringRef())),
           to_floats(m.attr("obs_mean").toTensor()), to_floats(m.attr("obs_inv_std").toTensor()),
           float(m.attr("obs_clip").toDouble()), to_floats(m.attr("act_low").toTensor()),
           to_floats(m.attr("act_high").toTensor()), features);
  if (m.hasattr("source")) p.set_source(m.attr("source").toStringRef());
  if (m.hasattr("tanh_output")) p.set_tanh_output(m.attr("tanh_output").toBool());
  if (m.hasattr("log_std")) p.set_log_std(to_floats(m.attr("log_std").toTensor()));
  if (m.hasattr("max_steps")) p.set_max_steps(int(m.attr("max_steps").toInt()));
  // The Eigen forward must be the function the file defines: check on a random batch.
  torch::manual_seed(0);
  auto obs = torch::randn({8, p.obs_dim()}) * 3.0;
  auto expected = m.forward({obs}).toTensor();
  std::vector<float> got(size_t(8) * p.act_dim());
  p.act(obs.data_ptr<float>(), 8, got.data());
  auto diff = (expected - torch::from_blob(got.data(), {8, p.act_dim()})).abs().max().item<float>();
  if (!(diff < 1e-4f))
    throw Error(path + ": the TorchScript forward and Segue's reading of its weights differ by " +
                std::to_string(diff));
  return p;
}

namespace {

// A training checkpoint's deterministic policy, whichever learner wrote it.
Policy checkpoint_policy(const std::string& path) {
  torch::serialize::InputArchive ar;
  ar.load_from(path);
  torch::Tensor learner;
  if (ar.try_read("meta_learner", learner) && to_text(learner) == "sac") return SAC::policy_from_checkpoint(ar, path);
  return OnPolicyLearner::policy_from_checkpoint(ar);
}

}  // namespace

Policy Policy::load(const std::string& path) {
  std::ifstream probe(path);
  if (!probe) throw Error(path + ": no such policy file");
  torch::jit::Module m;
  try {
    m = torch::jit::load(path);
  } catch (const c10::Error&) {
    throw Error(path + ": not a TorchScript policy or Segue checkpoint");
  }
  try {
    if (m.find_method("act_dim")) return load_torchscript(path);
    return checkpoint_policy(path);
  } catch (const c10::Error& e) {
    std::string what = e.what_without_backtrace();
    throw Error(path + ": unreadable policy: " + what.substr(0, what.find('\n')));
  }
}

}  // namespace segue
