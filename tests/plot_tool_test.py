#!/usr/bin/env python3
"""Test of tools/plot.py: learning curves from a small two-stage metrics.csv and a methods
chart from a small results table are PNG files (signature, plausible size); a run directory
without CSVs exits 2 with one line. Registered with CTest as PlotTool."""
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOOL = os.path.join(ROOT, "tools", "plot.py")
PNG = b"\x89PNG\r\n\x1a\n"
failures = []


def check(cond, message):
    if not cond:
        failures.append(message)
        print("FAIL: " + message)


def is_png(path):
    return os.path.isfile(path) and open(path, "rb").read(8) == PNG and os.path.getsize(path) > 10_000


with tempfile.TemporaryDirectory(prefix="plot_tool_test_") as tmp:
    run = os.path.join(tmp, "run")
    os.makedirs(run)
    with open(os.path.join(run, "metrics.csv"), "w") as f:
        f.write("stage,iteration,global_step,episode_return,success_rate,entropy\n")
        for i in range(1, 21):
            f.write(f"{'first' if i <= 10 else 'second'},{i},{i * 1024},{i * 1.5},{i / 20},{5 - i * 0.1}\n")
    p = subprocess.run([sys.executable, TOOL, "curves", run], capture_output=True, text=True)
    check(p.returncode == 0, f"curves exit {p.returncode}: {p.stderr}")
    check(is_png(os.path.join(run, "curves.png")), "curves.png is not a PNG of plausible size")

    results = os.path.join(tmp, "hurdle.json")
    json.dump({"tp": {"mean": 1.0, "std": 0.5}, "tp+q": {"mean": 3.0, "std": 1.0}}, open(results, "w"))
    p = subprocess.run([sys.executable, TOOL, "methods", results], capture_output=True, text=True)
    check(p.returncode == 0, f"methods exit {p.returncode}: {p.stderr}")
    check(is_png(os.path.join(tmp, "hurdle.png")), "hurdle.png is not a PNG of plausible size")

    empty = os.path.join(tmp, "empty")
    os.makedirs(empty)
    p = subprocess.run([sys.executable, TOOL, "curves", empty], capture_output=True, text=True)
    check(p.returncode == 2, f"a run without CSVs exits {p.returncode}, expected 2")
    check(p.stderr.count("\n") == 1 and "empty" in p.stderr, f"one line naming the folder, got {p.stderr!r}")

print("1 passed, 0 failed" if not failures else f"0 passed, 1 failed")
sys.exit(1 if failures else 0)
