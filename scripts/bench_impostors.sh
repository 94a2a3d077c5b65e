#!/usr/bin/env bash
# Figures for docs/BENCHMARKS.md (Sillion et al. 1997 impostors): a procedural city, a 300-frame car path, the depth-mesh
# and grid-mesh impostors of the cells the path visits (`bake --technique`, the pipeline's single stage with one
# capture per cell: one store per mesh kind), and the walkthrough benchmark of full, culled, grid-mesh and depth-mesh
# with full-geometry reference frames, for the edge local model and (second run) the junction one. The impostor
# modes keep the bake's bound (ERROR_PX, default 10): where a cell's impostor is not valid they draw its far objects
# as geometry, and report how often.
# Usage: scripts/bench_impostors.sh FARFIELD OUT BLOCKS DETAIL [FRAMES] [ERROR_PX]
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/bench/impostors}
BLOCKS=${3:-400}
DETAIL=${4:-2}
FRAMES=${5:-300}
ERROR_PX=${6:-10}
mkdir -p "$OUT"
"$FARFIELD" gen city --blocks "$BLOCKS" --detail "$DETAIL" --seed 1 -o "$OUT/city.glb" | tee "$OUT/gen.txt"
"$FARFIELD" path street "$OUT/city.streets.json" --frames "$FRAMES" --seed 1 --car -o "$OUT/path.json" | tee "$OUT/path.txt"
for local in edge junction; do
  for technique in depth-mesh grid-mesh; do
    "$FARFIELD" bake "$OUT/city.glb" --technique "$technique" --error-px "$ERROR_PX" --local "$local" \
      --path "$OUT/path.json" -o "$OUT/imp-$local-$technique" | tee "$OUT/bake-$local-$technique.txt"
  done
  "$FARFIELD" bench "$OUT/city.glb" --path "$OUT/path.json" \
    --mode-option depth_mesh_dir="$OUT/imp-$local-depth-mesh" --mode-option grid_mesh_dir="$OUT/imp-$local-grid-mesh" \
    --modes full,culled,grid-mesh,depth-mesh --reference --size 512x512 -o "$OUT/bench-$local" | tee "$OUT/bench-$local.txt"
done
