#!/usr/bin/env bash
# Automatic impostor placement measured (docs/BENCHMARKS.md, "Placement", after Jeschke et al. 2005, Table 1 and
# Figure 8): a procedural city with one object per building, the cost profile of this machine (farfield calibrate,
# 500 validation views), then placement over the whole street area at pedestrian and car eye heights for a sweep of
# frame budgets at the reference error bound, and the walkthrough benchmark of full, culled and placed along three
# paths for each budget (a walk, a drive, and independent random views of the view space; every frame rendered 3
# times, the fastest kept; full-geometry reference frames). Further
# rows: other error bounds, halved and doubled CPVs, fewer candidates, rectangular view cells and per-cell placement. tools/place_table.py makes the tables.
# Usage: scripts/bench_place.sh FARFIELD OUT [SEED] [BLOCKS] [FRAMES] [STRIDE]
# Environment: DETAIL (facade detail of the generated city, default the generator's: 1; 3 gives a city whose views
# are triangle-bound on llvmpipe, as the paper's 10.4 M-polygon Vienna was bound by its geometry), TMAXES (default "18 20 22 25 28"), BOUND (px, default 2), REF_TMAX (default 20), BOUNDS (default
# "1 4"), SIZE (default 512x512), ROWS=0 to skip the extra rows, FALLBACK (default "2,4": place --fallback-bounds;
# "" for none), MODEL_PROFILE (a profile whose frame model, safety factor and margin replace the fresh calibration's, its
# layered terms kept: for a machine loaded by other jobs while calibrating, with an earlier quiet calibration),
# PLACED_CAL=1 (the profile fitted on placed frames with the capped fill: place --visibility-only samples every
# region's visible set into the cache, then calibrate --fill-term --visibility-cache).
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/bench/place}
SEED=${3:-1}
BLOCKS=${4:-100}
FRAMES=${5:-300}
STRIDE=${6:-3}
TMAXES=${TMAXES:-"18 20 22 25 28"}
BOUND=${BOUND:-2}
REF_TMAX=${REF_TMAX:-20}
BOUNDS=${BOUNDS:-"1 4"}
SIZE=${SIZE:-512x512}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$OUT"
PLACE_COMMON=(--profile "$OUT/profile.json" --max-pitch 20 --size "$SIZE" --fov 45)

[ -f "$OUT/city.glb" ] || "$FARFIELD" gen city --blocks "$BLOCKS" --seed "$SEED" --detail "${DETAIL:-1}" --objects buildings -o "$OUT/city.glb" \
  > "$OUT/gen.txt"
# CAL_VIEWS (default 500): validation views of the frame model (8 is enough when MODEL_PROFILE replaces it).
[ "${PLACED_CAL:-0}" = 1 ] || [ -f "$OUT/calibrated.json" ] || "$FARFIELD" calibrate "$OUT/city.glb" -o "$OUT/calibrated.json" --views "${CAL_VIEWS:-500}" \
  --size "$SIZE" --fov 45 --csv "$OUT/calibration.csv" > "$OUT/calibrate.txt"
if [ "${PLACED_CAL:-0}" = 1 ]; then
  [ -f "$OUT/visibility.json" ] || "$FARFIELD" place "$OUT/city.glb" --visibility-only --cpv-size 46 \
    --visibility-cache "$OUT/visibility.json" > "$OUT/visibility-run.txt" 2>&1
  "$FARFIELD" calibrate "$OUT/city.glb" -o "$OUT/profile.json" --fill-term --visibility-cache "$OUT/visibility.json" \
    --views "${CAL_VIEWS:-500}" --size "$SIZE" --fov 45 --csv "$OUT/calibration-placed.csv" > "$OUT/calibrate-placed.txt"
elif [ -n "${MODEL_PROFILE:-}" ]; then
  python3 - "$OUT/calibrated.json" "$MODEL_PROFILE" "$OUT/profile.json" <<'PY'
import json, sys
fresh, quiet = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
for key in ("model", "safety_factor", "validation"):
    fresh[key] = quiet[key]
fresh["model"].setdefault("ms_per_mfill", 0.0)  # a model from a profile before version 3 has no fill term
fresh["safety_margin_ms"] = quiet.get("safety_margin_ms")  # none before version 4
fresh["validation"]["model_from"] = sys.argv[2]
json.dump(fresh, open(sys.argv[3], "w"), indent=2)
PY
else
  cp "$OUT/calibrated.json" "$OUT/profile.json"
fi
FALLBACK=${FALLBACK-2,4}
[ -n "$FALLBACK" ] && PLACE_COMMON+=(--fallback-bounds "$FALLBACK")
"$FARFIELD" path street "$OUT/city.streets.json" --frames "$FRAMES" --fps 2 --fov 45 --seed "$SEED" -o "$OUT/walk.json" \
  > /dev/null
"$FARFIELD" path street "$OUT/city.streets.json" --frames "$FRAMES" --fps 10 --fov 45 --car --seed "$((SEED + 1))" \
  -o "$OUT/drive.json" > /dev/null
"$FARFIELD" path views "$OUT/city.glb" --frames "$FRAMES" --fov 45 --seed "$((SEED + 2))" -o "$OUT/random.json" \
  > /dev/null

place() {  # NAME ARGS...
  local name=$1
  shift
  # A database of this build's format is reused; an older one (the store refuses it) is placed again.
  PLACED=0
  grep -q '"version": 3,' "$OUT/$name/placement.json" 2>/dev/null && return 0
  rm -rf "${OUT:?}/$name"
  PLACED=1
  # The view space's visibility cache, unless the row brings its own (other CPV sizes: other regions).
  local cache=(--visibility-cache "$OUT/visibility.json")
  case " $* " in *" --visibility-cache "*) cache=() ;; esac
  /usr/bin/time -f "%e s, %M kB" -o "$OUT/$name.time" "$FARFIELD" place "$OUT/city.glb" "${PLACE_COMMON[@]}" "${cache[@]}" \
    -o "$OUT/$name" "$@" > "$OUT/$name.txt" 2>&1
}

for t in $TMAXES; do
  place "place-b$BOUND-t$t" --tmax "$t" --error-px "$BOUND" --cpv-size 46
  if [ "$PLACED" = 1 ]; then rm -rf "$OUT"/bench-*-"t$t"; fi  # measured on the database placed before
  for path in walk drive random; do
    [ -f "$OUT/bench-$path-t$t/bench.json" ] && continue
    "$FARFIELD" bench "$OUT/city.glb" --path "$OUT/$path.json" --modes full,culled,placed \
      --impostors "$OUT/place-b$BOUND-t$t" --reference --size "$SIZE" --repeats 3 --tmax "$t" --error-px "$BOUND" \
      --stride "$STRIDE" --samples 2 -o "$OUT/bench-$path-t$t" > "$OUT/bench-$path-t$t.txt" 2>&1
  done
done
if [ "${ROWS:-1}" != 0 ]; then
  for b in $BOUNDS; do place "place-b$b-t$REF_TMAX" --tmax "$REF_TMAX" --error-px "$b" --cpv-size 46; done
  place "place-cpv-half" --tmax "$REF_TMAX" --error-px "$BOUND" --cpv-size 23 --visibility-cache "$OUT/visibility-23.json"
  place "place-cpv-double" --tmax "$REF_TMAX" --error-px "$BOUND" --cpv-size 92 --visibility-cache "$OUT/visibility-92.json"
  place "place-fewer-candidates" --tmax "$REF_TMAX" --error-px "$BOUND" --cpv-size 46 --distance-steps 3
  # Rectangular view cells (the paper's test 13) and per-cell placement (test 14: the smallest regions only).
  place "place-boxes-t$REF_TMAX" --tmax "$REF_TMAX" --error-px "$BOUND" --cpv-size 46 --view-cells boxes
  place "place-leaf-boxes-t$REF_TMAX" --tmax "$REF_TMAX" --error-px "$BOUND" --cpv-size 46 --view-cells leaf-boxes
fi
python3 "$here/../tools/place_table.py" "$OUT"
