#!/usr/bin/env bash
# Layers drawn as their tiles against whole quads (docs/BENCHMARKS.md, "Placement"): on a run of scripts/bench_place.sh
# (its city, visibility cache, placed-frames profile and paths), for each budget
# - placement with the fill charged over the tiles (the default) and over whole quads (`place --no-layer-tiles`, with
#   the layered draw term timed on whole quads: `calibrate --no-layer-tiles`, merged into a copy of the profile so
#   that both placements share the frame model, its factor and margin);
# - the placed walkthrough along each path, each database drawn the way it was placed (tiles; whole quads through
#   `--mode-option layer_tiles=off`), back to back, each frame the fastest of 3 renders, the tiles run against
#   full-geometry reference frames.
# tools/layer_tiles_table.py makes the tables.
# Usage: scripts/bench_layer_tiles.sh FARFIELD OUT "TMAXES" [BOUND] [STRIDE]
set -euo pipefail
FARFIELD=${1:?farfield binary}
OUT=${2:?the output folder of scripts/bench_place.sh}
TMAXES=${3:?budgets, e.g. "40 30"}
BOUND=${4:-2}
STRIDE=${5:-3}
SIZE=${SIZE:-512x512}
here=$(cd "$(dirname "$0")" && pwd)

# The layered terms timed on whole quads (8 frame views: only the layered terms are kept).
if [ ! -f "$OUT/profile-whole.json" ]; then
  "$FARFIELD" calibrate "$OUT/city.glb" -o "$OUT/calibrated-whole.json" --no-layer-tiles --views 8 --size "$SIZE" \
    --fov 45 --visibility-cache "$OUT/visibility.json" > "$OUT/calibrate-whole.txt"
  python3 - "$OUT/profile.json" "$OUT/calibrated-whole.json" "$OUT/profile-whole.json" <<'PY'
import json, sys
profile, whole = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
profile["layered"] = whole["layered"]
profile["validation"]["layered_from"] = sys.argv[2]
json.dump(profile, open(sys.argv[3], "w"), indent=2)
PY
fi

for t in $TMAXES; do
  for kind in tiles whole; do
    db="$OUT/lt-$kind-b$BOUND-t$t"
    profile="$OUT/profile.json"
    extra=()
    if [ "$kind" = whole ]; then
      profile="$OUT/profile-whole.json"
      extra=(--no-layer-tiles)
    fi
    [ -f "$db/placement.json" ] || /usr/bin/time -f "%e s, %M kB" -o "$db.time" "$FARFIELD" place "$OUT/city.glb" \
      --profile "$profile" --max-pitch 20 --size "$SIZE" --fov 45 --visibility-cache "$OUT/visibility.json" \
      --fallback-bounds 2,4 --tmax "$t" --error-px "$BOUND" --cpv-size 46 "${extra[@]}" -o "$db" > "$db.txt" 2>&1
  done
  for path in walk drive random; do
    for kind in tiles whole; do
      run="$OUT/lt-bench-$path-t$t-$kind"
      [ -f "$run/bench.json" ] && continue
      args=(--modes placed --impostors "$OUT/lt-$kind-b$BOUND-t$t")
      if [ "$kind" = tiles ]; then args+=(--reference); else args+=(--mode-option layer_tiles=off); fi
      "$FARFIELD" bench "$OUT/city.glb" --path "$OUT/$path.json" "${args[@]}" --size "$SIZE" --repeats 3 --tmax "$t" \
        --error-px "$BOUND" --stride "$STRIDE" -o "$run" > "$run.txt" 2>&1
    done
  done
done
python3 "$here/../tools/layer_tiles_table.py" "$OUT" $TMAXES
