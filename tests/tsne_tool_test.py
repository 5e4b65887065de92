#!/usr/bin/env python3
"""Test of tools/tsne_actions.py (the t-SNE action plot, cf. Byun & Perrault 2022, Fig. 4).

Runs the tool as a subprocess on generated CSVs and checks: three well-separated 6-D
Gaussian clusters give a PNG and a 10-NN label purity above 0.9 for every label; a bad
value exits 2 with a one-line message naming the file and line; the same input and seed
give a byte-identical PNG.
Exit status 0 on success. Registered with CTest as TsneTool.
"""
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOOL = os.path.join(ROOT, "tools", "tsne_actions.py")
LABELS = ["pi_a", "pi_ab", "pi_b"]
PER_LABEL = 100
DIM = 6
failures = []


def check(cond, message):
    if not cond:
        failures.append(message)
        print("FAIL: " + message)
    return cond


def write_clusters(path):
    rng = np.random.default_rng(12345)
    with open(path, "w") as f:
        f.write("label," + ",".join(f"a{i}" for i in range(DIM)) + "\n")
        rows = []
        for k, label in enumerate(LABELS):
            mean = np.zeros(DIM)
            mean[k] = 8.0  # pairwise distance between means: 8 * sqrt(2)
            for x in rng.normal(mean, 1.0, size=(PER_LABEL, DIM)):
                rows.append(label + "," + ",".join(f"{v:.6f}" for v in x))
        # interleave the labels so first-appearance order, not file blocks, is tested
        first_seen = []
        for i in rng.permutation(len(rows)):
            f.write(rows[i] + "\n")
            label = rows[i].split(",", 1)[0]
            if label not in first_seen:
                first_seen.append(label)
    return first_seen


def run(args):
    t0 = time.monotonic()
    p = subprocess.run([sys.executable, TOOL] + args, capture_output=True, text=True,
                       timeout=120)
    return p, time.monotonic() - t0


def main():
    with tempfile.TemporaryDirectory(prefix="tsne_tool_test_") as tmp:
        csv_path = os.path.join(tmp, "clusters.csv")
        label_order = write_clusters(csv_path)

        # 1. separated clusters: a PNG, and every label's 10-NN purity above 0.9
        png1 = os.path.join(tmp, "out1.png")
        p, secs = run([csv_path, png1, "--seed", "3", "--title", "clusters & <test>"])
        print(f"tool run: {secs:.1f} s, exit {p.returncode}")
        print(p.stdout, end="")
        if p.stderr:
            print("stderr: " + p.stderr, end="")
        if check(p.returncode == 0, f"exit status {p.returncode}, expected 0"):
            check(os.path.isfile(png1) and open(png1, "rb").read(8) == b"\x89PNG\r\n\x1a\n"
                  and os.path.getsize(png1) > 10_000, "no PNG of plausible size written")
            lines = p.stdout.strip().splitlines()
            check([l.split("\t")[0] for l in lines] == label_order,
                  f"labels not in first-appearance order: {lines}")
            for line in lines:
                m = re.search(r"count=(\d+)\s+knn10_purity=([0-9.]+)", line)
                if check(m is not None, f"bad stdout line: {line!r}"):
                    check(int(m.group(1)) == PER_LABEL, f"count in {line!r}")
                    check(float(m.group(2)) > 0.9, f"separated clusters mixed: {line!r}")

        # 2. determinism: same input and seed, the same picture and figures
        png2 = os.path.join(tmp, "out2.png")
        p2, _ = run([csv_path, png2, "--seed", "3", "--title", "clusters & <test>"])
        if check(p2.returncode == 0, "second run failed") and os.path.isfile(png1) and os.path.isfile(png2):
            with open(png1, "rb") as a, open(png2, "rb") as b:
                check(a.read() == b.read(), "same input and seed gave different PNGs")
            check(p2.stdout == p.stdout, "same input and seed gave different stdout")

        # 3. a bad value: exit 2, one line naming the file and the line number
        bad = os.path.join(tmp, "bad_values.csv")
        with open(csv_path) as f:
            lines = f.read().splitlines()
        fields = lines[5].split(",")
        fields[3] = "abc"
        lines[5] = ",".join(fields)  # file line 6
        with open(bad, "w") as f:
            f.write("\n".join(lines) + "\n")
        svg3 = os.path.join(tmp, "bad.png")
        p3, _ = run([bad, svg3])
        err = p3.stderr.strip()
        print(f"bad value: exit {p3.returncode}, stderr: {err}")
        check(p3.returncode == 2, f"bad value: exit status {p3.returncode}, expected 2")
        check(len(err.splitlines()) == 1, f"bad value: stderr not one line: {p3.stderr!r}")
        check("bad_values.csv" in err, "bad value: message does not name the file")
        check(":6:" in err, "bad value: message does not give line 6")
        check("Traceback" not in p3.stderr, "bad value: Python traceback")
        check(not os.path.exists(svg3), "bad value: a picture was written anyway")

        # 4. other input errors: same contract
        one_label = os.path.join(tmp, "one_label.csv")
        with open(one_label, "w") as f:
            f.write("label,a0,a1\n" + "".join(f"pi_a,{i},{i * i}\n" for i in range(10)))
        cases = [(os.path.join(tmp, "missing.csv"), "missing.csv"),
                 (one_label, "one_label.csv")]
        bad_header = os.path.join(tmp, "bad_header.csv")
        with open(bad_header, "w") as f:
            f.write("policy,a0\npi_a,1\npi_b,2\n")
        cases.append((bad_header, "bad_header.csv"))
        for path, name in cases:
            p4, _ = run([path, os.path.join(tmp, "x.png")])
            err = p4.stderr.strip()
            print(f"{name}: exit {p4.returncode}, stderr: {err}")
            check(p4.returncode == 2 and len(err.splitlines()) == 1 and name in err
                  and "Traceback" not in p4.stderr, f"{name}: bad error report")

    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
