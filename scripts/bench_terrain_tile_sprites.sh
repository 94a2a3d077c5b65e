#!/usr/bin/env bash
# Sprites per terrain tile (lod-sprite-tiles with the per-frame choice, lod-sprite-tiles-each-frame deciding on every
# frame, lod-sprite-tiles-always without a choice) against the
# whole-frame sprite (lod-sprite, lod-sprite-always) and the high LOD, on the shared DEM and a fractal no test or
# tuning used, at several tile sizes; then the table.
# Usage: scripts/bench_terrain_tile_sprites.sh [OUT] [FRAMES]   (FARFIELD=path/to/farfield to use another binary)
set -euo pipefail
OUT=${1:-out/terrain-tile-sprites}
FRAMES=${2:-600}
FF=${FARFIELD:-build/release/bin/farfield}
DEM=../shared/data/terrain/bigtujunga_srtm30m_utm11.tif
FRACTAL=fractal:4097:31:relief=3000:roughness=0.6
MODES=high,low,lod-sprite,lod-sprite-always,lod-sprite-tiles,lod-sprite-tiles-each-frame,lod-sprite-tiles-always
mkdir -p "$OUT"
common=(--frames "$FRAMES" --epsilon 1 --modes "$MODES" --no-sweeps --no-section5 --quality-stride 5)
for cells in 128 256 512; do
  "$FF" terrain bench "$DEM" "${common[@]}" --sprite-tile-cells "$cells" -o "$OUT/dem-$cells"
done
for cells in 256 512 1024; do
  "$FF" terrain bench "$FRACTAL" --block 256 --clearance 1000 "${common[@]}" --sprite-tile-cells "$cells" \
    -o "$OUT/fractal-$cells"
done
/usr/bin/python3 tools/terrain_tile_sprites_table.py "$OUT"/*/bench.json | tee "$OUT/table.md"
