#!/bin/sh
# Issue 18's tiled-terrain figures (docs/BENCHMARKS.md, "Issue 18: tiles"): terrains paged under a memory budget with
# the LOD built per tile, and sprites per tile against the whole-frame sprite. Usage: scripts/bench_terrain_tiles.sh
# [OUT] (default out/terrain18b); FARFIELD=path/to/farfield overrides the binary. The 16,385^2 cache (about 4.6 GB)
# goes to ${TILE_CACHE_DIR:-/tmp}.
set -eu
FF=${FARFIELD:-build/release/bin/farfield}
OUT=${1:-out/terrain18b}
DEM=../shared/data/terrain/bigtujunga_srtm30m_utm11.tif
mkdir -p "$OUT"
# The shared DEM: a budget below the terrain (16 MiB of 34) and one above it; every 10th frame checked against the
# whole grid's LOD.
"$FF" terrain tiles "$DEM" --block 64 --tile-blocks 4 --budget-mb 16 --frames 600 --check-stride 10 -o "$OUT/dem_tiles"
"$FF" terrain tiles "$DEM" --block 64 --tile-blocks 4 --budget-mb 40 --frames 600 --check-stride 10 -o "$OUT/dem_tiles_40"
# Sprites per tile against the whole-frame sprite: tile sizes at 1 px, thresholds at 128-cell tiles.
for c in 64 128 256; do
  "$FF" terrain tiles "$DEM" --block 64 --tile-blocks 4 --budget-mb 40 --frames 600 --sprite-tiles $c --epsilon 1 \
    -o "$OUT/dem_sprites_$c"
done
for e in 0.5 2; do
  "$FF" terrain tiles "$DEM" --block 64 --tile-blocks 4 --budget-mb 40 --frames 600 --sprite-tiles 128 --epsilon $e \
    -o "$OUT/dem_sprites_e$e"
done
# Fractals of 8,193^2 and 16,385^2 points paged under 256 and 512 MiB.
"$FF" terrain tiles fractal:8193:23:relief=3000:roughness=0.6 --block 128 --tile-blocks 8 --budget-mb 256 \
  --clearance 1000 --frames 600 -o "$OUT/fractal8193_tiles"
"$FF" terrain tiles fractal:16385:23:relief=3000:roughness=0.75 --block 128 --tile-blocks 8 --budget-mb 512 \
  --clearance 300 --frames 600 --cache "${TILE_CACHE_DIR:-/tmp}/terrain18_f16385.tiles" -o "$OUT/fractal16385_tiles"
