#!/usr/bin/env bash
# Figures for docs/BENCHMARKS.md ("Faster bakes: occlusion-culled PVS views"): the PVS sampler's 360-degree item-buffer
# views with occlusion culling against the same views without it (frustum and facing culling of the clusters only),
# in one process on the same viewpoints, and whether they see the same objects (`farfield pvs-speed`), on cities of
# seeds and sizes that no test used, at the eyes of a street walk.
# Usage: scripts/bench_pvs.sh [FARFIELD] [OUT] [POINTS]
# Each case: "BLOCKS SEED DETAIL GROUPING" (GROUPING blocks or buildings).
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/bench/pvs}
POINTS=${3:-40}
CASES=${FF_PVS_CASES:-"400 7 2 blocks;400 7 2 buildings;2000 19 1 blocks;10000 3 1 blocks;100000 3 0 blocks"}
SHARES=${FF_PVS_SHARES:-0.02,0.05,0.1}
FACE=${FF_PVS_FACE:-64}
mkdir -p "$OUT"
table="$OUT/pvs.md"
{
  echo "| city (blocks, seed, detail, objects) | M triangles | viewpoints | face px | unculled ms/point | culled ms/point (share) | speedup | M triangles drawn unculled / culled per point | viewpoints that differ |"
  echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|"
} > "$table"
IFS=';' read -r -a cases <<< "$CASES"
for c in "${cases[@]}"; do
  read -r blocks seed detail grouping <<< "$c"
  city="$OUT/city-$blocks-$seed-$detail-$grouping"
  mkdir -p "$city"
  [ -f "$city/city.glb" ] || "$FARFIELD" gen city --blocks "$blocks" --detail "$detail" --seed "$seed" \
    --objects "$grouping" -o "$city/city.glb" > "$city/gen.txt"
  [ -f "$city/walk.json" ] || "$FARFIELD" path street "$city/city.streets.json" --frames 2000 --seed "$seed" \
    -o "$city/walk.json" > "$city/path.txt"
  "$FARFIELD" pvs-speed "$city/city.glb" --path "$city/walk.json" --points "$POINTS" --face "$FACE" \
    --shares "$SHARES" -o "$city/pvs.json" | tee "$city/pvs.txt"
  python3 - "$city/pvs.json" "$blocks" "$seed" "$detail" "$grouping" "$FACE" >> "$table" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
runs = r["runs"]
ref = runs[0]
best = min(runs[1:], key=lambda x: x["ms"])
n = r["points"]
differ = max(x["mismatched_points"] for x in runs[1:])
print(f"| {sys.argv[2]}, {sys.argv[3]}, {sys.argv[4]}, {sys.argv[5]} | {r['scene_triangles'] / 1e6:.2f} | {n} | "
      f"{sys.argv[6]} | {ref['ms_per_point']:.1f} | {best['ms_per_point']:.1f} ({best['occluder_share']}) | "
      f"{ref['ms'] / best['ms']:.1f}x | {ref['triangles_drawn'] / n / 1e6:.2f} / {best['triangles_drawn'] / n / 1e6:.3f} | "
      f"{differ} of {n} |")
PY
done
cat "$table"
