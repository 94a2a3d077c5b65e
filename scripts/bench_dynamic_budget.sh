#!/usr/bin/env bash
# The frame budget of the dynamic impostor modes (docs/BENCHMARKS.md, "Billboards, dynamic impostors, warping"): the
# default city with trees along a drive and a forest on rolling ground along a flyover, each with a cost profile of
# this machine calibrated over the path's district (frame model, safety factor, layered draw and capture terms), then
# the modes that regenerate images inside t_max (dynamic-shade, dynamic-schaufler, layered) against culled, every
# frame rendered 3 times and the fastest kept, against full-geometry reference frames.
# OCCLUSION=off runs the dynamic modes without the image cache's occlusion culling (--mode-option occlusion=off; the
# outputs get the suffix -occlusion-off), to compare with the default (on). INVEST=0 runs them with
# --mode-option lost_frame_investment=0 (suffix -invest-0): a frame over t_max whatever it does regenerates nothing.
# PAY_BACK=off (suffix -pay-back-off): every invalid image that fits t_max is regenerated, paying or not.
# GEOMETRY=cpu (suffix -geometry-cpu): the modes' geometry culled on the CPU (--mode-option geometry=cpu; with the
# image cache's occlusion culling, read back), against the default, the GPU-driven frame's culler.
# MODES=all (suffix -all) adds billboard and warp, for the table of every mode against full and culled.
# Usage: scripts/bench_dynamic_budget.sh FARFIELD OUT [TMAX_MS] [FRAMES] [STRIDE]
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/bench/dynamic-budget}
TMAX=${3:-200}
FRAMES=${4:-40}
STRIDE=${5:-3}
OCCLUSION=${OCCLUSION:-on}
SUFFIX=""
[ "$OCCLUSION" = on ] || SUFFIX="-occlusion-$OCCLUSION"
INVEST=${INVEST:-1}
[ "$INVEST" = 1 ] || SUFFIX="$SUFFIX-invest-$INVEST"
PAY_BACK=${PAY_BACK:-on}
[ "$PAY_BACK" = on ] || SUFFIX="$SUFFIX-pay-back-$PAY_BACK"
GEOMETRY=${GEOMETRY:-gpu}
[ "$GEOMETRY" = gpu ] || SUFFIX="$SUFFIX-geometry-$GEOMETRY"
MODES_LIST=culled,dynamic-shade,dynamic-schaufler,layered
if [ "${MODES:-}" = all ]; then
  MODES_LIST=culled,billboard,dynamic-shade,dynamic-schaufler,layered,warp
  SUFFIX="$SUFFIX-all"
fi
mkdir -p "$OUT"
[ -f "$OUT/city_trees.glb" ] || "$FARFIELD" gen city --trees -o "$OUT/city_trees.glb" > "$OUT/gen_city.txt"
[ -f "$OUT/drive2.json" ] || "$FARFIELD" path street "$OUT/city_trees.streets.json" --car --frames 400 --seed 2 \
  -o "$OUT/drive2.json" > /dev/null
[ -f "$OUT/forest5.glb" ] || "$FARFIELD" gen forest --seed 5 --trees 600 -o "$OUT/forest5.glb" > "$OUT/gen_forest.txt"
[ -f "$OUT/fly5.json" ] || "$FARFIELD" path flyover "$OUT/forest5.glb" --frames 300 --altitude 25 -o "$OUT/fly5.json" \
  > /dev/null
for run in "city city_trees.glb drive2.json" "forest forest5.glb fly5.json"; do
  set -- $run
  name=$1 scene=$OUT/$2 path=$OUT/$3
  [ -f "$OUT/profile-$name.json" ] || "$FARFIELD" calibrate "$scene" -o "$OUT/profile-$name.json" --size 640x360 \
    --fov 60 --around "$path" --margin 20 --views "${CAL_VIEWS:-100}" --fit-views 50 --layered-samples 30 \
    --layered-error-px 2 > "$OUT/calibrate-$name.txt" 2>&1
  run_dir=$OUT/bench-$name-t$TMAX$SUFFIX
  [ -f "$run_dir/bench.json" ] && continue
  "$FARFIELD" bench "$scene" --path "$path" --modes "$MODES_LIST" --reference \
    --repeats 3 --tmax "$TMAX" --frames "$FRAMES" --stride "$STRIDE" --mode-option error_px=2 \
    --mode-option t_max_ms="$TMAX" --mode-option profile="$OUT/profile-$name.json" --mode-option occlusion="$OCCLUSION" \
    --mode-option geometry="$GEOMETRY" \
    --mode-option lost_frame_investment="$INVEST" --mode-option pay_back="$PAY_BACK" \
    -o "$run_dir" > "$run_dir.txt" 2>&1
done
