#!/usr/bin/env python3
"""Runs `build/segue bench --json` RUNS times (default 3) and prints docs/speed.md's table:
physics steps per second of bare mj_step replaying the rollouts' own trajectories, the
rollout with policy inference, and the full PPO and TRPO loops (also with the next rollout
collected beside each update, policy_lag 1), on one thread and on every core, for the
walker and the arm, with the ratios to bare physics; then the time of one PPO minibatch
step and of one TRPO update; then the walker's PPO and TRPO on 1 and 2 ranks
(docs/distributed.md).

usage: tools/bench_table.py [RUNS]
"""
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
runs = int(sys.argv[1]) if len(sys.argv) > 1 else 3
results = []
for _ in range(runs):
    out = subprocess.run([os.path.join(ROOT, "build", "segue"), "bench", "--json"], check=True,
                         capture_output=True, text=True).stdout
    results.append(json.loads(out.strip().splitlines()[-1]))

rows = [("mujoco-testspeed (walker.xml), 1 thread", "testspeed_sps", None)]
for robot, p in (("walker", ""), ("arm", "jaco_")):
    rows += [
        (f"{robot}: bare mj_step replay, 1 thread", p + "bare_sps", None),
        (f"{robot}: rollout + inference, 1 thread", p + "rollout_sps", p + "rollout_vs_bare"),
        (f"{robot}: full PPO loop, 1 thread", p + "ppo_sps", p + "ppo_vs_bare"),
        (f"{robot}: full TRPO loop, 1 thread", p + "trpo_sps", p + "trpo_vs_bare"),
        (f"{robot}: PPO, policy_lag 1, 1 stepping thread", p + "ppo_lag_sps", p + "ppo_lag_vs_bare"),
        (f"{robot}: TRPO, policy_lag 1, 1 stepping thread", p + "trpo_lag_sps", p + "trpo_lag_vs_bare"),
        (f"{robot}: bare replay, all cores", p + "bare_sps_all_cores", None),
        (f"{robot}: rollout, all cores", p + "rollout_sps_all_cores", p + "rollout_vs_bare_all_cores"),
        (f"{robot}: full PPO loop, all cores", p + "ppo_sps_all_cores", p + "ppo_vs_bare_all_cores"),
        (f"{robot}: full TRPO loop, all cores", p + "trpo_sps_all_cores", p + "trpo_vs_bare_all_cores"),
        (f"{robot}: PPO, policy_lag 1, all cores", p + "ppo_lag_sps_all_cores", p + "ppo_lag_vs_bare_all_cores"),
        (f"{robot}: TRPO, policy_lag 1, all cores", p + "trpo_lag_sps_all_cores", p + "trpo_lag_vs_bare_all_cores"),
    ]
print("| physics steps/s | " + " | ".join(f"run {i + 1}" for i in range(runs)) + " |")
print("|---|" + "---|" * runs)
for label, key, ratio in rows:
    cells = []
    for r in results:
        cell = f"{r[key]:,.0f}"
        if ratio:
            cell += f" ({r[ratio]:.2f} of bare)"
        cells.append(cell)
    print(f"| {label} | " + " | ".join(cells) + " |")
print(f"\ncores: {int(results[0]['cores'])}")
print("\n| the learner's update, 1 thread | " + " | ".join(f"run {i + 1}" for i in range(runs)) + " |")
print("|---|" + "---|" * runs)
for robot, p in (("walker", ""), ("arm", "jaco_")):
    print(f"| {robot}: one PPO minibatch step (ms) | " + " | ".join(f"{r[p + 'ppo_minibatch_ms']:.2f}" for r in results) + " |")
    print(f"| {robot}: one TRPO update (s) | " + " | ".join(f"{r[p + 'trpo_update_seconds']:.3f}" for r in results) + " |")
print("\n| walker, data-parallel, physics steps/s | " + " | ".join(f"run {i + 1}: 1 rank, 2 ranks" for i in range(runs)) + " |")
print("|---|" + "---|" * runs)
for label, key in (("PPO (walker_forward.yaml)", "ppo_sps_by_ranks"),
                   ("TRPO (walker_forward_trpo.yaml)", "trpo_sps_by_ranks")):
    cells = [f"{r[key]['1']:,.0f}, {r[key]['2']:,.0f} ({r[key]['2'] / r[key]['1']:.2f}x)" for r in results]
    print(f"| {label} | " + " | ".join(cells) + " |")
