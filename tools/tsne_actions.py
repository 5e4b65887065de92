#!/usr/bin/env python3
"""t-SNE of policy actions, drawn as a scatter plot (PNG or SVG by the output's extension).

Reproduces the kind of figure in Byun & Perrault, "Training Transition Policies via
Distribution Matching for Complex Tasks" (ICLR 2022), Fig. 4: the actions of pi_a, the
transition policy pi_ab and pi_b within one transition interval, embedded in 2-D with
t-SNE (scikit-learn's exact method), one colour per policy (matplotlib).

usage: tools/tsne_actions.py INPUT.csv OUT.png [--perplexity 30] [--seed 0]
           [--iterations 1000] [--max-points 1500] [--learning-rate 200|auto] [--title TEXT]

INPUT.csv has a header `label,a0,a1,...,aK` and one row per action; the label is a short
string (pi_a, pi_ab, pi_b, ...). Labels keep their order of first appearance for colours
and legend. With more rows than --max-points, each label is subsampled in proportion,
deterministically from --seed. For each label, stdout gets one tab-separated line:
`LABEL  count=N  knn10_purity=F`, F being the mean fraction of a point's 10 nearest
neighbours in the embedding that share its label (1.0: the groups are fully separated).
Input errors print one line to stderr and exit 2.
"""
import os

# One BLAS thread: repeatable results, and the tool stays off the other cores.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from sklearn.manifold import TSNE  # noqa: E402
from sklearn.neighbors import NearestNeighbors  # noqa: E402

PROG = "tsne_actions.py"
# Okabe-Ito palette (colour-blind friendly); the pale yellow goes last.
COLOURS = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9",
           "#000000", "#F0E442"]
NEIGHBOURS = 10


class InputError(Exception):
    """An error in the user's input; reported on one line, exit status 2."""


def read_csv(path):
    """Returns (labels in first-appearance order, label index per row, X[N, K])."""
    try:
        f = open(path, newline="", encoding="utf-8-sig")
    except OSError as e:
        raise InputError(f"{path}: cannot open: {e.strerror or e}")
    label_ids, label_order, rows = {}, [], []
    try:
        with f:
            reader = csv.reader(f)
            header = None
            for row in reader:
                line = reader.line_num
                if not row or all(not c.strip() for c in row):
                    continue
                if header is None:
                    header = [c.strip() for c in row]
                    if len(header) < 2 or header[0].lower() != "label":
                        raise InputError(f"{path}:{line}: bad header: expected "
                                         "'label,a0,a1,...', got "
                                         f"'{','.join(row)[:60]}'")
                    if any(not c for c in header[1:]):
                        raise InputError(f"{path}:{line}: bad header: empty column name")
                    continue
                if len(row) != len(header):
                    raise InputError(f"{path}:{line}: expected {len(header)} fields, "
                                     f"got {len(row)}")
                label = row[0].strip()
                if not label:
                    raise InputError(f"{path}:{line}: empty label")
                values = []
                for col, cell in zip(header[1:], row[1:]):
                    try:
                        v = float(cell)
                    except ValueError:
                        raise InputError(f"{path}:{line}: column '{col}': "
                                         f"not a number: '{cell.strip()[:40]}'")
                    if not math.isfinite(v):
                        raise InputError(f"{path}:{line}: column '{col}': "
                                         f"not a finite number: '{cell.strip()}'")
                    values.append(v)
                if label not in label_ids:
                    label_ids[label] = len(label_order)
                    label_order.append(label)
                rows.append((label_ids[label], values))
    except csv.Error as e:
        raise InputError(f"{path}:{reader.line_num}: malformed CSV: {e}")
    except UnicodeDecodeError:
        raise InputError(f"{path}: not UTF-8 text")
    except OSError as e:
        raise InputError(f"{path}: read error: {e.strerror or e}")
    if header is None:
        raise InputError(f"{path}: empty file (expected header 'label,a0,a1,...')")
    if not rows:
        raise InputError(f"{path}: no data rows")
    if len(label_order) < 2:
        raise InputError(f"{path}: need at least 2 distinct labels, found "
                         f"{len(label_order)} ('{label_order[0]}')")
    y = np.array([r[0] for r in rows], dtype=np.int64)
    X = np.array([r[1] for r in rows], dtype=np.float64)
    return label_order, y, X


def subsample(y, n_labels, max_points, rng):
    """Row indices: every row when len(y) <= max_points, otherwise each label in
    proportion (largest remainder, at least one row per label), sorted."""
    n = len(y)
    if n <= max_points:
        return np.arange(n)
    counts = np.bincount(y, minlength=n_labels)
    quota = counts * (max_points / n)
    take = np.floor(quota).astype(np.int64)
    short = max_points - int(take.sum())
    order = sorted(range(n_labels), key=lambda l: (-(quota[l] - take[l]), l))
    for l in order[:short]:
        take[l] += 1
    take = np.minimum(np.maximum(take, 1), counts)
    keep = []
    for l in range(n_labels):
        idx = np.flatnonzero(y == l)
        keep.append(rng.choice(idx, size=int(take[l]), replace=False))
    return np.sort(np.concatenate(keep))


def embed(X, perplexity, seed, iterations, learning_rate):
    perplexity = min(perplexity, (len(X) - 1) / 3.0)  # sklearn needs perplexity < n
    kwargs = dict(n_components=2, perplexity=perplexity, init="pca", random_state=seed,
                  method="exact", learning_rate=learning_rate)
    try:
        tsne = TSNE(max_iter=iterations, **kwargs)
    except TypeError:  # scikit-learn before 1.5 calls it n_iter
        tsne = TSNE(n_iter=iterations, **kwargs)
    return tsne.fit_transform(X)


def knn_purity(Y, y, k=NEIGHBOURS):
    k = min(k, len(Y) - 1)
    idx = NearestNeighbors(n_neighbors=k + 1).fit(Y).kneighbors(Y, return_distance=False)[:, 1:]
    return (y[idx] == y[:, None]).mean(axis=1)


def draw(Y, y, labels, out, title):
    fig, ax = plt.subplots(figsize=(6, 5))
    for l, name in enumerate(labels):
        pts = Y[y == l]
        ax.scatter(pts[:, 0], pts[:, 1], s=8, alpha=0.7, color=COLOURS[l % len(COLOURS)], label=name)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.legend(markerscale=2)
    if title:
        ax.set_title(title)
    fig.tight_layout()
    fig.savefig(out, dpi=100, metadata={"Software": None} if out.endswith(".png") else None)
    plt.close(fig)


def main(argv):
    ap = argparse.ArgumentParser(prog=PROG, description="t-SNE of policy actions")
    ap.add_argument("input")
    ap.add_argument("output")
    ap.add_argument("--perplexity", type=float, default=30.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--iterations", type=int, default=1000)
    ap.add_argument("--max-points", type=int, default=1500)
    ap.add_argument("--learning-rate", default="200")
    ap.add_argument("--title", default="")
    a = ap.parse_args(argv)
    try:
        if a.perplexity <= 0 or a.iterations < 250 or a.max_points < 3:
            raise InputError("--perplexity must be > 0, --iterations >= 250, --max-points >= 3")
        lr = "auto" if a.learning_rate == "auto" else float(a.learning_rate)
        labels, y, X = read_csv(a.input)
        keep = subsample(y, len(labels), a.max_points, np.random.default_rng(a.seed))
        y, X = y[keep], X[keep]
        if len(X) < 3:
            raise InputError(f"{a.input}: need at least 3 rows, found {len(X)}")
        Y = embed(X, a.perplexity, a.seed, a.iterations, lr)
        draw(Y, y, labels, a.output, a.title)
    except InputError as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        return 2
    purity = knn_purity(Y, y)
    for l, name in enumerate(labels):
        print(f"{name}\tcount={int((y == l).sum())}\tknn10_purity={purity[y == l].mean():.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
