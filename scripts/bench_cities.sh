#!/usr/bin/env bash
# Figures for docs/BENCHMARKS.md: procedural cities of several sizes (detail 1), generation cost, and full vs culled
# median frame time on a 300-frame street walk at 512x512 with full-geometry reference frames.
# Usage: scripts/bench_cities.sh [FARFIELD] [OUT] [BLOCKS...]
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/bench/cities}
shift 2 || true
SIZES=("$@")
[ ${#SIZES[@]} -gt 0 ] || SIZES=(100 1000 10000)
mkdir -p "$OUT"
table="$OUT/cities.md"
{
  echo "| blocks | objects | triangles | geometry MiB | gen s | peak MiB (gen + .glb) | full median ms | culled median ms | culled speedup | culled tris |"
  echo "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
} > "$table"
for n in "${SIZES[@]}"; do
  d="$OUT/city$n"; mkdir -p "$d"
  "$FARFIELD" gen city --blocks "$n" --detail 1 --seed 1 -o "$d/city.glb" > "$d/gen.txt"
  "$FARFIELD" path street "$d/city.streets.json" --frames 300 --seed 1 -o "$d/path.json" > "$d/path.txt"
  "$FARFIELD" bench "$d/city.glb" --path "$d/path.json" --modes full,culled --reference --size 512x512 -o "$d/bench" > "$d/bench.txt"
  python3 - "$d" "$n" >> "$table" <<'PY'
import json, re, sys
d, n = sys.argv[1], sys.argv[2]
gen = open(f"{d}/gen.txt").read()
def grab(key):
    m = re.search(rf"^{key}:\s+([0-9.]+)", gen, re.M)
    return m.group(1) if m else "?"
mem = re.search(r"memory:\s+([0-9.]+) MiB", gen)
t = re.search(r"time:\s+([0-9.]+) s generation", gen)
b = json.load(open(f"{d}/bench/bench.json"))["modes"]
f, c = b["full"], b["culled"]
print(f"| {n} | {grab('objects')} | {grab('triangles')} | {grab('geometry')} | {t.group(1) if t else '?'} | "
      f"{mem.group(1) if mem else '?'} | {f['median_ms']:.1f} | {c['median_ms']:.1f} | {c['speedup_vs_full']:.2f}x | "
      f"{c['mean_triangles']:.0f} |")
PY
  echo "bench_cities: $n blocks done" >&2
done
cat "$table"
