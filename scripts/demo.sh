#!/usr/bin/env bash
# The main job on the built-in default scene: generate the default city (400 blocks, facade detail 2: about 5.7M
# triangles, so that full geometry takes roughly 100-300 ms a frame on llvmpipe), a 300-frame street drive, and the
# walkthrough benchmark of full geometry against view-frustum culling with full-geometry reference frames.
# Writes OUT/report.md with the table, the plots and sample frames.
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/demo}
BLOCKS=${FF_DEMO_BLOCKS:-400}
DETAIL=${FF_DEMO_DETAIL:-2}
FRAMES=${FF_DEMO_FRAMES:-300}
mkdir -p "$OUT"
start=$(date +%s)

echo "== farfield gen city (blocks $BLOCKS, detail $DETAIL)"
"$FARFIELD" gen city --blocks "$BLOCKS" --detail "$DETAIL" --seed 1 -o "$OUT/city.glb" | tee "$OUT/gen.txt"
echo "== farfield path street ($FRAMES frames)"
"$FARFIELD" path street "$OUT/city.streets.json" --frames "$FRAMES" --seed 1 --car -o "$OUT/path.json" | tee "$OUT/path.txt"
echo "== farfield bench full,culled --reference"
"$FARFIELD" bench "$OUT/city.glb" --path "$OUT/path.json" --modes full,culled --reference --size 512x512 \
  -o "$OUT" --report "$OUT/bench_report.md" | tee "$OUT/bench.txt"

{
  echo "# Farfield demo: the default city"
  echo
  echo "Generated with \`farfield gen city --blocks $BLOCKS --detail $DETAIL --seed 1\`, walked with"
  echo "\`farfield path street --frames $FRAMES --car\`, measured with \`farfield bench --modes full,culled --reference\`"
  echo "on $(date -u +%Y-%m-%d) ($(( $(date +%s) - start )) s for the whole job)."
  echo
  echo '```'; cat "$OUT/gen.txt"; echo '```'
  echo
  cat "$OUT/bench_report.md"
} > "$OUT/report.md"
echo "demo: report written to $OUT/report.md"
