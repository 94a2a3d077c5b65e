#!/usr/bin/env bash
# Figures for docs/BENCHMARKS.md ("The frame governor"): the GPU-driven frame ("culled") against the same frame under
# the frame governor ("governed": eval/governed_mode.h, runtime/frame_governor.h) at budgets set from this machine's
# own culled frames (FACTORS x their median), on cities and paths that no test and no tuning of the governor used.
# Each run has full-geometry reference frames, so the image error and the bound every governed frame kept are checked
# (--error-px 1: a frame drawn at scale s is checked against 1 / s px).
#
#   scripts/bench_governor.sh [FARFIELD] [OUT]
#
# Environment: SIZE (640x360), STRIDE (5: every 5th of 300 frames), FACTORS ("0.8"), RUNS ("d3-car d3-walk
# d2-car"). Writes OUT/governor.md (the table) and, per run, OUT/RUN/tX/ (bench outputs with governor.png).
set -euo pipefail
FARFIELD=$(readlink -f "${1:-build/release/bin/farfield}")
OUT=$(readlink -m "${2:-out/bench/governor}")
SIZE=${SIZE:-640x360}
STRIDE=${STRIDE:-5}
FACTORS=${FACTORS:-"0.8"}
RUNS=${RUNS:-"d3-car d3-walk d2-car"}
export FF_PROGRESS=0
mkdir -p "$OUT"

# city NAME BLOCKS DETAIL SEED: OUT/NAME/city.glb and its car and walk paths, made once.
city() {
  local name=$1 blocks=$2 detail=$3 seed=$4
  mkdir -p "$OUT/$name"
  [ -f "$OUT/$name/city.glb" ] || "$FARFIELD" gen city --blocks "$blocks" --detail "$detail" --seed "$seed" \
    --objects buildings -o "$OUT/$name/city.glb" > "$OUT/$name/gen.txt"
  [ -f "$OUT/$name/car.json" ] || "$FARFIELD" path street "$OUT/$name/city.streets.json" --frames 300 \
    --seed $((seed + 1)) --car --fov 60 -o "$OUT/$name/car.json" > /dev/null
  [ -f "$OUT/$name/walk.json" ] || "$FARFIELD" path street "$OUT/$name/city.streets.json" --frames 300 \
    --seed $((seed + 2)) --fov 60 -o "$OUT/$name/walk.json" > /dev/null
}
city d3 300 3 173
city d2 300 2 59

for run in $RUNS; do
  scene=${run%-*}
  kind=${run#*-}
  dir="$OUT/$run"
  mkdir -p "$dir"
  common=("$OUT/$scene/city.glb" --path "$OUT/$scene/$kind.json" --size "$SIZE" --stride "$STRIDE")
  # The machine's own culled frames: their median sets the budgets.
  [ -f "$dir/base/bench.json" ] || "$FARFIELD" bench "${common[@]}" --modes culled -o "$dir/base" \
    > "$dir/base.txt" 2>&1
  median=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['modes']['culled']['median_ms'])" \
    "$dir/base/bench.json")
  for f in $FACTORS; do
    tmax=$(python3 -c "print(round($f * $median, 2))")
    [ -f "$dir/t$f/bench.json" ] || "$FARFIELD" bench "${common[@]}" --modes culled,governed --tmax "$tmax" \
      --reference --error-px 1 -o "$dir/t$f" > "$dir/t$f.txt" 2>&1
  done
  echo "bench_governor: $run done" >&2
done

python3 - "$OUT" "$RUNS" "$FACTORS" > "$OUT/governor.md" <<'PY'
import json, sys
out, runs, factors = sys.argv[1], sys.argv[2].split(), sys.argv[3].split()
print("| run | t_max ms (x culled median) | mode | median ms | p99 ms | frames over t_max | frames relaxed | "
      "frames per level (simplified px @ resolution) | measured / expected p50, p95 | PSNR mean dB | frames over bound "
      "| own CPU median ms | syncs | triangles |")
print("|---|---|---|---:|---:|---:|---:|---|---|---:|---:|---:|---:|---:|")
for run in runs:
    for f in factors:
        b = json.load(open(f"{out}/{run}/t{f}/bench.json"))
        for name in ("culled", "governed"):
            m = b["modes"][name]
            i = m["info"]
            n = len(b.get("frames", [])) if isinstance(b.get("frames"), list) else b["frames"]
            levels = "-"
            ratio = "-"
            relaxed = "-"
            if name == "governed":
                levels = ", ".join(f"{i[f'governor_level_{k}_lod_px']:g}@{i[f'governor_level_{k}_scale']:g}: "
                                   f"{int(i[f'governor_level_{k}_frames'])}"
                                   for k in range(int(i["governor_levels"]))
                                   if i[f"governor_level_{k}_frames"] > 0)
                ratio = f"{i['governor_measured_over_corrected_p50']:.2f}, {i['governor_measured_over_corrected_p95']:.2f}"
                relaxed = str(m["frames_relaxed"])
            over_bound = m["frames_over_bound"]
            print(f"| {run} | {m['t_max_ms']:.2f} ({f}x) | {name} | {m['median_ms']:.1f} | {m['p99_ms']:.1f} | "
                  f"{m['frames_over_tmax']} of {n} | {relaxed} | {levels} | {ratio} | {m['psnr_db_mean']:.1f} | "
                  f"{over_bound if over_bound is not None else '-'} of {m['frames_checked_against_bound']} | "
                  f"{m['cpu_median_ms']:.3f} | {m['mean_syncs']:.2f} | {m['mean_triangles']:.0f} |")
PY
cat "$OUT/governor.md"
