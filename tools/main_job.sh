#!/usr/bin/env bash
# The main job: installs dependencies, builds, and runs the paper's method on Patrol from
# the shipped skills (walk forward, walk backward, balance): for each of its four
# transitions, collect S_a and T_b, train the transition policy (AIRL), the switch
# Q-network (double DQN) and Lee et al.'s baseline, then evaluate all five methods.
# Progress is shown stage by stage; rerunning resumes an interrupted run. The table is
# written to runs/patrol/patrol.md (the shipped one is experiments/results/patrol.md).
# Hurdle takes Patrol's place here once the jump skill reaches its target (README).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install_deps.sh
bash tools/build.sh
build/segue run experiments/patrol.yaml
cat runs/patrol/patrol.md
