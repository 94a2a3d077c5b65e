#!/usr/bin/env bash
# The main job on the built-in default scene (`make demo`): the default city (400 blocks, facade detail 2: about
# 5.7 M triangles, one object per building), a 300-frame street drive, the cost profile of this machine measured
# over the drive's district, automatic impostor placement there (Jeschke et al. 2005) under the two promises (an
# error bound of 2 px and a frame budget t_max of 25 ms: on llvmpipe below what the cost profile predicts for the
# district's slowest views, 27-36 ms in the runs of docs/BENCHMARKS.md, so the placement has problem views to solve;
# a faster GPU wants a lower FF_DEMO_TMAX), and the walkthrough benchmark of full geometry, view-frustum culling, the
# placed impostors, and the placed impostors under the frame governor (`governed`: coarser levels before a frame would
# break t_max, each relaxed frame reported with the bound it kept) against full-geometry reference frames. The
# report's verdict is the governed walkthrough's.
# Writes OUT/report.html (self-contained: the verdict of the two promises first) and OUT/report.md.
# Environment: FF_DEMO_BLOCKS, FF_DEMO_DETAIL, FF_DEMO_SEED, FF_DEMO_FRAMES, FF_DEMO_STRIDE, FF_DEMO_TMAX (ms), FF_DEMO_BOUND (px).
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/demo}
BLOCKS=${FF_DEMO_BLOCKS:-400}
DETAIL=${FF_DEMO_DETAIL:-2}
SEED=${FF_DEMO_SEED:-1}
FRAMES=${FF_DEMO_FRAMES:-300}
STRIDE=${FF_DEMO_STRIDE:-2}
TMAX=${FF_DEMO_TMAX:-25}
BOUND=${FF_DEMO_BOUND:-2}
SIZE=640x360
FOV=60
MARGIN=30
mkdir -p "$OUT"
start=$(date +%s)
commands="$OUT/commands.txt"
: > "$commands"
step() {  # TITLE LOG COMMAND...: runs a step, keeps its output in LOG and the command in commands.txt
  local title=$1 log=$2
  shift 2
  echo "== [$(( $(date +%s) - start )) s] $title"
  echo "${*/#$FARFIELD/farfield}" | sed "s|$OUT/||g" >> "$commands"
  "$@" 2>&1 | tee "$log"
}

step "generate the default city (blocks $BLOCKS, detail $DETAIL, seed $SEED, one object per building)" "$OUT/gen.txt" \
  "$FARFIELD" gen city --blocks "$BLOCKS" --detail "$DETAIL" --seed "$SEED" --objects buildings -o "$OUT/city.glb"
step "a $FRAMES-frame street drive" "$OUT/path.txt" \
  "$FARFIELD" path street "$OUT/city.streets.json" --frames "$FRAMES" --seed "$SEED" --car --fov "$FOV" -o "$OUT/path.json"
step "measure this machine's frame cost over the drive's district (about a minute)" "$OUT/calibrate.txt" \
  "$FARFIELD" calibrate "$OUT/city.glb" -o "$OUT/profile.json" --size "$SIZE" --fov "$FOV" --views 60 --fit-views 40 \
  --around "$OUT/path.json" --margin "$MARGIN"
step "place impostors under ${BOUND} px and t_max ${TMAX} ms over the district" "$OUT/place.txt" \
  "$FARFIELD" place "$OUT/city.glb" --profile "$OUT/profile.json" -o "$OUT/placement" --tmax "$TMAX" \
  --error-px "$BOUND" --size "$SIZE" --fov "$FOV" --around "$OUT/path.json" --margin "$MARGIN" --max-pitch 20
step "benchmark full, culled, placed and placed under the frame governor against full-geometry reference frames (a few minutes)" "$OUT/bench.txt" \
  "$FARFIELD" bench "$OUT/city.glb" --path "$OUT/path.json" --impostors "$OUT/placement" \
  --modes full,culled,placed,governed --mode-option governed=placed --mode-option governor_error_px="$BOUND" \
  --reference --size "$SIZE" --tmax "$TMAX" --error-px "$BOUND" --stride "$STRIDE" -o "$OUT" \
  --report "$OUT/bench_report.md"

elapsed=$(( $(date +%s) - start ))
{
  echo "Made on $(date -u +%Y-%m-%d) in $elapsed s (after the build) by scripts/demo.sh:"
  echo
  cat "$commands"
  echo
  echo "The placement (farfield place):"
  grep -E '^(promises|view space|greedy|CPVs|memory|wall):' "$OUT/place.txt" || true
  echo
  echo "Look around: farfield view $OUT/city.glb --impostors $OUT/placement --path $OUT/path.json"
} > "$OUT/notes.txt"
"$FARFIELD" report "$OUT" --mode governed --database "$OUT/placement" --notes "$OUT/notes.txt" \
  --title "Farfield demo: the default city, impostors placed under ${BOUND} px and ${TMAX} ms, kept by the frame governor" \
  -o "$OUT/report.html"

{
  echo "# Farfield demo: the default city"
  echo
  echo '```'; cat "$OUT/notes.txt"; echo '```'
  echo
  echo '```'; cat "$OUT/gen.txt"; echo '```'
  echo
  cat "$OUT/bench_report.md"
} > "$OUT/report.md"
echo "demo: $elapsed s; open $OUT/report.html (also $OUT/report.md)"
echo "demo: look around with: $FARFIELD view $OUT/city.glb --impostors $OUT/placement --path $OUT/path.json"
