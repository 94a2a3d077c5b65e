#!/usr/bin/env bash
# Figures for docs/BENCHMARKS.md ("Occlusion culling"): the CPU culled baseline with occlusion culling (mode
# "culled-cpu", called "culled" before the GPU-driven frame took that name)
# against the frustum-only culling it replaced (mode "frustum"), in one process on the same frames, with
# full-geometry reference frames (both must be identical to them), on the default city and cities of other seeds
# and sizes, on a car drive and a pedestrian walk of 300 frames at 640x360.
# Usage: scripts/bench_occlusion.sh [FARFIELD] [OUT] [STRIDE] [REPEATS]
# Each case: "BLOCKS SEED PATH" (PATH car or walk).
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/bench/occlusion}
STRIDE=${3:-3}
REPEATS=${4:-3}
CASES=${FF_OCCLUSION_CASES:-"400 1 car;400 1 walk;700 23 car;500 41 walk;1000 57 car"}
mkdir -p "$OUT"
table="$OUT/occlusion.md"
{
  echo "| city (blocks, seed) | path | frames | frustum median ms | culled median ms | culled / frustum | p99 frustum / culled ms | frustum tris | culled tris | hidden items/frame | readback ms | identical to reference |"
  echo "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|"
} > "$table"
IFS=';' read -r -a cases <<< "$CASES"
for c in "${cases[@]}"; do
  read -r blocks seed path <<< "$c"
  city="$OUT/city-$blocks-$seed"
  mkdir -p "$city"
  [ -f "$city/city.glb" ] || "$FARFIELD" gen city --blocks "$blocks" --detail 2 --seed "$seed" --objects buildings \
    -o "$city/city.glb" > "$city/gen.txt"
  car=(); [ "$path" = car ] && car=(--car)
  run="$city/$path"
  mkdir -p "$run"
  "$FARFIELD" path street "$city/city.streets.json" --frames 300 --seed "$seed" "${car[@]}" --fov 60 -o "$run/path.json" \
    > "$run/path.txt"
  "$FARFIELD" bench "$city/city.glb" --path "$run/path.json" --modes frustum,culled-cpu --reference --size 640x360 \
    --stride "$STRIDE" --repeats "$REPEATS" -o "$run/bench" > "$run/bench.txt" 2>&1
  python3 - "$run/bench/bench.json" "$blocks" "$seed" "$path" >> "$table" <<'PY'
import json, sys
b = json.load(open(sys.argv[1]))
m = b["modes"]
f, c = m["frustum"], m["culled-cpu"]
info = c.get("info", {})
same = all(x["psnr_db_min"] >= 99.0 for x in (f, c))
print(f"| {sys.argv[2]}, seed {sys.argv[3]} | {sys.argv[4]} | {b['frames']} | {f['median_ms']:.1f} | "
      f"{c['median_ms']:.1f} | {c['median_ms'] / f['median_ms']:.2f} | {f['p99_ms']:.1f} / {c['p99_ms']:.1f} | "
      f"{f['mean_triangles']:.0f} | {c['mean_triangles']:.0f} | "
      f"{info.get('occlusion_hidden_items_per_frame', 0):.0f} | {info.get('occlusion_readback_ms_per_frame', 0):.1f} | "
      f"{'yes' if same else 'NO'} |")
PY
  echo "bench_occlusion: $blocks blocks, seed $seed, $path done" >&2
done
cat "$table"
