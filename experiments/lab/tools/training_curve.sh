#!/usr/bin/env bash
# Training curve of a run from its metrics.csv: per bin of environment steps, the mean
# success count and success rate over the episodes that finished in it (weighted by
# episodes, not iterations), the mean return and the policy's entropy.
#   tools/training_curve.sh runs/walker_jump_gait [BIN_STEPS=500000] [FROM_STEP=0]
set -euo pipefail
run=${1:?usage: tools/training_curve.sh RUN_DIR [BIN_STEPS] [FROM_STEP]}
bin=${2:-500000}
from=${3:-0}
csv="$run/metrics.csv"
[[ -f "$csv" ]] || { echo "error: $csv: no such file" >&2; exit 1; }
awk -F, -v bin="$bin" -v from="$from" '
  NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
  $(col["global_step"]) <= from || $(col["episodes"]) == 0 { next }
  {
    b = int(($(col["global_step"]) - from - 1) / bin)
    if (b != cur && n > 0) flush()
    cur = b; e = $(col["episodes"])
    n += e; cnt += $(col["success_count"]) * e; rate += $(col["success_rate"]) * e
    ret += $(col["episode_return"]) * e; ent += $(col["entropy"]); it++
  }
  function flush() {
    printf "%7.2fM  episodes %6d  success_count %.3f  success_rate %.3f  return %8.1f  entropy %6.2f\n",
           (from + (cur + 1) * bin) / 1e6, n, cnt / n, rate / n, ret / n, ent / it
    n = cnt = rate = ret = ent = it = 0
  }
  BEGIN { cur = -1 }
  END { if (n > 0) flush() }' "$csv"
