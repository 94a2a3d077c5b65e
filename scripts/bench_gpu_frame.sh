#!/usr/bin/env bash
# Figures for docs/BENCHMARKS.md ("The GPU-driven frame"): the GPU-culled frame ("culled") against the CPU culling it
# replaced ("culled-cpu": frustum, facing and occlusion culling with the occluders' depth read back) and frustum
# culling ("frustum"), one process per scene on the same frames, with Farfield's own CPU time, draw calls, GL calls,
# uploads and CPU-GPU synchronisations per frame; then the GPU-culled frames checked against the frustum-culled ones
# on cities and paths that no test and no tuning used (farfield cull-check: the same object at every pixel outside
# coplanar ties, PSNR >= 60 dB).
#
#   scripts/bench_gpu_frame.sh [FARFIELD] [OUT]
#
# Environment: SIZE (640x360), STRIDE (5: every 5th of 300 frames), BIG (1: also the 100,000-block city, detail 0),
# CHECKS (1: the cull checks), SCENES ("demo heldout-d3 small-d0": the benchmark scenes, big added with BIG=1).
set -euo pipefail
FARFIELD=$(readlink -f "${1:-build/release/bin/farfield}")
OUT=$(readlink -m "${2:-out/bench/gpu-frame}")
SIZE=${SIZE:-640x360}
STRIDE=${STRIDE:-5}
BIG=${BIG:-1}
CHECKS=${CHECKS:-1}
SCENES=${SCENES:-"demo heldout-d3 small-d0"}
[ "$BIG" = 1 ] && SCENES="$SCENES big-d0"
export FF_PROGRESS=0
mkdir -p "$OUT"

# city NAME BLOCKS DETAIL SEED [gen options...]: generates OUT/NAME/city.glb once.
city() {
  local name=$1 blocks=$2 detail=$3 seed=$4
  shift 4
  mkdir -p "$OUT/$name"
  [ -f "$OUT/$name/city.glb" ] || "$FARFIELD" gen city --blocks "$blocks" --detail "$detail" --seed "$seed" "$@" \
    -o "$OUT/$name/city.glb" > "$OUT/$name/gen.txt"
}
# path NAME SEED car|walk: a 300-frame street path of the city.
path() {
  local name=$1 seed=$2 kind=$3 car=()
  [ "$kind" = car ] && car=(--car)
  [ -f "$OUT/$name/$kind.json" ] || "$FARFIELD" path street "$OUT/$name/city.streets.json" --frames 300 --seed "$seed" \
    "${car[@]}" --fov 60 -o "$OUT/$name/$kind.json" > /dev/null
}

# ---- the benchmark: frustum, culled-cpu and culled (full added as the baseline) ----
for s in $SCENES; do
  case $s in
    demo) city demo 400 2 1 --objects buildings; path demo 1 car ;;          # make demo's city and drive until 2026-12-05
    heldout-d3) city heldout-d3 400 3 97 --objects buildings; path heldout-d3 5 car ;;
    small-d0) city small-d0 400 0 3; path small-d0 41 car ;;               # the big city's kind, 400 blocks
    big-d0) city big-d0 100000 0 3; path big-d0 41 car ;;
    *) echo "bench_gpu_frame: unknown scene $s" >&2; exit 2 ;;
  esac
  [ -f "$OUT/$s/bench/bench.json" ] || "$FARFIELD" bench "$OUT/$s/city.glb" --path "$OUT/$s/car.json" \
    --modes frustum,culled-cpu,culled --size "$SIZE" --stride "$STRIDE" -o "$OUT/$s/bench" > "$OUT/$s/bench.txt" 2>&1
  echo "bench_gpu_frame: $s done" >&2
done

python3 - "$OUT" $SCENES > "$OUT/gpu-frame.md" <<'PY'
import json, sys
out, scenes = sys.argv[1], sys.argv[2:]
print("| scene | objects | mode | median ms | p95 ms | own CPU median ms | own CPU p95 ms | draw calls | GL calls | "
      "uploaded KB | syncs | triangles | speedup vs culled-cpu |")
print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
for s in scenes:
    b = json.load(open(f"{out}/{s}/bench/bench.json"))
    gen = open(f"{out}/{s}/gen.txt").read()
    objects = next((l.split()[-1] for l in gen.splitlines() if l.startswith("objects:")), "?")
    m = b["modes"]
    base = m["culled-cpu"]["median_ms"]
    for name in ("frustum", "culled-cpu", "culled"):
        e = m[name]
        print(f"| {s} | {objects} | {name} | {e['median_ms']:.1f} | {e['p95_ms']:.1f} | {e['cpu_median_ms']:.3f} | "
              f"{e['cpu_p95_ms']:.3f} | {e['mean_draw_calls']:.0f} | {e['mean_gl_calls']:.0f} | "
              f"{e['mean_upload_bytes'] / 1024:.1f} | {e['mean_syncs']:.2f} | {e['mean_triangles']:.0f} | "
              f"{base / e['median_ms']:.2f}x |")
PY
cat "$OUT/gpu-frame.md"

# ---- the checks: three cities of other seeds, detail 2 and 3, a car drive and a walk each ----
if [ "$CHECKS" = 1 ]; then
  {
    echo "| city (blocks, detail, seed) | path | frames | frames with a differing object pixel | PSNR min dB | tie pixels | colour ties in an object | result |"
    echo "|---|---|---:|---:|---:|---:|---:|---|"
  } > "$OUT/cull-check.md"
  for c in "300 2 83" "300 3 131" "500 3 211"; do
    read -r blocks detail seed <<< "$c"
    name=check-$blocks-$detail-$seed
    city "$name" "$blocks" "$detail" "$seed" --objects buildings
    for kind in car walk; do
      path "$name" $((seed + 7)) "$kind"
      [ -f "$OUT/$name/check-$kind/cullcheck.json" ] || "$FARFIELD" cull-check "$OUT/$name/city.glb" \
        --path "$OUT/$name/$kind.json" --size "$SIZE" --stride 2 -o "$OUT/$name/check-$kind" \
        > "$OUT/$name/check-$kind.txt" 2>&1 || true
      python3 - "$OUT/$name/check-$kind/cullcheck.json" "$blocks, $detail, $seed" "$kind" >> "$OUT/cull-check.md" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
print(f"| {sys.argv[2]} | {sys.argv[3]} | {j['frames']} | {j['frames_differing']} | {j['psnr_db_min']:.2f} | "
      f"{100 * j['tie_share_mean']:.4f}% | {100 * j['colour_tie_share_mean']:.4f}% | "
      f"{'passed' if j['passed'] else 'FAILED'} |")
PY
    done
    echo "bench_gpu_frame: check $name done" >&2
  done
  cat "$OUT/cull-check.md"
fi
