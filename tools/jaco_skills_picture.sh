#!/usr/bin/env bash
# Draws docs/jaco_skills.png: one frame of each shipped arm skill, rendered headless by
# `segue render` (pick and catch by the model's close camera, toss and hit by its track
# camera, which shows the targets), side by side. Run from the repository root after a build.
set -euo pipefail
cd "$(dirname "$0")/.."
frames=$(mktemp -d)
trap 'rm -rf "$frames"' EXIT
render() {  # skill, camera, steps, episode seed
  build/segue render "assets/policies/jaco/jaco_$1.pt" --task "jaco_$1" --camera "$2" --steps "$3" --seed "$4" \
    --width 480 --height 360 --frames "$frames/$1" >/dev/null
}
render pick close 90 1
render catch close 90 0
render toss track 85 0
render hit track 60 0
"$([ -x /usr/bin/python3 ] && echo /usr/bin/python3 || echo python3)" tools/plot.py montage "$frames/pick/frame_00021.png" "$frames/catch/frame_00021.png" \
  "$frames/toss/frame_00020.png" "$frames/hit/frame_00014.png" \
  --titles "pick: the box lifted,catch: the thrown box held,toss: the ball thrown up,hit: the ball struck at the target" \
  --out docs/jaco_skills.png
