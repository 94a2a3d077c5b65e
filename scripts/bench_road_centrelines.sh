#!/usr/bin/env bash
# Road centre lines of CityGML road areas on generated grids that no test uses: `farfield import` of an N x N city
# (scripts/make_citygml_road_grid.py, jittered streets of 6-14 m) for each N and seed, its street graph's counts
# against the grid's (N+1)^2 junctions, 2N(N+1) streets and N^2 blocks, the import's streets time, and a picture of
# one corner (road areas under the streets and junctions).
#
# usage: scripts/bench_road_centrelines.sh [OUT_DIR] [FARFIELD]   (sizes and seeds: SIZES="40 80" SEEDS="7 11")
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
out="${1:-out/roads}"
ff="${2:-build/release/bin/farfield}"
mkdir -p "$out"
printf '%-6s %-5s %10s %10s %8s %8s %12s\n' N seed junctions streets blocks expected "streets (s)"
for n in ${SIZES:-40 80}; do
  for seed in ${SEEDS:-7 11}; do
    base="$out/grid${n}_seed${seed}"
    python3 "$here/make_citygml_road_grid.py" "$n" "$seed" "$base.gml"
    line="$("$ff" import "$base.gml" -o "$base.glb" 2>&1 | tr '\r' '\n')"
    counts="$(grep '^streets:' <<<"$line" | sed -E 's/.*-> ([0-9]+) junctions, ([0-9]+) streets, ([0-9]+) blocks.*/\1 \2 \3/')"
    secs="$(grep '^time:' <<<"$line" | sed -E 's/.*streets ([0-9.]+).*/\1/')"
    read -r j s b <<<"$counts"
    printf '%-6s %-5s %10s %10s %8s %8s %12s\n' "$n" "$seed" "$j" "$s" "$b" \
      "$(( (n + 1) * (n + 1) ))/$(( 2 * n * (n + 1) ))/$(( n * n ))" "$secs"
    lo=$(( -n * 55 - 15 )); hi=$(( lo + 335 ))
    /usr/bin/python3 "$here/plot_road_centrelines.py" "$base.gml" "$base.streets.json" "$base.georef.json" \
      "$base.png" --window="$lo,$lo,$hi,$hi" --title "corner of the $n x $n grid, seed $seed: $j junctions"
    rm -f "$base.glb"
  done
done
