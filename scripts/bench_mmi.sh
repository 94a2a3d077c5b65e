#!/usr/bin/env bash
# Table 1 of Decoret et al. 1999 for our city (docs/BENCHMARKS.md): a procedural city, camera paths through it, the
# extractor pipeline (PVS, near/far split, multi-mesh impostors and the single mesh) baked for the cells the paths
# visit, and the walkthrough benchmark of full, local, visible, smi, mmi and mmi-dynamic against full-geometry
# reference frames:
#   drive-edge      a drive (1 m per frame), near geometry = the blocks touching the street (the paper's local model)
#   drive-junction  the same drive, near geometry = also the blocks around both end junctions (--local junction)
#   walk-edge       a pedestrian walk (5 cm per frame): slow enough for dynamic updates, which fast motion turns off
# Usage: scripts/bench_mmi.sh FARFIELD OUT BLOCKS DETAIL [FRAMES] [LAYER_MESH] [BUDGET_MS]
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/bench/mmi}
BLOCKS=${3:-400}
DETAIL=${4:-2}
FRAMES=${5:-300}
LAYER_MESH=${6:-grid}
BUDGET=${7:-50}
mkdir -p "$OUT"
"$FARFIELD" gen city --blocks "$BLOCKS" --detail "$DETAIL" --seed 1 -o "$OUT/city.glb" | tee "$OUT/gen.txt"
"$FARFIELD" path street "$OUT/city.streets.json" --frames "$FRAMES" --fps 10 --seed 1 --car -o "$OUT/drive.json" \
  | tee "$OUT/drive.txt"
"$FARFIELD" path street "$OUT/city.streets.json" --frames "$FRAMES" --seed 1 -o "$OUT/walk.json" | tee "$OUT/walk.txt"
run() {  # name path local
  "$FARFIELD" bake "$OUT/city.glb" --pipeline pvs,near-far,single,mmi --local "$3" --layer-mesh "$LAYER_MESH" \
    --pvs-spacing 5 --path "$OUT/$2.json" --list -o "$OUT/imp-$1" | tee "$OUT/bake-$1.txt"
  "$FARFIELD" bench "$OUT/city.glb" --path "$OUT/$2.json" --impostors "$OUT/imp-$1" \
    --modes full,local,visible,smi,mmi,mmi-dynamic --mode-option frame_budget_ms="$BUDGET" \
    --reference --size 512x512 -o "$OUT/bench-$1" | tee "$OUT/bench-$1.txt"
}
run drive-edge drive edge
run drive-junction drive junction
run walk-edge walk edge
