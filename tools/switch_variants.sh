#!/bin/bash
# Hurdle's walk->jump switch Q-network trained again on the shipped transition policies,
# under recipe overrides, to compare switch-training settings on the same pi_ab's: prints
# the held-out hand-over success of each margin (margins.csv). One thread, ~6 min.
#   tools/switch_variants.sh NAME [--set key=value ...]
#   e.g. tools/switch_variants.sh attempts10k --set switch.attempts=10000
# Run dir runs/switch_NAME (S_a, T_b, q.pt); rerunning resumes it. pi_ab's are copied from
# assets/policies/walker/hurdle/, so only collection and walk->jump's q_ab run; T_b is
# kept small (2000 rows), since no pi_ab is trained from it. Every variant after the first
# (`plain`, run first) reuses runs/switch_plain's S_a and T_b, so variants differ only in
# their settings (two collections' held-out starts alone differ by a few points).
set -euo pipefail
cd "$(dirname "$0")/.."
name=$1; shift
run=runs/switch_$name
for t in walk-jump jump-walk; do
  mkdir -p "$run/$t"
  cp -n assets/policies/walker/hurdle/$t/policy.pt "$run/$t/policy.pt"
  if [ "$name" != plain ]; then
    for f in start_states.pt demonstrations.pt; do cp -n runs/switch_plain/$t/$f "$run/$t/$f"; done
  fi
done
build/segue run experiments/hurdle.yaml --threads 1 --set run_dir=$run \
  --set collect.demonstrations=2000 "$@" > "$run/log.txt" 2>&1 &
pid=$!
# walk->jump's q_ab is the first switch stage; stop the pipeline once it is written.
while [ ! -f "$run/walk-jump/q.pt" ] && kill -0 $pid 2>/dev/null; do sleep 2; done
kill -INT $pid 2>/dev/null || true
wait $pid || true
[ -f "$run/walk-jump/q.pt" ] || { echo "error: no q.pt; see $run/log.txt" >&2; exit 1; }
cat "$run/walk-jump/margins.csv"
