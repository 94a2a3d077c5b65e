#!/usr/bin/env bash
# The walkthrough streaming its impostor database under memory budgets (docs/BENCHMARKS.md, "Whole cities: shards,
# resume, streaming"): one mode along one path per budget, the per-frame streaming log (stalls, resident bytes) and
# frame times, summarised in OUT/summary.txt.
#
#   scripts/bench_streaming.sh SCENE PATH.json DATABASE OUT [MODE] [BUDGETS_MB...]
#
# A budget of 0 is the walk with everything resident (no budget: gpu_budget_mb=1000000, read-ahead on). FARFIELD
# names the binary (default build/release/bin/farfield), SIZE the frame size (default 640x360).
set -euo pipefail
scene=$1 path=$2 db=$3 out=$4 mode=${5:-mmi}
shift 5 || shift $#
budgets=("$@")
[ ${#budgets[@]} -gt 0 ] || budgets=(0 256)
farfield=${FARFIELD:-$(dirname "$0")/../build/release/bin/farfield}
size=${SIZE:-640x360}
mkdir -p "$out"
export FF_PROGRESS=0
for b in "${budgets[@]}"; do
  if [ "$b" = 0 ]; then option=(--mode-option gpu_budget_mb=1000000); else option=(--memory-budget "$b"); fi
  /usr/bin/time -f "%e s, %M kB" -o "$out/walk-$b.time" "$farfield" walk "$scene" --path "$path" --mode "$mode" --size "$size" --mode-option impostor_dir="$db" "${option[@]}" \
    --mode-option streaming_csv="$out/streaming-$b.csv" --csv "$out/frames-$b.csv" > "$out/walk-$b.txt"
done
python3 - "$out" "${budgets[@]}" <<'PY' | tee "$out/summary.txt"
import csv, statistics, sys
out, budgets = sys.argv[1], sys.argv[2:]
print(f"{'budget MB':>10} {'frames':>6} {'entries':>7} {'stalls':>6} {'stall ms max':>12} {'resident MB max':>15} "
      f"{'mean':>6} {'read-ahead MB max':>17} {'wall ms median':>14} {'p95':>6} {'max':>6} {'stall-frame ms mean':>19}")
for b in budgets:
    s = list(csv.DictReader(open(f"{out}/streaming-{b}.csv")))
    f = list(csv.DictReader(open(f"{out}/frames-{b}.csv")))
    # the walk's warm-up frame is untimed: align the streaming rows to the timed frames from the end
    s = s[-len(f):]
    wall = [float(r["wall_ms"]) for r in f]
    stall_wall = [float(fr["wall_ms"]) for fr, sr in zip(f, s) if sr["stall"] == "1"]
    res = [int(r["resident_bytes"]) / 2**20 for r in s]
    ahead = [int(r["read_ahead_bytes"]) / 2**20 for r in s]
    q = statistics.quantiles(wall, n=100)
    print(f"{('all' if b == '0' else b):>10} {len(f):>6} {sum(1 for r in s if r['read']):>7} "
          f"{sum(1 for r in s if r['stall'] == '1'):>6} {max([float(r['load_ms']) for r in s if r['stall'] == '1'] or [0]):>12.1f} "
          f"{max(res):>15.1f} {statistics.mean(res):>6.1f} {max(ahead):>17.1f} {statistics.median(wall):>14.2f} "
          f"{q[94]:>6.1f} {max(wall):>6.1f} {(statistics.mean(stall_wall) if stall_wall else 0):>19.1f}")
PY
