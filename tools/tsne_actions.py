#!/usr/bin/env python3
"""t-SNE of policy actions, drawn as a standalone SVG scatter plot.

Reproduces the kind of figure in Byun & Perrault, "Training Transition Policies via
Distribution Matching for Complex Tasks" (ICLR 2022), Fig. 4: the actions of pi_a, the
transition policy pi_ab and pi_b within one transition interval, embedded in 2-D with
exact t-SNE (van der Maaten & Hinton, JMLR 2008), one colour per policy.

usage: tools/tsne_actions.py INPUT.csv OUT.svg [--perplexity 30] [--seed 0]
           [--iterations 1000] [--max-points 1500] [--learning-rate 200|auto] [--title TEXT]

INPUT.csv has a header `label,a0,a1,...,aK` and one row per action; the label is a short
string (pi_a, pi_ab, pi_b, ...). Labels keep their order of first appearance for colours
and legend. With more rows than --max-points, each label is subsampled in proportion,
deterministically from --seed. For each label, stdout gets one tab-separated line:
`LABEL  count=N  knn10_purity=F`, F being the mean fraction of a point's 10 nearest
neighbours in the embedding that share its label (1.0: the groups are fully separated).

The t-SNE follows the reference implementation (bhtsne, exact gradient): Gaussian input
affinities with a per-point bisection on the precision to match the perplexity,
symmetrised P, Student-t Q, gradient descent with momentum 0.5 then 0.8, early
exaggeration 12 for the first 250 iterations, per-coordinate gains (+0.2 / x0.8, floor
0.01), learning rate 200 (or max(N/12, 50) with --learning-rate auto), and a
deterministic PCA initialisation scaled to standard deviation 1e-4. Only numpy is used;
the O(N^2) loop runs on one thread. Input errors print one line to stderr and exit 2.
"""
import os

# One BLAS thread: repeatable results, and the tool stays off the other cores.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import csv
import math
import sys
from xml.sax.saxutils import escape, quoteattr

import numpy as np

PROG = "tsne_actions.py"
# Okabe-Ito palette (colour-blind friendly); the pale yellow goes last.
COLOURS = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9",
           "#000000", "#F0E442"]
EXAGGERATION = 12.0
EXAGGERATION_ITERS = 250
MOMENTUM_SWITCH_ITER = 250
NEIGHBOURS = 10


class InputError(Exception):
    """An error in the user's input; reported on one line, exit status 2."""


# ----------------------------------------------------------------------------- input

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


# ----------------------------------------------------------------------------- t-SNE

def squared_distances(X):
    s = np.einsum("ij,ij->i", X, X)
    D = -2.0 * (X @ X.T)
    D += s[:, None]
    D += s[None, :]
    np.maximum(D, 0.0, out=D)
    np.fill_diagonal(D, 0.0)
    return D


def conditional_p(X, perplexity, tol=1e-5, max_tries=100):
    """P[i, j] = p_{j|i}: row-normalised Gaussian affinities whose entropy matches
    log(perplexity), found by bisection on beta = 1 / (2 sigma_i^2), all rows at once."""
    n = X.shape[0]
    D = squared_distances(X)
    np.fill_diagonal(D, np.inf)
    D -= D.min(axis=1, keepdims=True)  # shift: P and H are unchanged, exp() cannot underflow
    np.fill_diagonal(D, 0.0)
    off = ~np.eye(n, dtype=bool)
    target = math.log(perplexity)
    beta = np.ones(n)
    lo = np.full(n, -np.inf)
    hi = np.full(n, np.inf)
    active = np.arange(n)
    P = np.zeros((n, n))
    for _ in range(max_tries):
        Da = D[active]
        Pa = np.exp(-Da * beta[active, None]) * off[active]
        sumP = Pa.sum(axis=1)
        H = np.log(sumP) + beta[active] * (Da * Pa).sum(axis=1) / sumP
        P[active] = Pa / sumP[:, None]
        diff = H - target
        todo = np.abs(diff) > tol
        if not todo.any():
            break
        active, diff = active[todo], diff[todo]
        b = beta[active]
        up = diff > 0  # entropy too high: sharpen (raise beta)
        lo[active[up]] = b[up]
        hi[active[~up]] = b[~up]
        lo_a, hi_a = lo[active], hi[active]
        beta[active] = np.where(
            up, np.where(np.isinf(hi_a), b * 2.0, (b + hi_a) / 2.0),
            np.where(np.isinf(lo_a), b / 2.0, (b + lo_a) / 2.0))
    return P


def joint_p(X, perplexity):
    P = conditional_p(X, perplexity)
    P = P + P.T
    P /= P.sum()
    np.maximum(P, 1e-12, out=P)
    np.fill_diagonal(P, 0.0)
    return P


def pca_init(X, rng):
    """First two principal components, sign-fixed, scaled to std 1e-4 (deterministic)."""
    n = X.shape[0]
    Xc = X - X.mean(axis=0)
    _, _, Vt = np.linalg.svd(Xc, full_matrices=False)
    Y = np.zeros((n, 2))
    k = min(2, Vt.shape[0])
    Y[:, :k] = Xc @ Vt[:k].T
    for c in range(k):  # sign convention: the largest |coordinate| is positive
        if Y[np.argmax(np.abs(Y[:, c])), c] < 0:
            Y[:, c] = -Y[:, c]
    sd = Y.std(axis=0)
    if sd[0] <= 1e-12 * max(1.0, float(np.abs(X).max())):
        return rng.standard_normal((n, 2)) * 1e-4  # all rows (nearly) identical
    for c in range(2):  # degenerate second axis (1-D input): seeded jitter
        if sd[c] <= 1e-12 * sd[0]:
            Y[:, c] = rng.standard_normal(n) * sd[0]
    return Y / Y[:, 0].std() * 1e-4


def tsne(X, perplexity, iterations, learning_rate, rng):
    """Exact t-SNE; returns (Y[N, 2], final KL(P || Q))."""
    n = X.shape[0]
    P = joint_p(X, perplexity)
    Y = pca_init(X, rng)
    update = np.zeros_like(Y)
    gains = np.ones_like(Y)
    num = np.empty((n, n))
    W = np.empty((n, n))
    # A @ B.T = 1 + |y_i|^2 + |y_j|^2 - 2 y_i.y_j = 1 + |y_i - y_j|^2 in one product
    A = np.ones((n, 5))
    B = np.ones((n, 5))
    Y1 = np.ones((n, 3))  # [Y, 1]: W @ Y1 gives W @ Y and the row sums of W together
    Pe = P * EXAGGERATION
    for it in range(iterations):
        if it == EXAGGERATION_ITERS:
            Pe = P
        momentum = 0.5 if it < MOMENTUM_SWITCH_ITER else 0.8
        # num[i, j] = 1 / (1 + |y_i - y_j|^2), zero diagonal; Q = num / sum(num)
        s = np.einsum("ij,ij->i", Y, Y)
        A[:, :2] = -2.0 * Y
        A[:, 2] = s
        B[:, :2] = Y
        B[:, 3] = s
        np.dot(A, B.T, out=num)
        np.reciprocal(num, out=num)
        np.fill_diagonal(num, 0.0)
        z = num.sum()
        # W = (P - Q) * num;  dC/dy_i = sum_j W_ij (y_i - y_j)  (the factor 4 is left
        # out, as in the reference implementation: it is part of the learning rate)
        np.multiply(num, -1.0 / z, out=W)
        W += Pe
        W *= num
        Y1[:, :2] = Y
        g = W @ Y1
        grad = g[:, 2:3] * Y - g[:, :2]
        same = (grad > 0) == (update > 0)
        gains = np.where(same, gains * 0.8, gains + 0.2)
        np.maximum(gains, 0.01, out=gains)
        update = momentum * update - learning_rate * gains * grad
        Y = Y + update
        Y -= Y.mean(axis=0)
    # KL(P || Q) at the end, without exaggeration
    D = squared_distances(Y)
    Q = 1.0 / (1.0 + D)
    np.fill_diagonal(Q, 0.0)
    Q /= Q.sum()
    off = ~np.eye(n, dtype=bool)
    kl = float(np.sum(P[off] * np.log(P[off] / np.maximum(Q[off], 1e-12))))
    return Y, kl


def knn_purity(Y, y, k):
    """Per point: fraction of its k nearest neighbours (self excluded) with its label."""
    n = Y.shape[0]
    k = min(k, n - 1)
    D = squared_distances(Y)
    np.fill_diagonal(D, np.inf)
    nn = np.argsort(D, axis=1, kind="stable")[:, :k]
    return (y[nn] == y[:, None]).mean(axis=1)


# ----------------------------------------------------------------------------- SVG

def fmt(v):
    return f"{v:.2f}".rstrip("0").rstrip(".")


def write_svg(path, Y, y, labels, counts, title, footnote, rng):
    plot = 560.0  # square plot area: t-SNE distances are isotropic
    margin, top = 20.0, 56.0
    pad = 12.0
    char_w = 7.2
    legend_texts = [f"{lab} (n={c})" for lab, c in zip(labels, counts)]
    legend_w = 40.0 + char_w * max(len(t) for t in legend_texts)
    width = margin + plot + 24.0 + legend_w + margin
    width = max(width, margin * 2 + char_w * 1.25 * len(title),
                margin * 2 + 6.0 * max(len(line) for line in footnote))
    height = top + plot + 18.0 + 15.0 * len(footnote)
    lo = Y.min(axis=0)
    span = float((Y.max(axis=0) - lo).max()) or 1.0
    scale = (plot - 2 * pad) / span
    extent = (Y.max(axis=0) - lo) * scale
    off_x = margin + pad + (plot - 2 * pad - extent[0]) / 2
    off_y = top + pad + (plot - 2 * pad - extent[1]) / 2
    px = off_x + (Y[:, 0] - lo[0]) * scale
    py = off_y + (extent[1] - (Y[:, 1] - lo[1]) * scale)  # SVG y grows downwards

    out = []
    w = out.append
    w('<?xml version="1.0" encoding="UTF-8"?>\n')
    w(f'<svg xmlns="http://www.w3.org/2000/svg" width="{fmt(width)}" '
      f'height="{fmt(height)}" viewBox="0 0 {fmt(width)} {fmt(height)}" '
      'font-family="Helvetica, Arial, sans-serif">\n')
    w(f"<title>{escape(title)}</title>\n")
    colour = [COLOURS[i % len(COLOURS)] for i in range(len(labels))]
    w(f'<rect width="{fmt(width)}" height="{fmt(height)}" fill="#ffffff"/>\n')
    w(f'<text x="{fmt(width / 2)}" y="32" font-size="18" text-anchor="middle">'
      f"{escape(title)}</text>\n")
    w(f'<rect x="{fmt(margin)}" y="{fmt(top)}" width="{fmt(plot)}" height="{fmt(plot)}" '
      'fill="none" stroke="#444444" stroke-width="0.75"/>\n')
    # Points in a seeded shuffled order so no label is systematically drawn on top.
    w('<g id="points">\n')
    for j in rng.permutation(len(y)):
        w(f'<circle class="pt c{y[j]}" cx="{px[j]:.2f}" cy="{py[j]:.2f}" r="2.6" '
          f'fill="{colour[y[j]]}" fill-opacity="0.6" stroke="none"/>\n')
    w("</g>\n")
    lx, ly = margin + plot + 24.0, top + 14.0
    w('<g id="legend" font-size="13">\n')
    for i, text in enumerate(legend_texts):
        cy = ly + 22.0 * i
        w(f'<circle class="lg c{i}" cx="{fmt(lx + 6)}" cy="{fmt(cy)}" r="5" '
          f'fill="{colour[i]}" fill-opacity="0.8" stroke="none"/>\n')
        w(f'<text x="{fmt(lx + 18)}" y="{fmt(cy + 4.5)}">{escape(text)}</text>\n')
    w("</g>\n")
    for i, line in enumerate(footnote):
        w(f'<text x="{fmt(margin)}" y="{fmt(top + plot + 20 + 15 * i)}" font-size="11" '
          f'fill="#555555">{escape(line)}</text>\n')
    w("</svg>\n")
    text = "".join(out)
    tmp = path + ".tmp"
    try:
        with open(tmp, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
        os.replace(tmp, path)
    except OSError as e:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise InputError(f"{path}: cannot write: {e.strerror or e}")


# ----------------------------------------------------------------------------- main

class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2, no usage dump
        sys.stderr.write(f"{PROG}: {message} (see --help)\n")
        sys.exit(2)


def positive_int(s):
    try:
        v = int(s)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: '{s}'")
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1: '{s}'")
    return v


def positive_float(s):
    try:
        v = float(s)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: '{s}'")
    if not (math.isfinite(v) and v > 0):
        raise argparse.ArgumentTypeError(f"must be a positive number: '{s}'")
    return v


def learning_rate_arg(s):
    return "auto" if s == "auto" else positive_float(s)


def main(argv):
    ap = Parser(prog=PROG, description="t-SNE of policy actions as an SVG scatter plot "
                "(cf. Byun & Perrault, ICLR 2022, Fig. 4).")
    ap.add_argument("input", help="CSV: header label,a0,a1,...; one row per action")
    ap.add_argument("output", help="SVG file to write")
    ap.add_argument("--perplexity", type=positive_float, default=30.0)
    ap.add_argument("--seed", type=int, default=0,
                    help="for subsampling and draw order (the PCA start is deterministic)")
    ap.add_argument("--iterations", type=positive_int, default=1000)
    ap.add_argument("--max-points", type=positive_int, default=1500)
    ap.add_argument("--learning-rate", type=learning_rate_arg, default=200.0,
                    help="gradient-descent step, or 'auto' for max(N/12, 50) (default 200)")
    ap.add_argument("--title", default=None)
    args = ap.parse_args(argv)

    out_dir = os.path.dirname(os.path.abspath(args.output))
    if not os.path.isdir(out_dir):
        raise InputError(f"{args.output}: cannot write: no directory {out_dir}")
    labels, y, X = read_csv(args.input)
    if args.seed < 0:
        raise InputError(f"--seed must be >= 0, got {args.seed}")
    n_rows = len(y)
    if n_rows > args.max_points and args.max_points < len(labels):
        raise InputError(f"--max-points {args.max_points} is fewer than the "
                         f"{len(labels)} labels")
    rng = np.random.default_rng(args.seed)
    keep = subsample(y, len(labels), args.max_points, rng)
    y, X = y[keep], X[keep]
    n = len(y)
    if n < 4:
        raise InputError(f"{args.input}: need at least 4 rows, got {n}")
    perplexity = args.perplexity
    if 3.0 * perplexity > n - 1:  # the Gaussian would have to reach past every point
        perplexity = (n - 1) / 3.0
        sys.stderr.write(f"{PROG}: note: perplexity {args.perplexity:g} is too large for "
                         f"{n} points; using {perplexity:.3g}\n")
    lr = max(n / 12.0, 50.0) if args.learning_rate == "auto" else args.learning_rate

    Y, kl = tsne(X, perplexity, args.iterations, lr, rng)
    purity = knn_purity(Y, y, NEIGHBOURS)
    counts = np.bincount(y, minlength=len(labels))

    title = args.title if args.title is not None else \
        f"t-SNE of actions: {os.path.basename(args.input)}"
    footnote = [f"{n} actions ({X.shape[1]}-D)"
                + (f", subsampled from {n_rows} rows" if n < n_rows else "")
                + f"; 10-NN label purity {float(purity.mean()):.3f}",
                f"exact t-SNE: perplexity {perplexity:g}, {args.iterations} iterations, "
                f"learning rate {lr:g}, seed {args.seed}, final KL {kl:.3f}"]
    write_svg(args.output, Y, y, labels, counts, title, footnote, rng)
    for i, lab in enumerate(labels):
        p = float(purity[y == i].mean()) if counts[i] else float("nan")
        print(f"{lab}\tcount={counts[i]}\tknn{NEIGHBOURS}_purity={p:.4f}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except InputError as e:
        sys.stderr.write(f"{PROG}: {e}\n")
        sys.exit(2)
    except KeyboardInterrupt:
        sys.stderr.write(f"{PROG}: interrupted\n")
        sys.exit(130)
    except MemoryError:
        sys.stderr.write(f"{PROG}: out of memory (try a smaller --max-points)\n")
        sys.exit(2)
    except Exception as e:  # a bug, still reported on one line
        sys.stderr.write(f"{PROG}: internal error: {type(e).__name__}: "
                         f"{str(e).splitlines()[0] if str(e) else ''}\n")
        sys.exit(1)
