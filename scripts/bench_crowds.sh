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
# run_walk SEED NAME ARGS: one bench on walk SEED; run NAME ARGS: on walk 7, the issue's.
run_walk() {
  seed=$1
  name=$2
  shift 2
  mkdir -p "$out"
  # shellcheck disable=SC2086 # $models is one option and its value, or nothing
  xvfb-run -a -s '-screen 0 1280x1024x24 -noreset' "$ff" crowd bench -o "$out/$name" --size 512x512 \
    --path-seed "$seed" $models "$@" > "$out/$name.log" 2>&1
  grep '^|\|^- ' "$out/$name.log"
}
run() {
  run_walk 7 "$@"
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
# A level's texture: skinned levels chosen by the larger of their distance to the mesh and how far they move a texel
# (the default) against the distance alone, on walk 7 and on walk 9 with crowd seed 3 (no tuning used it).
lod="--agents 10000 --frames 6 --samples 1 --gpu-crowd --no-shadows --error-px 0.5"
for px in 0.1 0.15 0.25; do
  # shellcheck disable=SC2086 # $lod is a list of options
  run tex-s7-$px $lod --skinned-lod $px
done
for px in 0.1 0.2 0.5; do
  # shellcheck disable=SC2086
  run_walk 9 tex-s9-$px $lod --crowd-seed 3 --skinned-lod $px
done
for px in 0.05 0.1 0.25; do
  # shellcheck disable=SC2086
  run dist-s7-$px $lod --skinned-lod $px --lod-distance-only
  # shellcheck disable=SC2086
  run_walk 9 dist-s9-$px $lod --crowd-seed 3 --skinned-lod $px --lod-distance-only
done
