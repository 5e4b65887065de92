#!/usr/bin/env python3
"""Test of tools/tsne_actions.py (the t-SNE action plot, cf. Byun & Perrault 2022, Fig. 4).

Runs the tool as a subprocess on generated CSVs and checks: three well-separated 6-D
Gaussian clusters give a well-formed SVG with one class="pt" circle per row and a
10-NN label purity above 0.9 for every label; a bad value exits 2 with a one-line
message naming the file and line; the same input and seed give a byte-identical SVG.
Exit status 0 on success. Registered with CTest as TsneTool.
"""
import os
import re
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOOL = os.path.join(ROOT, "tools", "tsne_actions.py")
SVG_NS = "{http://www.w3.org/2000/svg}"
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

        # 1. separated clusters
        svg1 = os.path.join(tmp, "out1.svg")
        p, secs = run([csv_path, svg1, "--seed", "3", "--title", "clusters & <test>"])
        print(f"tool run: {secs:.1f} s, exit {p.returncode}")
        print(p.stdout, end="")
        if p.stderr:
            print("stderr: " + p.stderr, end="")
        if check(p.returncode == 0, f"exit status {p.returncode}, expected 0") and \
                check(os.path.isfile(svg1), "no SVG written"):
            try:
                root = ET.parse(svg1).getroot()
            except ET.ParseError as e:
                check(False, f"SVG does not parse as XML: {e}")
                root = None
            if root is not None:
                check(root.tag == SVG_NS + "svg", f"root element is {root.tag}")
                circles = list(root.iter(SVG_NS + "circle"))
                points = [c for c in circles if "pt" in c.get("class", "").split()]
                check(len(points) == PER_LABEL * len(LABELS),
                      f"{len(points)} point circles, expected {PER_LABEL * len(LABELS)}")
                check(len(circles) > len(points), "no legend markers")
                fills = {c.get("fill") for c in points}
                check(len(fills) == len(LABELS), f"point colours {sorted(fills)}")
                texts = " ".join(t.text or "" for t in root.iter(SVG_NS + "text"))
                check("clusters & <test>" in texts, "title missing or badly escaped")
                for label in LABELS:
                    check(f"{label} (n={PER_LABEL})" in texts, f"legend lacks {label}")
            lines = p.stdout.strip().splitlines()
            check(len(lines) == len(LABELS), f"{len(lines)} stdout lines, expected 3")
            seen = []
            for line in lines:
                m = re.fullmatch(r"(\S+)\tcount=(\d+)\tknn10_purity=([0-9.]+)", line)
                if not check(m is not None, f"unexpected stdout line: {line!r}"):
                    continue
                seen.append(m.group(1))
                check(int(m.group(2)) == PER_LABEL, f"count in {line!r}")
                check(float(m.group(3)) > 0.9, f"purity not > 0.9: {line!r}")
            check(seen == label_order,
                  f"labels printed as {seen}, first-appearance order is {label_order}")

        # 2. determinism: same input and seed, byte-identical SVG
        svg2 = os.path.join(tmp, "out2.svg")
        p2, _ = run([csv_path, svg2, "--seed", "3", "--title", "clusters & <test>"])
        if check(p2.returncode == 0, f"second run exit status {p2.returncode}") and \
                os.path.isfile(svg1) and os.path.isfile(svg2):
            with open(svg1, "rb") as a, open(svg2, "rb") as b:
                check(a.read() == b.read(), "same input and seed gave different SVGs")
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
        svg3 = os.path.join(tmp, "bad.svg")
        p3, _ = run([bad, svg3])
        err = p3.stderr.strip()
        print(f"bad value: exit {p3.returncode}, stderr: {err}")
        check(p3.returncode == 2, f"bad value: exit status {p3.returncode}, expected 2")
        check(len(err.splitlines()) == 1, f"bad value: stderr not one line: {p3.stderr!r}")
        check("bad_values.csv" in err, "bad value: message does not name the file")
        check(":6:" in err, "bad value: message does not give line 6")
        check("Traceback" not in p3.stderr, "bad value: Python traceback")
        check(not os.path.exists(svg3), "bad value: an SVG was written anyway")

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
            p4, _ = run([path, os.path.join(tmp, "x.svg")])
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
