#include "hrl/collection.h"

#include "core/progress.h"

#include <spdlog/spdlog.h>

#include <sstream>

#include "algorithms/mlp.h"
#include "core/rng.h"
#include "core/run_dir.h"
#include "environments/registry.h"

namespace segue {

StartStates collect_start_states(const CompositeRecipe& r, int transition, int count, uint64_t seed,
                                 const std::vector<TransitionArtefacts>& trained, int max_episodes,
                                 const std::atomic<int>* stop) {
  auto env = r.make_env();
  const EnvSpec& spec = env->spec();
  bool any_q = false;
  for (const auto& a : trained) any_q |= bool(a.q);
  TransitionController controller(r.skills, r.meta, trained, any_q ? SwitchRule::QNetwork : SwitchRule::IntervalEnd);
  std::vector<float> obs(spec.obs_dim), act(spec.act_dim);
  std::vector<double> state;
  StartStates out;
  out.source = r.transition_source(transition);
  out.obs_dim = spec.obs_dim;
  Progress progress("S_a " + r.transition_name(transition), count, 0, "state");
  for (int e = 0; e < max_episodes && out.size() < count; ++e) {
    if (stop && stop->load()) return out;
    env->reset(mix_seed(seed, e), obs.data());
    controller.reset(*env, obs.data());
    for (bool done = false; !done && out.size() < count;) {
      // The interval a->b begins where the meta-controller hands a's phase to b. That phase
      // may be driven by a transition policy into a rather than by pi_a itself: on Patrol,
      // balance->walk begins at the very step walk->balance's interval ends, so balance
      // never runs alone and "pi_a in control" would find no state at all.
      env->save_state(state);
      controller.act(*env, obs.data(), act.data());
      if (controller.entered() == transition) {  // the hand-over to b happened at this state
        out.state_dim = int(state.size());
        out.states.insert(out.states.end(), state.begin(), state.end());
        out.obs.insert(out.obs.end(), obs.begin(), obs.end());  // act() leaves obs as it was
      }
      done = env->step(act.data(), obs.data()).done();
    }
    // A late interval is reached only as often as every earlier hand-over succeeds.
    progress.update(out.size(), NAN, NAN);
    if (out.size() == 0 && e + 1 == kEmptyEpisodes) {
      max_episodes = e + 1;
      break;
    }
  }
  if (out.size() < count)
    throw Error(r.file + ": transition " + r.transition_name(transition) + " was entered only " +
                std::to_string(out.size()) + " times in " + std::to_string(max_episodes) +
                " episodes (collect.start_states asks for " + std::to_string(count) + ")");
  return out;
}

Demonstrations collect_demonstrations(const CompositeRecipe& r, int transition, int count, uint64_t seed,
                                      int max_episodes, const std::atomic<int>* stop, const StartStates* handovers) {
  const Transition& tr = r.meta.transitions().at(transition);
  const bool own_task = !tr.expert_task.empty();
  if (tr.expert_after_handover) {
    if (!handovers || handovers->size() == 0)
      throw Error(r.file + ": transition " + r.transition_name(transition) +
                  ": expert.after_handover needs S_a's states, and none were given");
    max_episodes = handovers->size();  // restores are exact and pi_b deterministic: once each
  }
  auto env = own_task ? reference_task_factory(tr.expert_task)() : r.make_env();
  const EnvSpec& spec = env->spec();
  Skill b = r.skills[tr.to];
  const int D = b.obs_end - b.obs_begin;
  // On its own sub-task (checked at load to have D numbers) pi_b sees all of them.
  if (own_task) {
    b.obs_begin = 0;
    b.obs_end = D;
  }
  std::vector<float> obs(spec.obs_dim), act(spec.act_dim), prev(D);
  std::vector<double> f(spec.feature_names.size()), state;
  Demonstrations out, window;  // window: this episode's steps, added to out once kept
  out.source = r.transition_source(transition);
  out.obs_dim = window.obs_dim = D;
  out.act_dim = window.act_dim = spec.act_dim;
  Progress progress("T_b " + r.transition_name(transition), count, 0, "step");
  for (int e = 0; e < max_episodes && out.size() < count; ++e) {
    if (stop && stop->load()) return out;
    if (tr.expert_after_handover) {
      handovers->state(e, state);
      env->restore_state(state, obs.data());
    } else {
      env->reset(mix_seed(seed, e), obs.data());
    }
    window.clear();
    bool entered = false, past = false, done = false, succeeded = false;
    int successes = 0, at_entry = 0;  // the task's success count, now and on entering
    // With expert_successful a window is seen to its end, then pi_b runs on to its success.
    for (int t = 0; !done && (tr.expert_successful || out.size() + window.size() < count); ++t) {
      env->features(f.data());
      const bool inside = (!own_task || tr.expert_steps == 0 || t < tr.expert_steps) &&
                          MetaController::holds(tr.expert_when, f.data());
      past |= entered && !inside;  // one window per episode
      if (past && (succeeded || !tr.expert_successful)) break;
      if (!entered && inside) at_entry = successes;
      entered |= inside;
      std::copy(obs.begin() + b.obs_begin, obs.begin() + b.obs_end, prev.begin());
      b.policy.act(prev.data(), 1, act.data());
      StepResult sr = env->step(act.data(), obs.data());
      done = sr.done();
      successes = sr.info.success_count;
      // A restored episode's count so far is first seen after a step; no success is won in
      // the one step after pi_a hands over.
      if (t == 0 && tr.expert_after_handover) at_entry = successes;
      succeeded |= entered && successes > at_entry;
      if (inside && !past) {
        window.obs.insert(window.obs.end(), prev.begin(), prev.end());
        window.act.insert(window.act.end(), act.begin(), act.end());
        window.next_obs.insert(window.next_obs.end(), obs.begin() + b.obs_begin, obs.begin() + b.obs_end);
        window.done.push_back(sr.terminated);
      }
    }
    if (succeeded || !tr.expert_successful) out.append(window);
    progress.update(std::min(out.size(), count), NAN, NAN);
    if (out.size() == 0 && e + 1 == kEmptyEpisodes) {
      max_episodes = e + 1;
      break;
    }
  }
  if (out.size() < count && !(tr.expert_after_handover && out.size() > 0))
    throw Error(r.file + ": pi_b of transition " + r.transition_name(transition) + " gave only " +
                std::to_string(out.size()) + " demonstration steps in " + std::to_string(max_episodes) +
                " episodes (T_b: pi_b's steps inside its expert window, in episodes it runs " +
                (tr.expert_after_handover ? "from S_a's states" : "alone") +
                (tr.expert_successful ? " and then succeeds)" : ")"));
  return out;
}

namespace {

template <class T>
torch::Tensor as_tensor(const std::vector<T>& v, int64_t rows, torch::ScalarType type) {
  auto t = torch::from_blob(const_cast<T*>(v.data()), {rows, rows ? int64_t(v.size()) / rows : 0}, type);
  return t.clone();
}
template <class T>
std::vector<T> as_vector(const torch::Tensor& t) {
  auto c = t.contiguous();
  return std::vector<T>(c.data_ptr<T>(), c.data_ptr<T>() + c.numel());
}
void write(torch::serialize::OutputArchive& ar, const std::string& path) {
  std::ostringstream bytes;
  ar.save_to(bytes);
  write_file_atomic(path, bytes.str());
}

}  // namespace

void save(const StartStates& s, const std::string& path) {
  torch::serialize::OutputArchive ar;
  ar.write("states", as_tensor(s.states, s.size(), torch::kFloat64));
  ar.write("obs", as_tensor(s.obs, s.size(), torch::kFloat32));
  ar.write("source", text_tensor(s.source));
  write(ar, path);
}

void save(const Demonstrations& d, const std::string& path) {
  const int64_t m = d.size();
  torch::serialize::OutputArchive ar;
  ar.write("obs", as_tensor(d.obs, m, torch::kFloat32));
  ar.write("act", as_tensor(d.act, m, torch::kFloat32));
  ar.write("next_obs", as_tensor(d.next_obs, m, torch::kFloat32));
  ar.write("done", as_tensor(d.done, m, torch::kUInt8));
  ar.write("source", text_tensor(d.source));
  write(ar, path);
}

namespace {

// Reads `keys` of the archive at `path` into `out`, and its source (empty if the file has
// none), or throws naming the file.
void read_archive(const std::string& path, const std::string& what, const std::vector<std::string>& keys,
                  std::vector<torch::Tensor*> out, std::string& source) {
  try {
    torch::serialize::InputArchive ar;
    ar.load_from(path);
    for (size_t i = 0; i < keys.size(); ++i) {
      ar.read(keys[i], *out[i]);
      if (out[i]->dim() < 1 || out[i]->size(0) != out[0]->size(0)) throw Error(path + ": rows differ between arrays");
    }
    torch::Tensor text;
    source = ar.try_read("source", text) ? to_text(text) : "";
  } catch (const c10::Error& e) {
    std::string why = e.what_without_backtrace();
    throw Error(path + ": not " + what + " (" + why.substr(0, why.find('\n')) + ")");
  }
}

}  // namespace

StartStates load_start_states(const std::string& path) {
  torch::Tensor states, obs;
  StartStates s;
  read_archive(path, "a file of start states (S_a)", {"states", "obs"}, {&states, &obs}, s.source);
  s.state_dim = int(states.size(1));
  s.obs_dim = int(obs.size(1));
  s.states = as_vector<double>(states);
  s.obs = as_vector<float>(obs);
  return s;
}

Demonstrations load_demonstrations(const std::string& path) {
  torch::Tensor obs, act, next, done;
  Demonstrations d;
  read_archive(path, "a file of demonstrations (T_b)", {"obs", "act", "next_obs", "done"}, {&obs, &act, &next, &done},
               d.source);
  d.obs_dim = int(obs.size(1));
  d.act_dim = int(act.size(1));
  d.obs = as_vector<float>(obs);
  d.act = as_vector<float>(act);
  d.next_obs = as_vector<float>(next);
  d.done = as_vector<uint8_t>(done);
  return d;
}

}  // namespace segue
