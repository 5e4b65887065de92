#!/usr/bin/env python3
"""The learners side by side: each skill trained by each learner on several seeds at the
same environment-step budget, then one table and one figure.

  python3 tools/compare_learners.py [--skills walker_forward] [--learners ppo,trpo]
                                    [--seeds 1,2,3] [--threads 1] [--runs runs/learners]
                                    [--steps N | --steps LEARNER=N,...] [--report-only]
                                    [--out docs/learner_comparison]

A learner's recipe for a skill: `ppo` is the shipped one, experiments/primitives/SKILL.yaml;
any other is experiments/learners/SKILL_LEARNER.yaml. `LEARNER+lag` is LEARNER's recipe with
its next rollout collected beside each update (`LEARNER.policy_lag=1`). Every run is `segue train RECIPE
--set seed=S --set run_dir=RUNS/SKILL/LEARNER/seedS` (resumable: rerunning the command
resumes unfinished runs and skips finished ones); `--steps` sets every run's budget, or,
as `ppo=3000000,trpo=3000000`, the budgets of the learners it names (the others keep their
recipes').
Writes OUT.md (the table: final deterministic success from each run's eval.json, mean and
spread over seeds; the training success over the last BIN steps of the smallest budget
among a skill's learners, so learners with different budgets meet at equal steps;
environment steps and wall time until the training episodes first succeed 90% of the
time) and OUT.png (training success and training episode return against environment
steps, mean and min-max over seeds). Bad input prints one line to stderr and exits 2.
"""
import argparse
import csv
import fcntl
import json
import math
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
THRESHOLD = 0.9
BIN = 100_000  # environment steps per point of the curves


class InputError(Exception):
    pass


def base(learner):
    """The learner a variant's recipe is read for, and the settings the variant adds."""
    if learner.endswith("+lag"):
        name = learner[:-len("+lag")]
        return name, ["--set", f"{name}.policy_lag=1"]
    return learner, []


def recipe(skill, learner):
    learner = base(learner)[0]
    rel = (f"experiments/primitives/{skill}.yaml" if learner == "ppo"
           else f"experiments/learners/{skill}_{learner}.yaml")
    if not os.path.exists(os.path.join(ROOT, rel)):
        raise InputError(f"no recipe for {skill} with {learner}: {rel} does not exist")
    return rel


def train(skill, learner, seed, args):
    run_dir = os.path.join(args.runs, skill, learner, f"seed{seed}")
    # Several copies of this command may share the runs (e.g. one per core, seeds in
    # another order): a run is trained by whichever takes its lock first.
    os.makedirs(os.path.dirname(run_dir), exist_ok=True)
    lock = open(run_dir + ".lock", "w")
    fcntl.flock(lock, fcntl.LOCK_EX)
    if os.path.exists(os.path.join(run_dir, "eval.json")):
        return run_dir
    name, variant = base(learner)
    cmd = [os.path.join(ROOT, "build", "segue"), "train", recipe(skill, learner), "--set", f"seed={seed}",
           "--set", f"run_dir={run_dir}", "--threads", str(args.threads)] + variant
    steps = args.budgets.get(learner, args.budgets.get("*"))
    if steps:
        cmd += ["--set", f"{name}.total_steps={steps}"]
    print(" ".join(cmd), flush=True)
    if subprocess.call(cmd, cwd=ROOT) != 0:
        raise InputError(f"training failed: {' '.join(cmd)}")
    return run_dir


def read_run(run_dir):
    path = os.path.join(run_dir, "metrics.csv")
    if not os.path.exists(os.path.join(run_dir, "eval.json")):
        return None  # not finished
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
        with open(os.path.join(run_dir, "eval.json")) as f:
            final = json.load(f)
    except OSError as e:
        raise InputError(f"{e.filename}: cannot read ({e.strerror}); run without --report-only first")
    steps = [float(r["global_step"]) for r in rows]
    def column(key):
        return [float(r[key]) if r.get(key) not in (None, "", "nan") else math.nan for r in rows]
    wall = [float(r["wall_seconds"]) for r in rows]
    run = {"steps": steps, "success": column("success_rate"), "return": column("episode_return"),
           "final": final["success_rate"], "env_steps": final["env_steps"]}
    # The first bin of BIN steps whose training success averages THRESHOLD or more, and the
    # training time by its end (single iterations are too noisy to judge by).
    per_bin = binned(run, int(steps[-1] // BIN))
    reached = next((b for b, v in enumerate(per_bin) if v >= THRESHOLD), None)
    run["to_threshold"] = None
    if reached is not None:
        end = (reached + 1) * BIN
        run["to_threshold"] = (end, max(w for st, w in zip(steps, wall) if st <= end))
    return run


def binned(run, bins, key="success"):
    """The run's training success (or `key`) averaged over each bin of BIN environment steps."""
    sums, counts = [0.0] * bins, [0] * bins
    for step, value in zip(run["steps"], run[key]):
        b = int((step - 1) // BIN)
        if b < bins and not math.isnan(value):
            sums[b] += value
            counts[b] += 1
    return [s / c if c else math.nan for s, c in zip(sums, counts)]


def curve(ax, rs, key, label):
    """Learners log at different rollout sizes: each run's `key` is averaged over bins of BIN
    environment steps, then the bins over seeds (mean, and the range as a band)."""
    bins = max(1, int(min(r["steps"][-1] for r in rs) // BIN))
    per_run = [binned(r, bins, key) for r in rs]
    x, mean, low, high = [], [], [], []
    for b in range(bins):
        v = [p[b] for p in per_run if not math.isnan(p[b])]
        if v:
            x.append((b + 0.5) * BIN / 1e6)
            mean.append(sum(v) / len(v)), low.append(min(v)), high.append(max(v))
    ax.plot(x, mean, label=label)
    ax.fill_between(x, low, high, alpha=0.25)


def fmt_steps(x):
    return f"{x / 1e6:.1f}M"


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--skills", default="walker_forward")
    p.add_argument("--learners", default="ppo,trpo")
    p.add_argument("--seeds", default="1,2,3")
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--runs", default="runs/learners")
    p.add_argument("--steps", default="", help="every run's environment-step budget, or LEARNER=N,... "
                   "(default: the recipes')")
    p.add_argument("--report-only", action="store_true", help="read finished runs, train nothing")
    p.add_argument("--out", default="docs/learner_comparison")
    args = p.parse_args()
    skills, learners = args.skills.split(","), args.learners.split(",")
    try:
        seeds = [int(s) for s in args.seeds.split(",")]
    except ValueError:
        raise InputError(f"--seeds: expected integers, got '{args.seeds}'")
    try:
        pairs = [item.split("=", 1) if "=" in item else ["*", item] for item in filter(None, args.steps.split(","))]
        budgets = {k: int(v) for k, v in pairs}
    except ValueError:
        raise InputError(f"--steps: expected N or LEARNER=N,..., got '{args.steps}'")
    args.budgets = budgets
    runs = {}
    for skill in skills:
        for learner in learners:
            for seed in seeds:
                run_dir = os.path.join(args.runs, skill, learner, f"seed{seed}")
                if not args.report_only:
                    train(skill, learner, seed, args)
                run = read_run(run_dir)
                if run:
                    runs[skill, learner, seed] = run
    if not runs:
        raise InputError(f"no finished run under {args.runs}; run without --report-only first")

    lines = ["Final success: the deterministic policy's success in each run's own evaluation (50 episodes),",
             "mean and range over the seeds listed (unfinished runs are left out). Steps and wall time to",
             f"{THRESHOLD:.0%}: until the training episodes first succeed {THRESHOLD:.0%} of the time over {BIN // 1000}k steps",
             "(median over the seeds that get there; wall time is training time, rollout and update).",
             f"Success at equal steps: the training episodes' success over the last {BIN // 1000}k steps of the",
             "smallest budget among the skill's learners (mean over seeds).", "",
             "| skill | learner | seeds | env steps | final success | success at equal steps | seeds at 90% | steps to 90% | wall time to 90% |",
             "|---|---|---|---|---|---|---|---|---|"]
    fig, axes = plt.subplots(2, len(skills), figsize=(6 * len(skills), 7.5), squeeze=False)
    for k, skill in enumerate(skills):
        common = min((r["env_steps"] for (sk, _, _), r in runs.items() if sk == skill), default=0)
        for learner in learners:
            done = [s for s in seeds if (skill, learner, s) in runs]
            if not done:
                continue
            rs = [runs[skill, learner, s] for s in done]
            finals = [r["final"] for r in rs]
            reached = sorted(r["to_threshold"] for r in rs if r["to_threshold"])
            mid = reached[len(reached) // 2] if reached else None
            at_common = [binned(r, int(common // BIN))[-1] for r in rs] if common >= BIN else []
            at_common = [v for v in at_common if not math.isnan(v)]
            lines.append(f"| {skill} | {learner} | {','.join(map(str, done))} | {fmt_steps(rs[0]['env_steps'])} | "
                         f"{sum(finals) / len(finals):.0%} ({min(finals):.0%}-{max(finals):.0%}) | "
                         f"{f'{sum(at_common) / len(at_common):.0%} at {fmt_steps(common)}' if at_common else '-'} | "
                         f"{len(reached)}/{len(rs)} | {fmt_steps(mid[0]) if mid else '-'} | "
                         f"{f'{mid[1] / 60:.0f} min' if mid else '-'} |")
            for row, key in enumerate(("success", "return")):
                curve(axes[row][k], rs, key, f"{learner} (mean of {len(rs)} seeds)")
        for row, label in enumerate(("training success rate", "training episode return")):
            ax = axes[row][k]
            ax.set_title(f"{skill}: mean over seeds, band = range")
            ax.set_xlabel("environment steps (millions)")
            ax.set_ylabel(f"{label} (per {BIN // 1000}k steps)")
            ax.grid(alpha=0.3)
            ax.legend(loc="lower right")
        axes[0][k].set_ylim(-0.02, 1.02)
    fig.tight_layout()
    cmd = "python3 tools/compare_learners.py " + " ".join(
        f"--{k.replace('_', '-')} {v}" for k, v in vars(args).items()
        if k not in ("report_only", "out", "threads", "budgets") and v not in (0, None, ""))
    if args.report_only:  # the runs may have been trained with other budgets per skill
        lines += ["", f"Produced by `{cmd} --report-only` from finished runs (each run's budget is in the env",
                  "steps column); the band is the range over seeds.", ""]
    else:
        lines += ["", f"Produced by `{cmd}`; the band is the range over seeds.", ""]
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    fig.savefig(args.out + ".png", dpi=110)
    with open(args.out + ".md", "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    try:
        main()
    except InputError as e:
        print(f"error: {e}", file=sys.stderr)
        sys.exit(2)
