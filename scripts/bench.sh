#!/usr/bin/env bash
# `make bench`: the benchmarks behind docs/BENCHMARKS.md. BIN is the build's bin directory, OUT the output folder.
# FF_BENCH_CITIES="100 1000 10000" sets the city sizes (the 10,000-block city needs about 3 GB and a few minutes).
set -euo pipefail
BIN=${1:-build/release/bin}
OUT=${2:-out/bench}
mkdir -p "$OUT"
echo "== renderer throughput (bench_renderer)"
"$BIN/bench_renderer" --benchmark_min_time=1 --benchmark_out="$OUT/bench_renderer.json" --benchmark_out_format=json
echo "== a paged terrain's page texels (bench_terrain_texture)"
"$BIN/bench_terrain_texture" --benchmark_min_time=1 --benchmark_out="$OUT/bench_terrain_texture.json" \
  --benchmark_out_format=json
echo "== procedural cities, full vs culled"
# shellcheck disable=SC2086
bash "$(dirname "$0")/bench_cities.sh" "$BIN/farfield" "$OUT/cities" ${FF_BENCH_CITIES:-100 1000}
