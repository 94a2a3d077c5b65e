#!/usr/bin/env bash
# What the impostors add to the placed frames (docs/BENCHMARKS.md, "Placement"): on a run of scripts/bench_place.sh,
# the placed mode alone along each path, with each budget's database and with one of no impostors (`place
# --view-cells none`: the same problem view space and regions' visible sets, occlusion-culled, and nothing else), one
# after the other on the same frames, each frame the fastest of 3 renders. tools/place_control_table.py makes the table.
# Usage: scripts/bench_place_control.sh FARFIELD OUT "TMAXES" [BOUND] [STRIDE]
set -euo pipefail
FARFIELD=${1:?farfield binary}
OUT=${2:?the output folder of scripts/bench_place.sh}
TMAXES=${3:?budgets, e.g. "40 30 20"}
BOUND=${4:-2}
STRIDE=${5:-3}
SIZE=${SIZE:-512x512}
here=$(cd "$(dirname "$0")" && pwd)
for t in $TMAXES; do
  # The same problem view space and visible sets as the budget's database, without a candidate.
  none="$OUT/place-none-t$t"
  [ -f "$none/placement.json" ] || "$FARFIELD" place "$OUT/city.glb" --profile "$OUT/profile.json" --max-pitch 20 \
    --size "$SIZE" --fov 45 --visibility-cache "$OUT/visibility.json" --tmax "$t" --error-px "$BOUND" --cpv-size 46 \
    --view-cells none -o "$none" > "$none.txt" 2>&1
  for path in walk drive random; do
    for db in "place-b$BOUND-t$t" "place-none-t$t"; do
      run="$OUT/control-$path-t$t-$db"
      [ -f "$run/bench.json" ] && continue
      "$FARFIELD" bench "$OUT/city.glb" --path "$OUT/$path.json" --modes placed --impostors "$OUT/$db" --size "$SIZE" \
        --repeats 3 --tmax "$t" --error-px "$BOUND" --stride "$STRIDE" -o "$run" > "$run.txt" 2>&1
    done
  done
done
/usr/bin/python3 "$here/../tools/place_control_table.py" "$OUT" $TMAXES
