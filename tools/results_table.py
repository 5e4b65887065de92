#!/usr/bin/env python3
"""Prints the README's table of all six tasks: each method's mean +- std success count
from experiments/results/TASK.json (written by `segue report TASK`), beside the paper's
(tools/paper_results.json). A task without a results file prints its paper row only.

usage: tools/results_table.py
"""
import json
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TASKS = [("repetitive_picking", "Repetitive picking up"), ("repetitive_catching", "Repetitive catching"),
         ("serve", "Serve"), ("patrol", "Patrol"), ("hurdle", "Hurdle"), ("obstacle_course", "Obstacle course")]
METHODS = ["single", "without-tp", "tp", "lee", "tp+q"]
paper = json.load(open(os.path.join(ROOT, "tools", "paper_results.json")))["tasks"]

print("| task | Single | Without TP | With TP | Lee et al. | With TP + Q |")
print("|---|---|---|---|---|---|")
for key, name in TASKS:
    path = os.path.join(ROOT, "experiments", "results", key + ".json")
    ours = json.load(open(path)) if os.path.exists(path) else {}
    cells = []
    for m in METHODS:
        p = "%.2f +- %.2f" % tuple(paper[key][m])
        o = ours.get(m)
        cells.append((f"{o['mean']:.2f} +- {o['std']:.2f}" if o else "not yet") + f" ({p})")
    print(f"| {name} | " + " | ".join(cells) + " |")
