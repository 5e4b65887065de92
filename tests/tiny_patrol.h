#pragma once
// A composite recipe small enough for tests: Patrol cut to one transition (forward ->
// balance), 300-step episodes, no pushes, budgets of a few seconds.
#include <string>

namespace segue {

inline constexpr const char* kTinyPatrol = R"(
task: patrol
env: {max_episode_steps: 300, push_prob: 0}
skills:
  forward: {policy: assets/policies/walker/walker_forward.pt}
  backward: {policy: assets/policies/walker/walker_backward.pt}
  balance: {policy: assets/policies/walker/walker_balance.pt}
start:
  - {skill: forward, when: {direction: 1}}
  - {skill: backward, when: {direction: -1}}
transitions:
  - {from: forward, to: balance, when: {since_turn: [0, 100]}, expert: {when: {steps: [0, 100]}}}
seed: 3
threads: 1
collect: {start_states: 12, demonstrations: 400}
transition:
  ppo: {total_steps: 2048, num_envs: 4, steps_per_env: 128, minibatch_size: 256, epochs: 2}
  discriminator: {steps: 4, batch: 64}
switch: {attempts: 24, warmup: 16, batch: 16, updates_per_attempt: 2}
eval: {episodes: 3, seeds: [0]}
)";

// The tiny recipe with forward->balance's interval at steps 20 to 120 of the episode,
// which every episode that starts walking forward reaches.
inline std::string tiny_patrol_by_steps() {
  std::string text = kTinyPatrol;
  const std::string interval = "when: {since_turn: [0, 100]}";
  text.replace(text.find(interval), interval.size(), "when: {steps: [20, 120]}");
  return text;
}

}  // namespace segue
