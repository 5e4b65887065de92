#!/usr/bin/env python3
"""Prints the training cost of the shipped transition artefacts beside the paper's, as a
markdown table: environment steps and wall time per stage, summed over each task's
transitions, read from assets/policies/<group>/<task>/manifest.json (which
tools/ship_transitions.py writes from the run's stage CSVs).

The paper's figures (appendix): each transition policy 10M interactions; switch training,
all of a task's DQNs together, 30M (Patrol), 11M (Hurdle) and 47M (Obstacle course)
interactions with 30,000 / 20,000 / 30,000 updates.

usage: tools/cost_table.py [--group walker] [TASK ...]
"""
import argparse, json, os

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PAPER_PI_AB = 10_000_000
PAPER_SWITCH = {"patrol": 30_000_000, "hurdle": 11_000_000, "obstacle_course": 47_000_000}

ap = argparse.ArgumentParser()
ap.add_argument("tasks", nargs="*", default=["patrol", "hurdle", "obstacle_course"])
ap.add_argument("--group", default="walker")
args = ap.parse_args()


def millions(n):
    return f"{n / 1e6:.1f}M"


def minutes(s):
    return f"{s / 60:.0f} min" if s >= 60 else f"{s:.0f} s"


print("| task | transitions | pi_ab: steps (paper) | pi_ab: wall | q_ab: steps (paper) | q_ab: wall | Lee et al.: steps | Lee et al.: wall |")
print("|---|---|---|---|---|---|---|---|")
for task in args.tasks:
    path = os.path.join(root, "assets", "policies", args.group, task, "manifest.json")
    with open(path) as f:
        transitions = json.load(f)["transitions"]

    def total(stage, key):
        return sum(t[stage][key] for t in transitions.values() if stage in t)

    n = len(transitions)
    print(f"| {task} | {n} | {millions(total('transition', 'env_steps'))} ({millions(n * PAPER_PI_AB)}) "
          f"| {minutes(total('transition', 'wall_seconds'))} "
          f"| {millions(total('switch', 'env_steps'))} ({millions(PAPER_SWITCH[task])}) "
          f"| {minutes(total('switch', 'wall_seconds'))} "
          f"| {millions(total('lee', 'env_steps'))} | {minutes(total('lee', 'wall_seconds'))} |")
