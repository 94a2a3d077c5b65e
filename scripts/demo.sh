#!/usr/bin/env bash
# The main job on the built-in default scene: render it and write a short report to OUT.
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/demo}
mkdir -p "$OUT"
"$FARFIELD" info builtin:cubes | tee "$OUT/info.txt"
"$FARFIELD" render builtin:cubes --eye 18,-22,14 --at 0,0,1 --fov 55 --size 800x600 \
  -o "$OUT/frame.png" --depth "$OUT/depth.pfm" --ids "$OUT/ids.png" | tee "$OUT/render.txt"
{
  echo "# Farfield demo"
  echo
  echo "Scene \`builtin:cubes\` rendered headless."
  echo
  echo '```'; cat "$OUT/info.txt"; cat "$OUT/render.txt"; echo '```'
  echo
  echo "![frame](frame.png) ![ids](ids.png)"
} > "$OUT/report.md"
echo "demo: report written to $OUT/report.md"
