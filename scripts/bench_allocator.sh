#!/usr/bin/env bash
# The cost of glibc's default malloc in timed runs (core/allocator.h): the same `farfield bench` with
#   default  glibc's defaults (FF_ALLOCATOR=default: farfield leaves malloc alone; no GLIBC_TUNABLES)
#   tunables glibc's defaults replaced by GLIBC_TUNABLES (trim threshold 4 GiB - 1, mmap threshold 32 MiB,
#            top pad 256 MiB), farfield still leaving malloc alone
#   builtin  what every timed command does by itself: the same settings through mallopt (no environment)
# and the median frame time of each mode in each, with the ratios default/tunables and default/builtin. A benchmark,
# not a test: it asserts nothing. REPEATS=N runs the three N times, in turn (drift hits them alike), and reports the
# median over the runs.
#
# Usage: scripts/bench_allocator.sh SCENE PATH [OUT] [-- extra farfield bench arguments]
#   FARFIELD (default build/release/bin/farfield), MODES (default culled), SIZE (default 640x360), FRAMES (0 = all),
#   REPEATS (default 1).
# Example: scripts/bench_allocator.sh out/demo/city.glb out/demo/path.json /tmp/alloc -- --stride 2
set -euo pipefail
if [ $# -lt 2 ]; then
  sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
SCENE=$1
CAMERA_PATH=$2
shift 2
OUT=out/bench_allocator
if [ $# -gt 0 ] && [ "$1" != "--" ]; then
  OUT=$1
  shift
fi
if [ "${1:-}" = "--" ]; then shift; fi
FARFIELD=${FARFIELD:-build/release/bin/farfield}
MODES=${MODES:-culled}
SIZE=${SIZE:-640x360}
FRAMES=${FRAMES:-0}
REPEATS=${REPEATS:-1}
TUNABLES="glibc.malloc.trim_threshold=4294967295:glibc.malloc.mmap_threshold=33554432:glibc.malloc.top_pad=268435456"
mkdir -p "$OUT"

run() {  # run NAME REPEAT [extra bench arguments]: one bench into OUT/NAME.REPEAT
  local name=$1 repeat=$2 dir="$OUT/$1.$2"
  shift 2
  local -a env_args=(env -u GLIBC_TUNABLES)
  case $name in
    default) env_args+=(FF_ALLOCATOR=default) ;;
    tunables) env_args+=(FF_ALLOCATOR=default "GLIBC_TUNABLES=$TUNABLES") ;;
    builtin) env_args+=(-u FF_ALLOCATOR) ;;
  esac
  echo "== $name (run $repeat of $REPEATS)"
  FF_PROGRESS=0 "${env_args[@]}" "$FARFIELD" bench "$SCENE" --path "$CAMERA_PATH" --modes "$MODES" --size "$SIZE" \
    --frames "$FRAMES" --samples 0 --no-plots -o "$dir" "$@" | grep -E '^(malloc|frames):'
}

for ((r = 1; r <= REPEATS; r++)); do
  for name in default tunables builtin; do run "$name" "$r" "$@"; done
done

python3 - "$OUT" "$REPEATS" <<'PY'
import json, os, statistics, sys
out, repeats = sys.argv[1], int(sys.argv[2])
configs = ["default", "tunables", "builtin"]
medians = {}  # (config, mode) -> [median_ms per run]
allocator = {}
for c in configs:
    for r in range(1, repeats + 1):
        with open(os.path.join(out, "%s.%d" % (c, r), "bench.json")) as f:
            j = json.load(f)
        allocator[c] = j.get("allocator", {}).get("description", "?")
        for mode, m in j["modes"].items():
            medians.setdefault((c, mode), []).append(m["median_ms"])
modes = sorted({mode for _, mode in medians}, key=lambda m: (m != "full", m))
print()
for c in configs:
    print("%-8s allocator: %s" % (c, allocator[c]))
print()
print("%-16s %14s %14s %14s %18s %18s" % ("mode", "default ms", "tunables ms", "builtin ms", "default/tunables",
                                          "default/builtin"))
summary = {}
for mode in modes:
    v = {c: statistics.median(medians[(c, mode)]) for c in configs}
    print("%-16s %14.2f %14.2f %14.2f %17.2fx %17.2fx" % (mode, v["default"], v["tunables"], v["builtin"],
                                                          v["default"] / v["tunables"], v["default"] / v["builtin"]))
    summary[mode] = {"median_ms": v, "runs_ms": {c: medians[(c, mode)] for c in configs},
                     "default_over_tunables": v["default"] / v["tunables"],
                     "default_over_builtin": v["default"] / v["builtin"]}
with open(os.path.join(out, "bench_allocator.json"), "w") as f:
    json.dump({"repeats": repeats, "allocator": allocator, "modes": summary}, f, indent=2)
print("\nwrote %s" % os.path.join(out, "bench_allocator.json"))
PY
