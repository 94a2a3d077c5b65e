#!/usr/bin/env bash
# The frame budget kept on the frames the runtime draws (issue 43's check), as a new user would try it: for each city
# and path (none used by a test or tuning), this machine's frame with region visibility alone (a placement with no
# impostor whose every region has its visible set: `--view-cells none` under a t_max no view meets; median M, measured
# by the same benchmark, with the same reference frames, as the runs it sets t_max for), then for each factor f a
# placement under t_max = f x M and an error bound, and the walkthrough benchmark of the placed impostors without the
# governor (the cost model alone) and under it (`governed`), against full-geometry reference frames; and the same two
# walkthroughs walked alone over every frame of the path (`farfield walk`: no other mode's frames and no reference
# between them, as a program embedding the runtime draws them). Writes OUT/budget.md: per city, path and factor, the
# impostors placed and their GPU memory, frames over t_max with and without the governor, frames relaxed (and to what
# bound), the image error, and the cost model's measured / predicted quantiles on the calibration's held-out views.
# Usage: scripts/bench_budget_factors.sh FARFIELD OUT
# Environment: CASES (default "150:3:211:car 150:3:307:walk 200:2:419:car": blocks:detail:seed:path, path car or
# walk), FACTORS (default "0.4 0.6 0.8"), BOUND (px, default 2), FRAMES (path frames, default 300), STRIDE (default 3),
# CALIBRATE_OPTIONS (more options of `farfield calibrate`, e.g. --fill-term), WALK_ONLY=1 (no bench: the baseline,
# placed and governed walkthroughs walked alone over every frame, t_max from the baseline walked alone;
# OUT/budget_walk.md: what a program embedding the runtime sees, without the bench's full-geometry and reference
# frames between its frames).
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/bench/budget}
CASES=${CASES:-"150:3:211:car 150:3:307:walk 200:2:419:car"}
FACTORS=${FACTORS:-"0.4 0.6 0.8"}
BOUND=${BOUND:-2}
FRAMES=${FRAMES:-300}
STRIDE=${STRIDE:-3}
SIZE=640x360
FOV=60
mkdir -p "$OUT"
start=$(date +%s)
say() { echo "== [$(( $(date +%s) - start )) s] $*"; }
table="$OUT/budget.md"
if [ "${WALK_ONLY:-0}" = 1 ]; then
  {
    echo "# The frame budget walked alone, at factors of the region-visibility-alone walk ($(date -u +%Y-%m-%d))"
    echo
    echo "WALK_ONLY=1 scripts/bench_budget_factors.sh; $SIZE, every frame of ${FRAMES}-frame paths, ${BOUND} px."
    echo
    echo "| city (blocks, detail, seed) | path | region visibility alone walked: median ms | model held-out measured/predicted p50, p95 (CPU term p95, GPU term p95) | factor | t_max ms | impostors | GPU MiB | placed: median, max ms, frames over t_max | governed: median, max ms, frames over t_max |"
    echo "|---|---|---:|---|---:|---:|---:|---:|---|---|"
  } > "$OUT/budget_walk.md"
  table=/dev/null
fi
{
  echo "# The frame budget at factors of the no-impostor walkthrough ($(date -u +%Y-%m-%d))"
  echo
  echo "scripts/bench_budget_factors.sh; $SIZE, ${FRAMES}-frame paths, every ${STRIDE}th frame measured, ${BOUND} px."
  echo
  echo "| city (blocks, detail, seed) | path | region visibility alone: median ms | model held-out measured/predicted p50, p95 (CPU term p95, GPU term p95) | factor | t_max ms | impostors | GPU MiB | placed: median ms, frames over t_max | governed: median ms, frames over t_max, relaxed (largest bound px) | PSNR placed / governed dB | frames over the bound | walked alone: placed, governed median ms, frames over t_max |"
  echo "|---|---|---:|---|---:|---:|---:|---:|---|---|---|---|---|"
} > "$table"
for spec in $CASES; do
  IFS=: read -r blocks detail seed kind <<< "$spec"
  dir="$OUT/b${blocks}-d${detail}-s${seed}-${kind}"
  mkdir -p "$dir"
  say "city $blocks blocks, detail $detail, seed $seed; a $kind path"
  "$FARFIELD" gen city --blocks "$blocks" --detail "$detail" --seed "$seed" --objects buildings -o "$dir/city.glb" \
    > "$dir/gen.txt" 2>&1
  car=()
  [ "$kind" = car ] && car=(--car)
  "$FARFIELD" path street "$dir/city.streets.json" --frames "$FRAMES" --seed "$seed" "${car[@]}" --fov "$FOV" \
    -o "$dir/path.json" > "$dir/path.txt" 2>&1
  district=(--size "$SIZE" --fov "$FOV" --around "$dir/path.json" --margin 30 --max-pitch 20 --error-px "$BOUND"
            --visibility-cache "$dir/visibility.bin")
  say "visible sets"
  "$FARFIELD" place "$dir/city.glb" -o "$dir/visibility" "${district[@]}" --visibility-only > "$dir/visibility.txt" 2>&1
  say "calibrate"
  "$FARFIELD" calibrate "$dir/city.glb" -o "$dir/profile.json" --size "$SIZE" --fov "$FOV" --views 60 --fit-views 40 \
    --visibility-cache "$dir/visibility.bin" ${CALIBRATE_OPTIONS:-} > "$dir/calibrate.txt" 2>&1
  ratios=$(python3 -c '
import json, sys
p = json.load(open(sys.argv[1]))
v = p.get("validation", {})
term = lambda k: v.get(k, {}).get("ratio_p95", float("nan"))
print("%.2f, %.2f (%.2f, %.2f)" % (v.get("ratio_p50", float("nan")), v.get("ratio_p95", float("nan")),
                                 term("cpu_term"), term("gpu_term")))' "$dir/profile.json" \
    2>/dev/null || echo "?")
  say "region visibility alone: every region's visible set, no impostor; benchmarked"
  "$FARFIELD" place "$dir/city.glb" --profile "$dir/profile.json" -o "$dir/no_impostor" --tmax 0.001 \
    "${district[@]}" --view-cells none > "$dir/no_impostor.txt" 2>&1
  if [ "${WALK_ONLY:-0}" = 1 ]; then
    "$FARFIELD" walk "$dir/city.glb" --path "$dir/path.json" --mode placed \
      --mode-option impostor_dir="$dir/no_impostor" --size "$SIZE" > "$dir/no_impostor_walk.txt" 2>&1
    median=$(awk '/^wall ms:/ {print $4}' "$dir/no_impostor_walk.txt")
  else
    "$FARFIELD" bench "$dir/city.glb" --path "$dir/path.json" --impostors "$dir/no_impostor" --modes placed \
      --reference --size "$SIZE" --error-px "$BOUND" --stride "$STRIDE" -o "$dir/no_impostor_bench" \
      > "$dir/no_impostor_bench.txt" 2>&1
    median=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["modes"]["placed"]["median_ms"])' \
      "$dir/no_impostor_bench/bench.json")
  fi
  for f in $FACTORS; do
    tmax=$(awk -v m="$median" -v f="$f" 'BEGIN {printf "%.1f", m * f}')
    run="$dir/f$f"
    mkdir -p "$run"
    say "factor $f: t_max $tmax ms: place"
    "$FARFIELD" place "$dir/city.glb" --profile "$dir/profile.json" -o "$run/placement" --tmax "$tmax" \
      "${district[@]}" > "$run/place.txt" 2>&1
    if [ "${WALK_ONLY:-0}" != 1 ]; then
    say "factor $f: bench placed and governed"
    "$FARFIELD" bench "$dir/city.glb" --path "$dir/path.json" --impostors "$run/placement" \
      --modes placed,governed --mode-option governed=placed --mode-option governor_error_px="$BOUND" \
      --reference --size "$SIZE" --tmax "$tmax" --error-px "$BOUND" --stride "$STRIDE" -o "$run" \
      > "$run/bench.txt" 2>&1
    fi
    say "factor $f: walk placed and governed alone"
    "$FARFIELD" walk "$dir/city.glb" --path "$dir/path.json" --mode placed \
      --mode-option impostor_dir="$run/placement" --size "$SIZE" --csv "$run/walk_placed.csv" > "$run/walk_placed.txt" 2>&1
    "$FARFIELD" walk "$dir/city.glb" --path "$dir/path.json" --mode governed --mode-option governed=placed \
      --mode-option impostor_dir="$run/placement" --mode-option governor_error_px="$BOUND" \
      --mode-option governor_t_max_ms="$tmax" --size "$SIZE" --csv "$run/walk_governed.csv" \
      > "$run/walk_governed.txt" 2>&1
    if [ "${WALK_ONLY:-0}" = 1 ]; then
      python3 - "$run" "$blocks" "$detail" "$seed" "$kind" "$median" "$ratios" "$f" "$tmax" >> "$OUT/budget_walk.md" <<'EOF'
import csv, json, statistics, sys
run, blocks, detail, seed, kind, median, ratios, f, tmax = sys.argv[1:]
placement = json.load(open(run + "/placement/placement.json"))["summary"]
def walked(name):
    rows = list(csv.DictReader(open(run + "/walk_" + name + ".csv")))
    walls = [float(r["wall_ms"]) for r in rows]
    return f"{statistics.median(walls):.1f}, {max(walls):.1f}, {sum(w > float(tmax) for w in walls)} of {len(walls)}"
print(f"| {blocks}, {detail}, {seed} | {kind} | {float(median):.1f} | {ratios} | {f} | {float(tmax):.1f} | "
      f"{placement['impostors']} | {placement['memory_bytes'] / 2**20:.1f} | {walked('placed')} | {walked('governed')} |")
EOF
      continue
    fi
    python3 - "$run" "$blocks" "$detail" "$seed" "$kind" "$median" "$ratios" "$f" "$tmax" "$BOUND" >> "$table" <<'EOF'
import json, sys
run, blocks, detail, seed, kind, median, ratios, f, tmax, bound = sys.argv[1:]
placement = json.load(open(run + "/placement/placement.json"))["summary"]
bench = json.load(open(run + "/bench.json"))
p, g = bench["modes"]["placed"], bench["modes"]["governed"]
frames = p.get("frames_checked_against_bound", bench.get("frames", 0))
def walked(csv_file, t_max):
    import csv, statistics
    walls = [float(r["wall_ms"]) for r in csv.DictReader(open(csv_file))]
    return f"{statistics.median(walls):.1f} ms, {sum(w > t_max for w in walls)} of {len(walls)}"
print(f"| {blocks}, {detail}, {seed} | {kind} | {float(median):.1f} | {ratios} | {f} | {float(tmax):.1f} | "
      f"{placement['impostors']} | {placement['memory_bytes'] / 2**20:.1f} | "
      f"{p['median_ms']:.1f}, {p['frames_over_tmax']} of {frames} | "
      f"{g['median_ms']:.1f}, {g['frames_over_tmax']} of {frames}, {g['frames_relaxed']} "
      f"({float(bound) * g['bound_scale_max']:.0f}) | {p['psnr_db_mean']:.1f} / {g['psnr_db_mean']:.1f} | "
      f"{p['frames_over_bound']} / {g['frames_over_bound']} | {walked(run + '/walk_placed.csv', float(tmax))}, "
      f"{walked(run + '/walk_governed.csv', float(tmax))} |")
EOF
  done
done
if [ "${WALK_ONLY:-0}" = 1 ]; then table="$OUT/budget_walk.md"; fi
say "wrote $table"
cat "$table"
