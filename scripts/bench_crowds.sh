#!/bin/sh
# The crowd figures of docs/BENCHMARKS.md ("Crowds"): farfield crowd bench on the default city, 512x512, pedestrian
# and elevated paths (path seed 7), every run writing OUT/<run>/{crowd.json,crowd.md,frames/}.
# Usage: scripts/bench_crowds.sh [OUT] (default out/crowd); FARFIELD=path/to/farfield to pick the binary, MODELS
# (default the shared CesiumMan and Fox of ../shared/data/models, which every figure of that section used; "builtin"
# for the built-in figures).
set -eu
out=${1:-out/crowd}
ff=${FARFIELD:-build/release/bin/farfield}
here=$(cd "$(dirname "$0")/.." && pwd)
MODELS=${MODELS:-$here/../shared/data/models/CesiumMan.glb,$here/../shared/data/models/Fox.glb}
models=""
[ "$MODELS" = builtin ] || models="--models $MODELS"
run() {
  name=$1
  shift
  mkdir -p "$out"
  # shellcheck disable=SC2086 # $models is one option and its value, or nothing
  xvfb-run -a -s '-screen 0 1280x1024x24 -noreset' "$ff" crowd bench -o "$out/$name" --size 512x512 --path-seed 7 \
    $models "$@" > "$out/$name.log" 2>&1
  grep '^|\|^- ' "$out/$name.log"
}
# The lecture's fixed atlas (32 x 8 views x 16 frames, 3 cm texels), agents' shadows on (1024 map, 60 m).
run main --agents 1000,10000 --frames 6
# The same without shadows: what the shadow pass costs.
run noshadow --agents 10000 --frames 4 --samples 1 --no-shadows
# Views, frames and texel chosen from the error bound (2 px) for impostors from 20 m on, then from 40 m on.
run bound2 --agents 10000 --frames 4 --samples 1 --atlas-from-bound --error-px 2 --bound-switch 20
run bound40 --agents 10000 --frames 4 --samples 1 --atlas-from-bound --error-px 2 --bound-switch 40
run a100k --agents 100000 --frames 3 --samples 1
# Popping at 30 fps: the nearest view against the four blended views.
run pop --agents 10000 --frames 12 --step 1 --samples 0
run popblend --agents 10000 --frames 12 --step 1 --samples 0 --blend-views
