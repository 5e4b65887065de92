#!/usr/bin/env python3
"""Test of tools/compare_learners.py --report-only on hand-made runs: two learners with
different budgets meet at the smaller one (the training success of its last 100k-step bin),
the steps and wall time to 90% are those of the first bin that averages 90%, and a malformed
--steps exits 2 with one line. Registered with CTest as CompareLearnersTool."""
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOOL = os.path.join(ROOT, "tools", "compare_learners.py")
failures = []


def check(cond, message):
    if not cond:
        failures.append(message)
        print("FAIL: " + message)


def make_run(runs, learner, budget, success, final):
    """One row per 100k steps; success(step) gives the training success, wall time is step / 1000 s."""
    run = os.path.join(runs, "walker_forward", learner, "seed1")
    os.makedirs(run)
    with open(os.path.join(run, "metrics.csv"), "w") as f:
        f.write("iteration,global_step,success_rate,wall_seconds\n")
        for i, step in enumerate(range(100_000, budget + 1, 100_000), 1):
            f.write(f"{i},{step},{success(step)},{step / 1000}\n")
    json.dump({"success_rate": final, "env_steps": budget}, open(os.path.join(run, "eval.json"), "w"))


with tempfile.TemporaryDirectory(prefix="compare_learners_test_") as tmp:
    runs = os.path.join(tmp, "runs")
    make_run(runs, "ppo", 1_000_000, lambda step: step / 1e6, 0.96)  # 10%, 20%, ... per bin
    make_run(runs, "sac", 300_000, lambda step: 0.5, 0.5)
    out = os.path.join(tmp, "cmp")
    p = subprocess.run([sys.executable, TOOL, "--learners", "ppo,sac", "--seeds", "1", "--runs", runs,
                        "--report-only", "--out", out], capture_output=True, text=True)
    check(p.returncode == 0, f"exit {p.returncode}: {p.stderr}")
    table = open(out + ".md").read() if os.path.exists(out + ".md") else ""
    # ppo at 0.3M: its third bin, 30%; first bin at 90%: the ninth, ending at 0.9M, 900 s.
    check("| walker_forward | ppo | 1 | 1.0M | 96% (96%-96%) | 30% at 0.3M | 1/1 | 0.9M | 15 min |" in table,
          "ppo's row:\n" + table)
    check("| walker_forward | sac | 1 | 0.3M | 50% (50%-50%) | 50% at 0.3M | 0/1 | - | - |" in table,
          "sac's row:\n" + table)
    check(os.path.getsize(out + ".png") > 10_000 if os.path.exists(out + ".png") else False, "no curves PNG")

    p = subprocess.run([sys.executable, TOOL, "--steps", "ppo=many", "--runs", runs, "--report-only",
                        "--out", out], capture_output=True, text=True)
    check(p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and "--steps" in p.stderr,
          f"--steps ppo=many: exit {p.returncode}, stderr {p.stderr!r}")

if failures:
    sys.exit(1)
print("compare_learners tool: ok")
