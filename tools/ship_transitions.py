#!/usr/bin/env python3
"""Ships the transition artefacts of a finished `segue run`: copies RUN_DIR/NAME/{policy,q,lee}.pt
to assets/policies/<group>/<task>/NAME/ and records what each cost in manifest.json there
(environment steps and wall time, read from the stage CSVs; q_ab's switch margin from
margins.csv), and copies RUN_DIR/TASK.md/json to experiments/results/. A stage the run did
not train (its artefact copied in from the shipped set, byte for byte) or has not finished
(no artefact yet: the shipped one stays) keeps the shipped manifest's entry.

usage: tools/ship_transitions.py RUN_DIR [--group walker] [--no-results]
"""
import argparse, csv, filecmp, json, os, shutil, sys

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ap = argparse.ArgumentParser()
ap.add_argument("run_dir")
ap.add_argument("--group", default="walker")
ap.add_argument("--no-results", action="store_true")
args = ap.parse_args()


def last_row(path):
    if not os.path.exists(path):
        return None
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return rows[-1] if rows else None


recipe = open(os.path.join(args.run_dir, "recipe.yaml")).read()
task = next(l.split(":", 1)[1].strip() for l in recipe.splitlines() if l.startswith("task:"))
out_dir = os.path.join(root, "assets", "policies", args.group, task)
manifest_path = os.path.join(out_dir, "manifest.json")
shipped = json.load(open(manifest_path)).get("transitions", {}) if os.path.exists(manifest_path) else {}
manifest = {"task": task, "recipe": f"experiments/{task}.yaml", "transitions": {}}
# stage, its artefact, its CSV's step column (the CSV is RUN_DIR/NAME/STAGE.csv)
STAGES = (("transition", "policy.pt", "global_step"), ("switch", "q.pt", "env_steps"), ("lee", "lee.pt", "global_step"))


names = sorted(d for d in os.listdir(args.run_dir) if os.path.isfile(os.path.join(args.run_dir, d, "policy.pt")))
if not names:
    sys.exit(f"{args.run_dir}: no transition has a policy.pt; is the run finished?")
for name in names:
    src, dst = os.path.join(args.run_dir, name), os.path.join(out_dir, name)
    os.makedirs(dst, exist_ok=True)
    entry = {}
    for stage, f, steps_key in STAGES:
        have = os.path.exists(os.path.join(src, f))
        reused = have and os.path.exists(os.path.join(dst, f)) and \
            filecmp.cmp(os.path.join(src, f), os.path.join(dst, f), shallow=False)  # before it is copied over
        if have:
            shutil.copyfile(os.path.join(src, f), os.path.join(dst, f))
        row = last_row(os.path.join(src, stage + ".csv")) if have else None
        if not row and (reused or not have) and stage in shipped.get(name, {}):
            entry[stage] = shipped[name][stage]
        elif row:
            entry[stage] = {"env_steps": int(float(row[steps_key])) if steps_key in row and row[steps_key] else None,
                            "wall_seconds": round(float(row["wall_seconds"]), 1) if row.get("wall_seconds") else None}
            if stage == "transition":
                entry[stage]["interval_completed_last_iteration"] = float(row["interval_completed"])
            if stage == "switch":
                entry[stage]["attempts"] = int(float(row["attempts"]))
                entry[stage]["subtask_success_last_100"] = float(row["subtask_success"])
    margins = os.path.join(src, "margins.csv")  # the held-out choice of q_ab's switch margin
    if os.path.exists(margins) and "switch" in entry:
        with open(margins) as f:
            rows = list(csv.DictReader(f))
        entry["switch"]["held_out_success"] = {f'{float(r["margin"]):g}': float(r["held_out_success"]) for r in rows}
        entry["switch"]["margin"] = next(float(r["margin"]) for r in rows if float(r["chosen"]))
        if rows[0].get("env_steps"):  # the stage's steps, the held-out check's included
            entry["switch"]["env_steps"] = int(float(rows[0]["env_steps"]))
    manifest["transitions"][name] = entry
with open(manifest_path, "w") as f:
    json.dump(manifest, f, indent=2, sort_keys=True)
    f.write("\n")
print(f"shipped {len(names)} transitions to {os.path.relpath(out_dir, root)}")
if not args.no_results:
    for ext in ("md", "json"):
        src = os.path.join(args.run_dir, f"{task}.{ext}")
        if os.path.exists(src):
            shutil.copyfile(src, os.path.join(root, "experiments", "results", f"{task}.{ext}"))
            print(f"copied {src} to experiments/results/")
