#!/bin/bash
# Hurdle's walk->jump hand-over trained again under recipe overrides, one thread:
#   tools/switch_variants.sh NAME [--set key=value ...]
#     only walk->jump's switch Q-network, on the shipped transition policies (~6 min);
#     e.g. tools/switch_variants.sh attempts10k --set switch.attempts=10000
#   tools/switch_variants.sh NAME --transition BASE_RUN [--set key=value ...]
#     walk->jump's transition policy and then its q_ab, on BASE_RUN's S_a and T_b and with
#     BASE_RUN's jump->walk artefacts; then With TP and With TP + Q are evaluated (50
#     episodes x seeds 0-2, printed). ~8-20 min.
#     e.g. tools/switch_variants.sh disc_steps2 --transition runs/hurdle15 --set transition.discriminator.steps=2
#   tools/switch_variants.sh NAME --transition BASE_RUN --new-tb [--set key=value ...]
#     as above, but walk->jump's T_b is collected afresh, for settings that change it; e.g.
#     tools/switch_variants.sh tbhandover --transition runs/hurdle16L --new-tb \
#       --set transitions.0.expert.after_handover=true
# Prints margins.csv (held-out hand-overs per switch margin). Run dir runs/switch_NAME;
# rerunning resumes it. In the first form T_b is kept small (2000 rows), since no pi_ab is
# trained from it, and every variant after the first (`plain`, run first) reuses
# runs/switch_plain's S_a and T_b, so variants differ only in their settings (two
# collections' held-out starts alone differ by a few points).
set -euo pipefail
cd "$(dirname "$0")/.."
name=$1; shift
base=
if [ "${1:-}" = --transition ]; then base=$2; shift 2; fi
new_tb=
if [ "${1:-}" = --new-tb ]; then new_tb=1; shift; fi
run=runs/switch_$name
mkdir -p "$run/walk-jump" "$run/jump-walk"
if [ -n "$base" ]; then
  cp -n "$base"/walk-jump/start_states.pt "$run/walk-jump/"
  [ -n "$new_tb" ] || cp -n "$base"/walk-jump/demonstrations.pt "$run/walk-jump/"
  cp -n "$base"/jump-walk/{start_states.pt,demonstrations.pt,policy.pt,q.pt} "$run/jump-walk/"
  overrides=()
else
  for t in walk-jump jump-walk; do
    cp -n assets/policies/walker/hurdle/$t/policy.pt "$run/$t/policy.pt"
    if [ "$name" != plain ]; then
      for f in start_states.pt demonstrations.pt; do cp -n runs/switch_plain/$t/$f "$run/$t/$f"; done
    fi
  done
  overrides=(--set collect.demonstrations=2000)
fi
build/segue run experiments/hurdle.yaml --threads 1 --set run_dir=$run "${overrides[@]}" "$@" > "$run/log.txt" 2>&1 &
pid=$!
# walk->jump's q_ab is its first switch stage; stop the pipeline once it is written.
while [ ! -f "$run/walk-jump/q.pt" ] && kill -0 $pid 2>/dev/null; do sleep 2; done
kill -INT $pid 2>/dev/null || true
wait $pid || true
[ -f "$run/walk-jump/q.pt" ] || { echo "error: no q.pt; see $run/log.txt" >&2; exit 1; }
cat "$run/walk-jump/margins.csv"
[ -n "$base" ] || exit 0
for m in tp tp+q; do
  for s in 0 1 2; do
    echo -n "$m seed $s: "
    build/segue eval --task hurdle --method $m --episodes 50 --seed $s --threads 1 "$@" \
      --set methods.transitions=$run | grep "success count"
  done
done
