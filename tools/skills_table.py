#!/usr/bin/env python3
"""The README's table of shipped skills, from assets/policies/{walker,jaco}/manifest.json:
recipe, environment steps, wall time, success in the training run's evaluation (its eval
seed), and success when re-evaluated on other seeds.

  tools/skills_table.py                 print the table
  tools/skills_table.py --reeval 0,1    first evaluate every shipped skill (`segue eval`,
                                        50 episodes, the task's reference settings) on
                                        those seeds and record them in the manifests
  ... --reeval 0,1 --skills jaco_pick   only those skills (e.g. one just shipped)
"""
import argparse
import json
import os
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# A manifest entry's name is its skill's task (tools/ship_policy.py writes it so).
GROUPS = {"walker": ["walker_forward", "walker_backward", "walker_balance", "walker_crawl", "walker_jump"],
          "jaco": ["jaco_pick", "jaco_catch", "jaco_toss", "jaco_hit"]}

ap = argparse.ArgumentParser()
ap.add_argument("--reeval", default="")
ap.add_argument("--skills", default="", help="comma-separated skills to re-evaluate (default: all)")
args = ap.parse_args()

print("| skill | recipe | env steps | wall time | success in the run | success on seeds |")
print("|---|---|---|---|---|---|")
for group, tasks in GROUPS.items():
    path = os.path.join(ROOT, "assets", "policies", group, "manifest.json")
    manifest = json.load(open(path))
    for task in tasks:
        e = manifest.get(task)
        if e is None:
            print(f"| {task} | not shipped yet | | | | |")
            continue
        reeval = args.reeval if not args.skills or task in args.skills.split(",") else ""
        for seed in [s for s in reeval.split(",") if s]:
            out = subprocess.run([os.path.join(ROOT, "build", "segue"), "eval", os.path.join(ROOT, e["file"]),
                                  "--task", task, "--episodes", "50", "--seed", seed, "--json"],
                                 check=True, capture_output=True, text=True).stdout
            r = json.loads(out.strip().splitlines()[-1])
            e.setdefault("reeval", {})[seed] = {k: r[k] for k in ("episodes", "success_rate", "return_mean")}
        minutes = e["wall_seconds"] / 60
        wall = f"{minutes / 60:.1f} h" if minutes >= 90 else f"{minutes:.0f} min"
        stages = f" ({len(e['stages'])} stages)" if "stages" in e else ""
        if "trained_as" in e:  # trained before stages: existed; the figures are its last stage's
            stages = f" ({len(e['trained_as'])} stages; steps and time: the last)"
        seeds = ", ".join(f"{100 * v['success_rate']:.0f}% ({s})" for s, v in sorted(e.get("reeval", {}).items()))
        print(f"| {task} | `{os.path.basename(e['recipe'])}`{stages} | {e['env_steps'] / 1e6:.1f}M | {wall} | "
              f"{100 * e['eval']['success_rate']:.0f}% | {seeds or '-'} |")
    if args.reeval:
        with open(path, "w") as f:
            json.dump(manifest, f, indent=2, sort_keys=True)
            f.write("\n")
