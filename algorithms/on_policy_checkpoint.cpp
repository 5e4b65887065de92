// OnPolicyLearner's checkpoint: everything an exact resume needs (networks, optimiser,
// normalisers, counters, the episodes in flight), one file written atomically, shared by
// PPO and TRPO.
#include <spdlog/spdlog.h>

#include <sstream>

#include "algorithms/on_policy.h"
#include "core/error.h"
#include "core/run_dir.h"

namespace segue {

namespace {

std::string key(std::string name) {
  for (auto& c : name)
    if (c == '.') c = '_';
  return "ac_" + name;
}
// The periodic features, if any (older checkpoints have none).
void write_features(torch::serialize::OutputArchive& ar, const ObsFeatures& f) {
  if (f.empty()) return;
  ar.write("meta_feature_inputs", int_tensor(f.inputs));
  ar.write("meta_feature_periods", torch::tensor(f.periods, torch::kFloat64));
}
ObsFeatures read_features(torch::serialize::InputArchive& ar) {
  ObsFeatures f;
  torch::Tensor in, per;
  if (!ar.try_read("meta_feature_inputs", in)) return f;
  ar.read("meta_feature_periods", per);
  f.inputs = to_ints(in);
  f.periods = to_doubles(per);
  return f;
}

}  // namespace

// The environments' episodes in flight with the trainer's per-environment state (the
// discounted return), as one rank holds them or as a checkpoint does.
struct OnPolicyLearner::InFlight {
  std::vector<double> state, running_return;
  std::string rngs;

  void append(const InFlight& o) {
    state.insert(state.end(), o.state.begin(), o.state.end());
    rngs += o.rngs;
    running_return.insert(running_return.end(), o.running_return.begin(), o.running_return.end());
  }
  void write(torch::serialize::OutputArchive& ar) const {
    ar.write("episodes_state", torch::tensor(state, torch::kFloat64));
    ar.write("episodes_rng", text_tensor(rngs));
    ar.write("episodes_running_return", torch::tensor(running_return, torch::kFloat64));
  }
  bool read(torch::serialize::InputArchive& ar) {
    torch::Tensor s, r, ret;
    if (!(ar.try_read("episodes_state", s) && ar.try_read("episodes_rng", r) &&
          ar.try_read("episodes_running_return", ret)))
      return false;
    state = to_doubles(s), rngs = to_text(r), running_return = to_doubles(ret);
    return true;
  }
  std::string bytes() const {
    torch::serialize::OutputArchive ar;
    write(ar);
    std::ostringstream out;
    ar.save_to(out);
    return out.str();
  }
  static InFlight from_bytes(const std::string& b) {
    torch::serialize::InputArchive ar;
    std::istringstream in(b);
    ar.load_from(in);
    InFlight f;
    f.read(ar);
    return f;
  }
};

void OnPolicyLearner::save(const std::string& path, const std::string& note, const ArchiveWriter& extra) const {
  torch::serialize::OutputArchive ar;
  if (extra) extra(ar);
  for (const auto& p : net_->named_parameters()) ar.write(key(p.key()), p.value().detach());
  torch::serialize::OutputArchive opt;
  optimizer_->save(opt);
  ar.write("optimizer", opt);
  obs_rms_.save(ar, "obs_rms_");
  return_rms_.save(ar, "return_rms_");
  const auto& s = net_->spec;
  ar.write("meta_counters", int64_tensor({iteration_, global_step_, int64_t(wall_seconds_ * 1000), schedule_start_}));
  ar.write("meta_dims", int64_tensor({s.obs_dim, s.act_dim, s.activation == Activation::Tanh ? 0 : 1}));
  ar.write("meta_pi_hidden", int_tensor(s.pi_hidden));
  ar.write("meta_vf_hidden", int_tensor(s.vf_hidden));
  write_features(ar, s.features);
  ar.write("meta_act_low", torch::tensor(envs_.spec().act_low));
  ar.write("meta_act_high", torch::tensor(envs_.spec().act_high));
  ar.write("meta_note", text_tensor(note));
  ar.write("meta_learner", text_tensor(name_));
  // The episodes in flight, every rank's, in environment order.
  InFlight mine;
  const bool saved = envs_.save_episodes(mine.state, mine.rngs);
  if (!group_.any(!saved)) {
    mine.running_return = running_return_;
    InFlight all;
    for (const std::string& part : group_.gather(group_.single() ? std::string() : mine.bytes()))
      all.append(group_.single() ? mine : InFlight::from_bytes(part));
    all.write(ar);
  }
  // policy_lag 1: the rollout collected beside the last update, which the next one uses.
  if (rollout_ready_)
    for (const auto& [name, rows] : pending_rollout())
      ar.write(name, torch::from_blob(rows->data(), {int64_t(rows->size())}).clone());
  if (!group_.leader()) return;
  std::ostringstream bytes;
  ar.save_to(bytes);
  write_file_atomic(path, bytes.str());
}

void OnPolicyLearner::load(const std::string& path, const ArchiveReader& extra, bool resume_episodes) {
  // Rank 0 reads the file and every rank loads its bytes (other hosts need not see it).
  const std::string kFailed = "\x01segue: unreadable\n";
  std::string bytes;
  if (group_.leader()) {
    try {
      bytes = read_file(path);
    } catch (const Error& e) {
      bytes = kFailed + e.what();
    }
  }
  bytes = group_.broadcast(bytes);
  if (bytes.rfind(kFailed, 0) == 0) throw Error(bytes.substr(kFailed.size()));
  torch::serialize::InputArchive ar;
  InFlight saved;
  bool in_flight = false;
  try {
    std::istringstream in(bytes);
    ar.load_from(in);
    if (extra) extra(ar);
    read_state(ar, path, resume_episodes);
    in_flight = resume_episodes && saved.read(ar);
    rollout_ready_ = false;
    if (resume_episodes && rollout_cfg_.policy_lag > 0) rollout_ready_ = read_pending_rollout(ar, path);
  } catch (const c10::Error& e) {
    std::string what = e.what_without_backtrace();
    throw Error(path + ": unreadable checkpoint: " + what.substr(0, what.find('\n')));
  }
  refresh_inference_copy();
  const int first = envs_.first_index(), N = envs_.size();
  if (in_flight && int64_t(saved.running_return.size()) == global_envs_) {
    try {
      std::vector<double> state;
      std::string rngs;
      VectorEnv::slice_episodes(saved.state, saved.rngs, first, N, state, rngs);
      envs_.restore_episodes(state, rngs);
      running_return_.assign(saved.running_return.begin() + first, saved.running_return.begin() + first + N);
      return;
    } catch (const Error& e) {
      // Saved by a Segue whose environments kept another state: the run goes on, its
      // episodes in flight started afresh.
      spdlog::warn("{}: its episodes in flight cannot be put back ({}); resuming with fresh ones", path, e.what());
    }
  }
  // Episodes in flight cannot be put back (or this continues another run): start fresh
  // ones, seeded by position.
  envs_.reset(mix_seed(seed_, 0x10000 + iteration_));
  running_return_.assign(envs_.size(), 0.0);
}

void OnPolicyLearner::read_state(torch::serialize::InputArchive& ar, const std::string& path, bool same_run) {
  torch::Tensor dims, learner;
  if (!ar.try_read("meta_dims", dims))
    throw Error(path + ": not a training checkpoint (an exported policy? a run starts from one with init_policy)");
  // Checkpoints from before TRPO are PPO's. Another learner's optimiser state does not fit
  // this one's: a run resumes with its own learner, a new run may continue another's
  // networks with a fresh optimiser.
  const std::string saved_by = ar.try_read("meta_learner", learner) ? to_text(learner) : "ppo";
  if (same_run && saved_by != name_)
    throw Error(path + ": the run was trained with learner '" + saved_by + "', the recipe says '" + name_ +
                "' (a new run_dir can continue it with init_from)");
  const int64_t obs = dims[0].item<int64_t>(), act = dims[1].item<int64_t>();
  if (obs != net_->spec.obs_dim || act != net_->spec.act_dim)
    throw Error(path + ": the checkpoint's policy takes obs_dim " + std::to_string(obs) + " / act_dim " +
                std::to_string(act) + ", the task " + std::to_string(net_->spec.obs_dim) + " / " +
                std::to_string(net_->spec.act_dim));
  if (!(read_features(ar) == net_->spec.features))
    throw Error(path + ": checkpoint's policy.fourier features differ from the recipe's");
  torch::NoGradGuard no_grad;
  for (auto& p : net_->named_parameters()) {
    torch::Tensor t;
    ar.read(key(p.key()), t);
    if (t.sizes() != p.value().sizes())
      throw Error(path + ": parameter '" + p.key() + "' has another shape than the recipe's network");
    p.value().copy_(t);
  }
  if (saved_by == name_) {
    torch::serialize::InputArchive opt;
    ar.read("optimizer", opt);
    optimizer_->load(opt);
  }
  obs_rms_.load(ar, "obs_rms_");
  return_rms_.load(ar, "return_rms_");
  torch::Tensor counters;
  ar.read("meta_counters", counters);
  iteration_ = counters[0].item<int64_t>();
  global_step_ = counters[1].item<int64_t>();
  wall_seconds_ = counters[2].item<int64_t>() / 1000.0;
  schedule_start_ = counters.numel() > 3 ? counters[3].item<int64_t>() : 0;  // older checkpoints: 0
}

std::vector<std::pair<std::string, std::vector<float>*>> OnPolicyLearner::pending_rollout() const {
  auto& b = const_cast<RolloutBuffer&>(buf_);  // save() only reads them
  return {{"pending_obs", &b.obs}, {"pending_actions", &b.actions}, {"pending_log_probs", &b.log_probs},
          {"pending_advantages", &b.advantages}, {"pending_returns", &b.returns}};
}

bool OnPolicyLearner::read_pending_rollout(torch::serialize::InputArchive& ar, const std::string& path) {
  const auto parts = pending_rollout();
  for (size_t i = 0; i < parts.size(); ++i) {
    torch::Tensor t;
    if (!ar.try_read(parts[i].first, t)) {
      if (i == 0) return false;  // saved between rollouts (or with policy_lag 0)
      throw Error(path + ": its pending rollout lacks '" + parts[i].first + "'");
    }
    std::vector<float>& rows = *parts[i].second;
    if (t.numel() != int64_t(rows.size()))
      throw Error(path + ": its pending rollout has " + std::to_string(t.numel()) + " values of '" + parts[i].first +
                  "', the recipe's rollout " + std::to_string(rows.size()));
    t = t.to(torch::kFloat32).contiguous();
    std::copy(t.data_ptr<float>(), t.data_ptr<float>() + t.numel(), rows.begin());
  }
  return true;
}

Policy OnPolicyLearner::policy_from_checkpoint(torch::serialize::InputArchive& ar) {
  torch::Tensor dims, pi, vf, low, high;
  ar.read("meta_dims", dims);
  ar.read("meta_pi_hidden", pi);
  ar.read("meta_vf_hidden", vf);
  ar.read("meta_act_low", low);
  ar.read("meta_act_high", high);
  ActorCriticSpec spec;
  spec.obs_dim = static_cast<int>(dims[0].item<int64_t>());
  spec.act_dim = static_cast<int>(dims[1].item<int64_t>());
  spec.activation = dims[2].item<int64_t>() == 0 ? Activation::Tanh : Activation::Relu;
  spec.pi_hidden = to_ints(pi);
  spec.vf_hidden = to_ints(vf);
  spec.features = read_features(ar);
  ActorCritic net(spec);
  torch::NoGradGuard no_grad;
  for (auto& p : net->named_parameters()) {
    torch::Tensor t;
    ar.read(key(p.key()), t);
    p.value().copy_(t);
  }
  RunningMeanStd rms(spec.obs_dim);
  rms.load(ar, "obs_rms_");
  Policy p(EigenMlp(net->actor, spec.activation), std::vector<float>(rms.mean().begin(), rms.mean().end()),
           rms.inv_std(), static_cast<float>(rms.clip()), to_floats(low), to_floats(high), spec.features);
  p.set_log_std(to_floats(net->log_std));
  return p;
}

}  // namespace segue
