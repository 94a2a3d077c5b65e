#!/usr/bin/env bash
# Figures for docs/BENCHMARKS.md (Sillion et al. 1997 impostors): a procedural city, a 300-frame car path, the depth-mesh
# and grid-mesh impostors of the cells the path visits, and the walkthrough benchmark of full, culled, grid-mesh and
# depth-mesh with full-geometry reference frames, for the edge local model and (second run) the junction one.
# Usage: scripts/bench_impostors.sh FARFIELD OUT BLOCKS DETAIL [FRAMES]
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/bench/impostors}
BLOCKS=${3:-400}
DETAIL=${4:-2}
FRAMES=${5:-300}
mkdir -p "$OUT"
"$FARFIELD" gen city --blocks "$BLOCKS" --detail "$DETAIL" --seed 1 -o "$OUT/city.glb" | tee "$OUT/gen.txt"
"$FARFIELD" path street "$OUT/city.streets.json" --frames "$FRAMES" --seed 1 --car -o "$OUT/path.json" | tee "$OUT/path.txt"
for local in edge junction; do
  "$FARFIELD" bake "$OUT/city.glb" --technique both --local "$local" --path "$OUT/path.json" -o "$OUT/imp-$local" \
    | tee "$OUT/bake-$local.txt"
  "$FARFIELD" bench "$OUT/city.glb" --path "$OUT/path.json" --impostors "$OUT/imp-$local" \
    --modes full,culled,grid-mesh,depth-mesh --reference --size 512x512 -o "$OUT/bench-$local" | tee "$OUT/bench-$local.txt"
done
