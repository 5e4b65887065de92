#!/usr/bin/env bash
# The main job: installs dependencies, builds, trains walk-forward from its recipe
# (resuming if interrupted), evaluates it over 50 episodes and exports it.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install_deps.sh
bash tools/build.sh
RECIPE=experiments/primitives/walker_forward.yaml
RUN=runs/walker_forward
build/segue train "$RECIPE" --set run_dir="$RUN"
build/segue eval "$RUN/checkpoint.pt" --task walker_forward --episodes 50 --seed 0
build/segue export "$RUN/checkpoint.pt" "$RUN/walker_forward.pt"
echo "exported $RUN/walker_forward.pt (the shipped one is assets/policies/walker/walker_forward.pt)"
