#!/usr/bin/env bash
# A city and a terrain in one frame: a procedural city laid on a fractal terrain no test or tuning used, flown over
# and driven through, with the terrain drawn by the 1 px LOD (terrain-high+MODE), by the 1 px CDLOD on the GPU
# (terrain-high-gpu+MODE) or by LOD-sprite (terrain-lod-sprite+MODE) under the city's culled and dynamic-shade modes;
# then PSNR of the LOD-sprite and CDLOD composites' sample frames against the high-LOD composite's.
# Usage: scripts/bench_city_on_terrain.sh [OUT] [FRAMES]   (FARFIELD=path/to/farfield to use another binary)
set -euo pipefail
OUT=${1:-out/city-on-terrain}
FRAMES=${2:-60}
FF=${FARFIELD:-build/release/bin/farfield}
TERRAIN=${TERRAIN:-fractal:2049:17:relief=1200:roughness=0.55}
SCALE=${SCALE:-0.5}
mkdir -p "$OUT"
"$FF" gen city --blocks 200 --seed 7 --trees --terrain "$TERRAIN" --terrain-scale "$SCALE" -o "$OUT/city.glb"
"$FF" path flyover "$OUT/city.glb" --frames 300 --altitude 220 -o "$OUT/flyover.json"
"$FF" path street "$OUT/city.streets.json" --frames 300 --car --seed 8 --terrain "$TERRAIN" \
  --terrain-scale "$SCALE" -o "$OUT/drive.json"
modes=culled,terrain-high+culled,terrain-high-gpu+culled,terrain-lod-sprite+culled,dynamic-shade
modes=$modes,terrain-high+dynamic-shade,terrain-high-gpu+dynamic-shade,terrain-lod-sprite+dynamic-shade
modes=${MODES:-$modes}
for path in flyover drive; do
  "$FF" bench "$OUT/city.glb" --path "$OUT/$path.json" --modes "$modes" --frames "$FRAMES" \
    --mode-option terrain="$TERRAIN" --mode-option terrain_scale="$SCALE" -o "$OUT/$path" | tee "$OUT/$path.txt"
  for technique in lod-sprite high-gpu; do
    for f in "$OUT/$path"/frames/*_terrain-${technique}_culled.png; do
      [ -e "$f" ] || continue
      "$FF" diff "${f/terrain-$technique/terrain-high}" "$f" | sed "s|^|$(basename "$f"): |" >> "$OUT/$path-psnr.txt"
    done
  done
done
cat "$OUT"/*-psnr.txt
