#!/usr/bin/env bash
# The error bound as a contract, measured (docs/BENCHMARKS.md, "Error bound"): one procedural city, a car drive and a
# pedestrian walk through it, the extractor pipeline baked for the cells each path visits (layers, stations and
# their validity regions), then for bounds of 10, 5, 2 and 1 px the walkthrough benchmark of full, culled, smi and
# mmi against full-geometry reference frames, each impostor mode drawing geometry wherever no impostor is valid under
# the bound. Bounds of 5 px and more use a store baked at 10 px (the layering threshold), tighter ones a store baked
# at 2 px. tools/bound_table.py turns the bench.json files into the tables.
# Usage: scripts/bench_bound.sh FARFIELD OUT BLOCKS DETAIL SEED [FRAMES] [STRIDE] [STATION_SPACING]
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/bench/bound}
BLOCKS=${3:-400}
DETAIL=${4:-2}
SEED=${5:-1}
FRAMES=${6:-300}
STRIDE=${7:-3}
STATIONS=${8:-5}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$OUT"
"$FARFIELD" gen city --blocks "$BLOCKS" --detail "$DETAIL" --seed "$SEED" -o "$OUT/city.glb" > "$OUT/gen.txt"
"$FARFIELD" path street "$OUT/city.streets.json" --frames "$FRAMES" --fps 10 --seed "$SEED" --car -o "$OUT/drive.json" \
  > "$OUT/drive.txt"
"$FARFIELD" path street "$OUT/city.streets.json" --frames "$FRAMES" --seed "$SEED" -o "$OUT/walk.json" > "$OUT/walk.txt"
for path in drive walk; do
  for bake_px in 10 2; do
    /usr/bin/time -f "%e s, %M kB" -o "$OUT/bake-$path-$bake_px.time" \
      "$FARFIELD" bake "$OUT/city.glb" --pipeline pvs,near-far,single,mmi --pvs-spacing 5 --error-px "$bake_px" \
      --station-spacing "$STATIONS" --path "$OUT/$path.json" -o "$OUT/imp-$path-$bake_px" > "$OUT/bake-$path-$bake_px.txt"
  done
  for bound in 10 5 2 1; do
    bake_px=10
    if [ "$bound" -lt 5 ]; then bake_px=2; fi
    "$FARFIELD" bench "$OUT/city.glb" --path "$OUT/$path.json" --impostors "$OUT/imp-$path-$bake_px" \
      --modes full,culled,smi,mmi --mode-option error_px="$bound" --error-px "$bound" --reference \
      --size 640x360 --stride "$STRIDE" --samples 2 -o "$OUT/bench-$path-$bound" > "$OUT/bench-$path-$bound.txt" 2>&1
  done
done
python3 "$here/../tools/bound_table.py" "$OUT"
