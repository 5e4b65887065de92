#!/usr/bin/env bash
# Times Hurdle's walk->jump collection (S_a 300 states, T_b 30,000 steps) with 1 and 2
# threads, and shows that the files are the same (docs/distributed.md quotes its output).
# Each run stops once the transition-policy stage begins. Usage: tools/collection_speed.sh
set -euo pipefail
cd "$(dirname "$0")/.."
for threads in 1 2; do
  dir=$(mktemp -d)
  start=$(date +%s.%N)
  build/segue run experiments/hurdle.yaml --set run_dir="$dir/run" --set threads=$threads \
    --set collect.start_states=300 --set collect.demonstrations=30000 > "$dir/log" 2>&1 &
  pid=$!
  until grep -q "transition policy (AIRL" "$dir/log" 2>/dev/null || ! kill -0 $pid 2>/dev/null; do sleep 0.5; done
  end=$(date +%s.%N)
  kill -INT $pid 2>/dev/null || true
  wait $pid 2>/dev/null || true
  echo "threads $threads: $(echo "$end - $start" | bc) s"
  md5sum "$dir/run/walk-jump/start_states.pt" "$dir/run/walk-jump/demonstrations.pt" | cut -d' ' -f1
  rm -rf "$dir"
done
