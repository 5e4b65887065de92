#!/usr/bin/env bash
# Widening curriculum for the jump: start from the fixed standing jump (curb always
# 1.0 m ahead, runs/walker_jump_fixed_more) and widen the curb's range step by step
# towards the task's (7 + U(1.5) m). Each round trains `STEP` more PPO steps at the
# current range; the range widens only once the round's training episodes succeed at
# least `PASS` of the time, so the policy must learn to read the curb's distance a
# little at a time instead of all at once (walker_jump_near jumped straight to
# 0.8-2.2 m and stayed at 44%).
# Usage: tools/jump_widen.sh [ROOT=runs/jump_widen] [threads]
# Measured (runs/jump_widen/progress.txt, one core): 1.1 +- 0.2 m 63% then 71% of
# training episodes; 1.25 +- 0.4 m 43% and 43%, stopped there (stalled like
# walker_jump_near). The policy's take-off does not follow the curb's distance even
# within +-0.4 m of a standing start.
set -euo pipefail
root=${1:-runs/jump_widen}
threads=${2:-0}
STEP=${STEP:-1000000}
PASS=${PASS:-0.70}
MAX_ROUNDS=${MAX_ROUNDS:-40}
# (curb_x curb_noise): the curb's start is curb_x + U(curb_noise) metres from the start.
ranges=("1.1 0.2" "1.25 0.4" "1.5 0.6" "2.0 0.9" "2.75 1.2" "3.75 1.5" "5.0 1.5" "6.0 1.5" "7.0 1.5")
prev=runs/walker_jump_fixed_more/checkpoint.pt
steps=34000000
mkdir -p "$root"
stage=0
for ((round = 1; round <= MAX_ROUNDS && stage < ${#ranges[@]}; ++round)); do
  read -r cx cn <<<"${ranges[$stage]}"
  dir=$(printf '%s/r%02d' "$root" "$round")
  steps=$((steps + STEP))
  build/segue train experiments/lab/primitives/walker_jump_fixed_more.yaml --threads "$threads" \
    --set run_dir="$dir" --set init_from="$prev" --set ppo.total_steps=$steps \
    --set env.curb_x="$cx" --set env.curb_noise="$cn" --set ppo.anneal_lr=false --set ppo.lr=1.5e-4 --set eval.episodes=20 >"$dir.log" 2>&1 || true
  # Success over the round's second half of training episodes (column 6: success_rate).
  rate=$(awk -F, 'NR>1 && $3>0 {n++; e[n]=$3; s[n]=$6*$3} END {h=int(n/2); for (i=h+1;i<=n;i++) {E+=e[i]; S+=s[i]} printf "%.3f", S/E}' "$dir/metrics.csv")
  echo "round $round range $cx+-$cn steps $steps success $rate" | tee -a "$root/progress.txt"
  prev="$dir/checkpoint.pt"
  if awk -v r="$rate" -v p="$PASS" 'BEGIN {exit !(r >= p)}'; then stage=$((stage + 1)); fi
done
