#!/usr/bin/env bash
# Table 1 of Decoret et al. 1999 for our city (docs/BENCHMARKS.md): a procedural city, a camera path through it, the
# extractor pipeline (PVS, near/far split, multi-mesh impostors and the single mesh) baked for the cells the path
# visits, and the walkthrough benchmark of full, local, visible, smi, mmi and mmi-dynamic against full-geometry
# reference frames. A second, slow path (a pedestrian standing and walking) shows the dynamic updates, which fast
# motion turns off.
# Usage: scripts/bench_mmi.sh FARFIELD OUT BLOCKS DETAIL [FRAMES] [LAYER_MESH] [BUDGET_MS]
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/bench/mmi}
BLOCKS=${3:-400}
DETAIL=${4:-2}
FRAMES=${5:-300}
LAYER_MESH=${6:-grid}
BUDGET=${7:-100}
mkdir -p "$OUT"
"$FARFIELD" gen city --blocks "$BLOCKS" --detail "$DETAIL" --seed 1 -o "$OUT/city.glb" | tee "$OUT/gen.txt"
# A drive at 10 m/s sampled at 10 frames per second: 1 m per frame, a few cells.
"$FARFIELD" path street "$OUT/city.streets.json" --frames "$FRAMES" --fps 10 --seed 1 --car -o "$OUT/path.json" \
  | tee "$OUT/path.txt"
# A walk at 1.4 m/s, 30 frames per second: slow enough for dynamic updates to live several frames.
"$FARFIELD" path street "$OUT/city.streets.json" --frames "$FRAMES" --seed 1 -o "$OUT/walk.json" | tee "$OUT/walk.txt"
"$FARFIELD" bake "$OUT/city.glb" --pipeline pvs,near-far,mmi --layer-mesh "$LAYER_MESH" --pvs-spacing 5 \
  --path "$OUT/path.json" --list -o "$OUT/imp" | tee "$OUT/bake.txt"
"$FARFIELD" bake "$OUT/city.glb" --pipeline pvs,near-far,mmi --layer-mesh "$LAYER_MESH" --pvs-spacing 5 \
  --path "$OUT/walk.json" --list -o "$OUT/imp-walk" | tee "$OUT/bake-walk.txt"
"$FARFIELD" bench "$OUT/city.glb" --path "$OUT/path.json" --impostors "$OUT/imp" \
  --modes full,local,visible,smi,mmi,mmi-dynamic --mode-option frame_budget_ms="$BUDGET" \
  --reference --size 512x512 -o "$OUT/bench-drive" | tee "$OUT/bench-drive.txt"
"$FARFIELD" bench "$OUT/city.glb" --path "$OUT/walk.json" --impostors "$OUT/imp-walk" \
  --modes full,local,visible,smi,mmi,mmi-dynamic --mode-option frame_budget_ms="$BUDGET" \
  --reference --size 512x512 -o "$OUT/bench-walk" | tee "$OUT/bench-walk.txt"
