#include "hrl/collection.h"

#include "core/progress.h"

#include <spdlog/spdlog.h>

#include <functional>
#include <optional>
#include <sstream>

#include "algorithms/mlp.h"
#include "core/rng.h"
#include "core/thread_pool.h"
#include "core/run_dir.h"
#include "environments/registry.h"

namespace segue {

namespace {

// Runs episode(i, e, part) for episodes e = 0, 1, ... in blocks of one per worker (i is
// the episode's place in its block, so each may own a context), and hands each part to
// take(e, part) in episode order until take returns false. The parts taken are those of
// the one-thread loop, however many threads run the episodes: each is seeded by e alone.
template <class Part>
void episodes_in_order(int threads, int max_episodes, const std::atomic<int>* stop,
                       const std::function<void(int, int, Part&)>& episode,
                       const std::function<bool(int, Part&)>& take) {
  ThreadPool pool(std::max(1, threads));
  std::vector<Part> parts(size_t(pool.size()));
  for (int first = 0; first < max_episodes; first += pool.size()) {
    if (stop && stop->load()) return;
    const int n = std::min(pool.size(), max_episodes - first);
    pool.parallel_for(n, [&](int i, int) { episode(i, first + i, parts[size_t(i)]); });
    for (int i = 0; i < n; ++i)
      if (!take(first + i, parts[size_t(i)])) return;
  }
}

}  // namespace

StartStates collect_start_states(const CompositeRecipe& r, int transition, int count, uint64_t seed,
                                 const std::vector<TransitionArtefacts>& trained, int max_episodes,
                                 const std::atomic<int>* stop, int threads) {
  bool any_q = false;
  for (const auto& a : trained) any_q |= bool(a.q);
  struct Worker {
    std::unique_ptr<Env> env;
    std::optional<TransitionController> controller;
    std::vector<float> obs, act;
    std::vector<double> state;
  };
  std::vector<Worker> workers(size_t(std::max(1, threads)));
  for (auto& w : workers) {
    w.env = r.training.at(transition).env();
    w.controller.emplace(r.skills, r.meta, trained, any_q ? SwitchRule::QNetwork : SwitchRule::IntervalEnd);
    w.obs.resize(w.env->spec().obs_dim), w.act.resize(w.env->spec().act_dim);
  }
  StartStates out;
  out.source = r.transition_source(transition);
  out.obs_dim = workers[0].env->spec().obs_dim;
  Progress progress("S_a " + r.transition_name(transition), count, 0, "state");
  episodes_in_order<StartStates>(
      threads, max_episodes, stop,
      [&](int i, int e, StartStates& part) {
        Worker& w = workers[size_t(i)];
        part = StartStates();
        part.obs_dim = out.obs_dim;
        w.env->reset(mix_seed(seed, e), w.obs.data());
        w.controller->reset(*w.env, w.obs.data(), mix_seed(seed, e));
        for (bool done = false; !done;) {
          // The interval a->b begins where the meta-controller hands a's phase to b. That
          // phase may be driven by a transition policy into a rather than by pi_a itself:
          // on Patrol, balance->walk begins at the very step walk->balance's interval ends,
          // so balance never runs alone and "pi_a in control" would find no state at all.
          w.env->save_state(w.state);
          w.controller->act(*w.env, w.obs.data(), w.act.data());
          if (w.controller->entered() == transition) {  // the hand-over to b happened at this state
            part.state_dim = int(w.state.size());
            part.states.insert(part.states.end(), w.state.begin(), w.state.end());
            part.obs.insert(part.obs.end(), w.obs.begin(), w.obs.end());  // act() leaves obs as it was
          }
          done = w.env->step(w.act.data(), w.obs.data()).done();
        }
      },
      [&](int e, StartStates& part) {
        if (part.size() > 0) out.state_dim = part.state_dim;
        part.keep_first(count - out.size());
        out.append(part);
        // A late interval is reached only as often as every earlier hand-over succeeds.
        progress.update(out.size(), NAN, NAN);
        if (out.size() == 0 && e + 1 == kEmptyEpisodes) max_episodes = e + 1;
        return out.size() < count && e + 1 < max_episodes;
      });
  if (stop && stop->load()) return out;
  if (out.size() < count)
    throw Error(r.file + ": transition " + r.transition_name(transition) + " was entered only " +
                std::to_string(out.size()) + " times in " + std::to_string(max_episodes) +
                " episodes (collect.start_states asks for " + std::to_string(count) + ")");
  return out;
}

Demonstrations collect_demonstrations(const CompositeRecipe& r, int transition, int count, uint64_t seed,
                                      int max_episodes, const std::atomic<int>* stop, const StartStates* handovers,
                                      int threads) {
  const Transition& rule = r.meta.transitions().at(transition);
  const TransitionTrainingSpec& tr = r.training.at(transition);
  const bool own_task = !tr.expert_task.empty();
  if (tr.expert_after_handover) {
    if (!handovers || handovers->size() == 0)
      throw Error(r.file + ": transition " + r.transition_name(transition) +
                  ": expert.after_handover needs S_a's states, and none were given");
    max_episodes = handovers->size();  // restores are exact and pi_b deterministic: once each
  }
  Skill b = r.skills[rule.to];
  const int D = b.obs_end - b.obs_begin;
  // On its own sub-task (checked at load to have D numbers) pi_b sees all of them.
  if (own_task) {
    b.obs_begin = 0;
    b.obs_end = D;
  }
  struct Worker {
    std::unique_ptr<Env> env;
    Skill b;  // an own copy: Policy::act keeps scratch buffers
    std::vector<float> obs, act, prev;
    std::vector<double> f, state;
  };
  std::vector<Worker> workers(size_t(std::max(1, threads)));
  for (auto& w : workers) {
    w.env = own_task ? reference_task_factory(tr.expert_task)() : tr.env();
    w.b = b;
    w.obs.resize(w.env->spec().obs_dim), w.act.resize(w.env->spec().act_dim), w.prev.resize(D);
    w.f.resize(w.env->spec().feature_names.size());
  }
  // An episode's part: its window of pi_b's steps, and whether it is kept.
  struct Window {
    Demonstrations steps;
    bool kept = false;
  };
  Demonstrations out;
  out.source = r.transition_source(transition);
  out.obs_dim = D;
  out.act_dim = workers[0].env->spec().act_dim;
  Progress progress("T_b " + r.transition_name(transition), count, 0, "step");
  episodes_in_order<Window>(
      threads, max_episodes, stop,
      [&](int i, int e, Window& part) {
        Worker& w = workers[size_t(i)];
        Demonstrations& window = part.steps;
        window.obs_dim = D, window.act_dim = out.act_dim;
        window.clear();
        if (tr.expert_after_handover) {
          handovers->state(e, w.state);
          w.env->restore_state(w.state, w.obs.data());
        } else {
          w.env->reset(mix_seed(seed, e), w.obs.data());
        }
        bool entered = false, past = false, done = false, succeeded = false;
        int successes = 0, at_entry = 0;  // the task's success count, now and on entering
        // With expert_successful a window is seen to its end, then pi_b runs on to its success.
        for (int t = 0; !done; ++t) {
          w.env->features(w.f.data());
          const bool inside = (!own_task || tr.expert_steps == 0 || t < tr.expert_steps) &&
                              MetaController::holds(tr.expert_when, w.f.data());
          past |= entered && !inside;  // one window per episode
          if (past && (succeeded || !tr.expert_successful)) break;
          if (!entered && inside) at_entry = successes;
          entered |= inside;
          std::copy(w.obs.begin() + w.b.obs_begin, w.obs.begin() + w.b.obs_end, w.prev.begin());
          w.b.policy.act(w.prev.data(), 1, w.act.data());
          StepResult sr = w.env->step(w.act.data(), w.obs.data());
          done = sr.done();
          successes = sr.info.success_count;
          // A restored episode's count so far is first seen after a step; no success is won
          // in the one step after pi_a hands over.
          if (t == 0 && tr.expert_after_handover) at_entry = successes;
          succeeded |= entered && successes > at_entry;
          if (inside && !past) {
            window.obs.insert(window.obs.end(), w.prev.begin(), w.prev.end());
            window.act.insert(window.act.end(), w.act.begin(), w.act.end());
            window.next_obs.insert(window.next_obs.end(), w.obs.begin() + w.b.obs_begin, w.obs.begin() + w.b.obs_end);
            window.done.push_back(sr.terminated);
          }
        }
        part.kept = succeeded || !tr.expert_successful;
      },
      [&](int e, Window& part) {
        // Without expert_successful, T_b is cut at `count` steps; with it, an episode's
        // window is kept whole.
        if (!tr.expert_successful) part.steps.keep_first(count - out.size());
        if (part.kept) out.append(part.steps);
        progress.update(std::min(out.size(), count), NAN, NAN);
        if (out.size() == 0 && e + 1 == kEmptyEpisodes) max_episodes = e + 1;
        return out.size() < count && e + 1 < max_episodes;
      });
  if (stop && stop->load()) return out;
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
