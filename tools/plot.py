#!/usr/bin/env python3
"""Pictures of Segue's runs and results, drawn with matplotlib (PNG).

  tools/plot.py curves RUN_DIR [--out FILE.png]
      Learning curves from RUN_DIR's CSVs against environment steps: for a skill run
      (metrics.csv) the episode return, success rate and policy entropy, one colour per
      stage of a curriculum; for a composite run, each transition's AIRL training
      (A-B/transition.csv: the share of episodes that complete the interval, D's loss and
      its accuracies on expert and generator rows). Default output RUN_DIR/curves.png.
  tools/plot.py methods RESULTS.json [--out FILE.png]
      The methods' mean success counts (+- std) beside the paper's (tools/paper_results.json),
      for a table written by `segue report`. Default output RESULTS.png.

  tools/plot.py diagnose DIAGNOSIS.json --out FILE.png
      `segue diagnose --plot`: per transition the share of hand-overs after which pi_b
      succeeds (at the interval's start, at its end, where q_ab switches, at the best point
      in hindsight) beside pi_b alone from its own start, and how the method's evaluation
      episodes ended.

  tools/plot.py montage FRAME.png ... --out FILE.png [--titles a,b,...]
      Frames from `segue render --frames` side by side, one per panel.

Bad input prints one line to stderr and exits 2.
"""
import argparse
import csv
import glob
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The most a task's success count can be (docs/reference/tasks.md#episode-limits).
MAXIMA = {"repetitive_picking": 5, "repetitive_catching": 5, "serve": 1, "patrol": 5, "hurdle": 5,
          "obstacle_course": 5}
METHODS = [("single", "Single"), ("without-tp", "Without TP"), ("tp", "With TP"),
           ("lee", "Lee et al. 2019"), ("tp+q", "With TP + Q")]


class InputError(Exception):
    pass


def read_csv(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        raise InputError(f"{path}: cannot read ({e.strerror})")
    if not rows:
        raise InputError(f"{path}: no rows")
    return rows


def column(rows, name):
    out = []
    for r in rows:
        try:
            out.append(float(r[name]))
        except (KeyError, TypeError, ValueError):
            out.append(math.nan)
    return out


def tidy_axes(axes, rates):
    """Readable step ticks (a few, in scientific notation) on every axis; rates in [0, 1]."""
    for ax in axes:
        ax.xaxis.set_major_locator(MaxNLocator(5))
        ax.ticklabel_format(axis="x", style="sci", scilimits=(0, 0))
    for ax in rates:
        ax.set_ylim(-0.03, 1.03)


def skill_curves(run_dir, out):
    rows = read_csv(os.path.join(run_dir, "metrics.csv"))
    for needed in ("global_step", "episode_return", "success_rate", "entropy"):
        if needed not in rows[0]:
            raise InputError(f"{run_dir}/metrics.csv: no column '{needed}'")
    stages = []
    for r in rows:
        s = r.get("stage", "")
        if s not in stages:
            stages.append(s)
    # A curriculum's stages may restart their step counters: lay them end to end.
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
    offset = 0.0
    for s in stages:
        part = [r for r in rows if r.get("stage", "") == s]
        steps = column(part, "global_step")
        if steps and steps[0] <= offset * 0.5 and offset > 0:
            steps = [x + offset for x in steps]
        for ax, key, title in zip(axes, ("episode_return", "success_rate", "entropy"),
                                  ("episode return", "success rate", "policy entropy")):
            ax.plot(steps, column(part, key), label=s or None, linewidth=1.2)
            ax.set_title(title)
            ax.set_xlabel("environment steps")
        offset = max(offset, max(steps))
    if any(stages):
        axes[0].legend(fontsize=7)
    tidy_axes(axes, [axes[1]])
    fig.suptitle(os.path.basename(os.path.normpath(run_dir)))
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def transition_curves(run_dir, files, out):
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
    for path in files:
        rows = read_csv(path)
        name = os.path.basename(os.path.dirname(path))
        steps = column(rows, "global_step")
        axes[0].plot(steps, column(rows, "interval_completed"), label=name)
        axes[1].plot(steps, column(rows, "disc_loss"), label=name)
        axes[2].plot(steps, column(rows, "expert_accuracy"), label=name + " expert")
        axes[2].plot(steps, column(rows, "generator_accuracy"), "--", label=name + " generator")
    for ax, title in zip(axes, ("interval completed", "D loss", "D accuracy")):
        ax.set_title(title)
        ax.set_xlabel("environment steps")
        ax.legend(fontsize=7)
    tidy_axes(axes, [axes[0], axes[2]])
    fig.suptitle(os.path.basename(os.path.normpath(run_dir)) + ": transition policies (AIRL)")
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def methods_chart(results_path, out):
    try:
        ours = json.load(open(results_path))
    except (OSError, ValueError) as e:
        raise InputError(f"{results_path}: cannot read a results table ({e})")
    task = os.path.splitext(os.path.basename(results_path))[0]
    paper = json.load(open(os.path.join(ROOT, "tools", "paper_results.json")))["tasks"].get(task, {})
    names = [(k, label) for k, label in METHODS if k in ours or k in paper]
    if not names:
        raise InputError(f"{results_path}: no method of the paper in it")
    fig, ax = plt.subplots(figsize=(8, 4.2))
    width = 0.38
    xs = range(len(names))
    top = MAXIMA.get(task)

    def whiskers(means, stds):  # a count lies in [0, maximum]: the whiskers stop there
        low = [min(s, m) if not math.isnan(m) else 0 for m, s in zip(means, stds)]
        high = [min(s, top - m) if top and not math.isnan(m) else s for m, s in zip(means, stds)]
        return [low, high]

    mean = [ours.get(k, {}).get("mean", math.nan) for k, _ in names]
    std = [ours.get(k, {}).get("std", 0.0) for k, _ in names]
    ax.bar([x - width / 2 for x in xs], mean, width, yerr=whiskers(mean, std), capsize=3, label="Segue",
           color="#0072B2")
    pm = [paper.get(k, [math.nan, 0])[0] for k, _ in names]
    ps = [paper.get(k, [math.nan, 0])[1] for k, _ in names]
    ax.bar([x + width / 2 for x in xs], pm, width, yerr=whiskers(pm, ps), capsize=3, label="paper", color="#BBBBBB")
    ax.set_xticks(list(xs))
    ax.set_xticklabels([label for _, label in names])
    ax.set_ylabel("success count")
    if top:
        ax.axhline(top, color="#666666", linewidth=0.8, linestyle=":")
        ax.set_ylim(0, top * 1.25)
    ax.set_title(task.replace("_", " ").capitalize())
    ax.legend()
    episodes = {ours[k].get("episodes") for k, _ in names if k in ours}
    seeds = {len(ours[k].get("seeds", [])) for k, _ in names if k in ours}
    fig.text(0.01, 0.01, f"Bars: mean success count over {'/'.join(map(str, sorted(episodes)))} episodes x "
             f"{'/'.join(map(str, sorted(seeds)))} seeds; whiskers: one standard deviation over the episodes,\n"
             f"cut at 0 and the maximum" + (f"; dotted line: the maximum, {top}." if top else "."), fontsize=8)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    fig.savefig(out, dpi=100)


def diagnosis_chart(path, out):
    try:
        d = json.load(open(path))
        transitions, ends = d["transitions"], d["ends"]
    except (OSError, ValueError, KeyError) as e:
        raise InputError(f"{path}: cannot read a diagnosis ({e})")
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4), gridspec_kw={"width_ratios": [3, 2]})
    kinds = [("at_start", "at the start (Without TP)", "#BBBBBB"), ("at_end", "at the end (With TP)", "#56B4E9"),
             ("with_q", "where q_ab switches", "#0072B2"), ("best_fixed", "best fixed point", "#009E73"),
             ("oracle", "best point per state, in hindsight", "#E69F00")]
    width = 0.8 / len(kinds)
    xs = range(len(transitions))
    for i, (key, label, colour) in enumerate(kinds):
        values = [t[key] if t.get(key) is not None else math.nan for t in transitions]
        left.bar([x - 0.4 + (i + 0.5) * width for x in xs], values, width, label=label, color=colour)
    # pi_b alone from its own start (its own task), where the diagnosis measured it.
    alone = {a["skill"]: a["success"] for a in d.get("skills", []) if a.get("success") is not None}
    marked = False
    for x, t in zip(xs, transitions):
        b = next((k for k in alone if t["transition"].endswith("-" + k)), None)
        if b is not None:
            left.hlines(alone[b], x - 0.45, x + 0.45, colors="black", linestyles="dashed",
                        label=None if marked else "pi_b alone, its own start")
            marked = True
    left.set_xticks(list(xs))
    left.set_xticklabels([t["transition"] for t in transitions], rotation=20 if len(transitions) > 3 else 0)
    left.set_ylim(0, 1.05)
    left.set_ylabel("hand-overs after which pi_b succeeds")
    left.set_title(f"hand-over, from {transitions[0]['starts'] if transitions else 0} states of S_a each")
    left.legend(fontsize=8, loc="lower left")
    top = ends[:8]
    labels = [f"{e['in_control'] or '-'}, count {e['success_count']}, {e['how']}" for e in top]
    right.barh(range(len(top)), [e["episodes"] for e in top], color="#0072B2")
    right.set_yticks(range(len(top)))
    right.set_yticklabels(labels, fontsize=8)
    right.invert_yaxis()
    right.set_xlabel("episodes")
    right.set_title(f"{d['method']}: how its {d['episodes']} episodes ended")
    fig.suptitle(f"{d['task'].replace('_', ' ')}: mean success count {d['success_count_mean']:.2f}")
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def montage(frames, titles, out):
    images = []
    for f in frames:
        try:
            images.append(plt.imread(f))
        except (OSError, ValueError, SyntaxError) as e:
            raise InputError(f"{f}: cannot read a picture ({e})")
    fig, axes = plt.subplots(1, len(images), figsize=(3.2 * len(images), 2.9))
    for i, (ax, img) in enumerate(zip(axes if len(images) > 1 else [axes], images)):
        ax.imshow(img)
        ax.axis("off")
        if i < len(titles):
            ax.set_title(titles[i])
    fig.tight_layout(pad=0.8)
    fig.savefig(out, dpi=100)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="what", required=True)
    c = sub.add_parser("curves")
    c.add_argument("run_dir")
    c.add_argument("--out")
    m = sub.add_parser("methods")
    m.add_argument("results")
    m.add_argument("--out")
    dg = sub.add_parser("diagnose")
    dg.add_argument("diagnosis")
    dg.add_argument("--out", required=True)
    g = sub.add_parser("montage")
    g.add_argument("frames", nargs="+")
    g.add_argument("--out", required=True)
    g.add_argument("--titles", default="")
    a = ap.parse_args()
    try:
        if a.what == "curves":
            if not os.path.isdir(a.run_dir):
                raise InputError(f"{a.run_dir}: no such run directory")
            out = a.out or os.path.join(a.run_dir, "curves.png")
            transitions = sorted(glob.glob(os.path.join(a.run_dir, "*", "transition.csv")))
            if os.path.exists(os.path.join(a.run_dir, "metrics.csv")):
                skill_curves(a.run_dir, out)
            elif transitions:
                transition_curves(a.run_dir, transitions, out)
            else:
                raise InputError(f"{a.run_dir}: neither metrics.csv nor */transition.csv")
        elif a.what == "diagnose":
            out = a.out
            diagnosis_chart(a.diagnosis, out)
        elif a.what == "montage":
            out = a.out
            montage(a.frames, [t for t in a.titles.split(",") if t], out)
        else:
            out = a.out or os.path.splitext(a.results)[0] + ".png"
            methods_chart(a.results, out)
    except InputError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
