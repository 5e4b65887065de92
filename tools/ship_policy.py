#!/usr/bin/env python3
"""Ships a trained skill: exports RUN_DIR/checkpoint.pt to assets/policies/<group>/<task>.pt
and records provenance in assets/policies/<group>/manifest.json (recipe, seed, environment
steps, wall time, evaluation, and the policy or checkpoint it started from) from the run
directory's recipe.yaml and eval.json.

usage: tools/ship_policy.py RECIPE RUN_DIR [--group walker]
"""
import argparse, json, os, subprocess, sys

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ap = argparse.ArgumentParser()
ap.add_argument("recipe")
ap.add_argument("run_dir")
ap.add_argument("--group", default="walker")
args = ap.parse_args()

evaluation = json.load(open(os.path.join(args.run_dir, "eval.json")))
resolved = open(os.path.join(args.run_dir, "recipe.yaml")).read()
# The resolved recipe's top-level scalars (task, seed, init_policy, ...), read once.
top = {k: v.strip().strip('"') for k, v in (l.split(":", 1) for l in resolved.splitlines()
                                            if ":" in l and not l.startswith((" ", "#")))}
task, seed = top["task"], top["seed"]
out_dir = os.path.join(root, "assets", "policies", args.group)
os.makedirs(out_dir, exist_ok=True)
out = os.path.join(out_dir, task + ".pt")
subprocess.run([os.path.join(root, "build", "segue"), "export",
                os.path.join(args.run_dir, "checkpoint.pt"), out], check=True)
manifest_path = os.path.join(out_dir, "manifest.json")
manifest = json.load(open(manifest_path)) if os.path.exists(manifest_path) else {}
manifest[task] = {
    "file": os.path.relpath(out, root),
    "recipe": os.path.relpath(os.path.abspath(args.recipe), root),
    "seed": int(seed),
    "env_steps": evaluation["env_steps"],
    "wall_seconds": round(evaluation["wall_seconds"], 1),
    "train_threads": evaluation["threads"],
    "eval": {k: evaluation[k] for k in evaluation if k not in ("env_steps", "wall_seconds", "threads")},
}
# A curriculum's stages, by name, in order (RUN_DIR/N-NAME holds each).
if "\nstages:" in resolved:
    import re
    manifest[task]["stages"] = re.findall(r"name:\s*([a-z0-9_-]+)", resolved.split("\nstages:", 1)[1])
# The policy or checkpoint this stage started from, if any (its own provenance is its entry).
manifest[task].update({k: top[k] for k in ("init_policy", "init_from") if top.get(k)})
with open(manifest_path, "w") as f:
    json.dump(manifest, f, indent=2, sort_keys=True)
    f.write("\n")
print(f"shipped {out} and updated {manifest_path}")
