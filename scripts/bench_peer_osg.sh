#!/usr/bin/env bash
# Farfield beside a peer: the same city along the same path at the same size drawn by OpenSceneGraph 3.6 (Debian's
# libopenscenegraph-dev; bench/osg_peer: per-object transforms, OSG's per-drawable view-frustum culling, a shader of
# the same cost as Farfield's), with and without osgSim::Impostor, then by Farfield's frustum, culled-cpu and culled
# (the GPU-driven frame) modes; one table of milliseconds per frame (docs/BENCHMARKS.md, "The GPU-driven frame").
#
#   scripts/bench_peer_osg.sh [FARFIELD] [OUT] [SCENE PATH]
#
# Without SCENE and PATH it makes the demo's city and drive of before 2026-12-05 (400 blocks, detail 2, seed 1). Environment: SIZE
# (640x360), STRIDE (5), IMPOSTORS ("100:4 200:8": osgSim::Impostor threshold in metres and pixel error),
# OSG_BUILD (build/osg-peer: where the peer is built), PEER (a peer built already, e.g. from a tarball of
# scripts/make_dist.sh with EXTRA_BINS: nothing is installed or built), PEER_GL (glx: a GLX window of the display, under
# xvfb-run where there is none; egl: an EGL pbuffer, no X server, the GPU machine's way; auto, the default: glx with a
# display, else egl). The last frame of each peer run is saved next to the table (osg-last.png, ...) as evidence of
# what it drew.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
FARFIELD=$(readlink -f "${1:-$here/build/release/bin/farfield}")
OUT=$(readlink -m "${2:-$here/out/bench/peer-osg}")
SCENE=${3:-}
PATHFILE=${4:-}
SIZE=${SIZE:-640x360}
STRIDE=${STRIDE:-5}
IMPOSTORS=${IMPOSTORS:-"100:4 200:8"}
OSG_BUILD=${OSG_BUILD:-$here/build/osg-peer}
PEER_GL=${PEER_GL:-auto}
mkdir -p "$OUT"
export FF_PROGRESS=0

[ -n "${PEER:-}" ] || PEER=$(bash "$here/scripts/build_osg_peer.sh" "$OSG_BUILD" "$OUT")
[ -x "$PEER" ] || { echo "bench_peer_osg: no peer $PEER" >&2; exit 2; }

if [ -z "$SCENE" ]; then
  SCENE=$OUT/city.glb
  PATHFILE=$OUT/path.json
  [ -f "$SCENE" ] || "$FARFIELD" gen city --blocks 400 --detail 2 --seed 1 --objects buildings -o "$SCENE" > "$OUT/gen.txt"
  [ -f "$PATHFILE" ] || "$FARFIELD" path street "$OUT/city.streets.json" --frames 300 --seed 1 --car --fov 60 \
    -o "$PATHFILE" > /dev/null
fi
[ "$PEER_GL" != auto ] || { PEER_GL=egl; [ -z "${DISPLAY:-}" ] || PEER_GL=glx; }
xvfb=()
# GLX: a window of the display (Mesa's GLX pbuffers answer its frame copies with X errors on Xvfb). EGL: a pbuffer.
surface=(--egl)
if [ "$PEER_GL" = glx ]; then
  surface=(--window)
  if [ -z "${DISPLAY:-}" ]; then
    command -v xvfb-run > /dev/null || { echo "bench_peer_osg: no display and no xvfb-run" >&2; exit 2; }
    xvfb=(xvfb-run -a -s "-screen 0 1280x1024x24")
  fi
fi

# The last frame of each run saved.
"${xvfb[@]}" "$PEER" "$SCENE" "$PATHFILE" --size "$SIZE" --stride "$STRIDE" --mode full --tag osg "${surface[@]}" \
  --csv "$OUT/osg.csv" --screenshot "$OUT/osg-last.png" > "$OUT/osg.txt" 2>&1 ||
  echo "bench_peer_osg: the peer failed (osg.txt)" >&2
for imp in $IMPOSTORS; do
  threshold=${imp%%:*} pixels=${imp##*:}
  "${xvfb[@]}" "$PEER" "$SCENE" "$PATHFILE" --size "$SIZE" --stride "$STRIDE" --mode impostor --threshold "$threshold" \
    --pixel-error "$pixels" --tag "osg-impostor-$threshold-$pixels" "${surface[@]}" \
    --screenshot "$OUT/osg-impostor-$threshold-$pixels-last.png" > "$OUT/osg-impostor-$threshold-$pixels.txt" 2>&1 ||
    echo "bench_peer_osg: the peer failed (osg-impostor-$threshold-$pixels.txt)" >&2
done
"$FARFIELD" bench "$SCENE" --path "$PATHFILE" --modes frustum,culled-cpu,culled --size "$SIZE" --stride "$STRIDE" \
  -o "$OUT/farfield" > "$OUT/farfield.txt" 2>&1

python3 - "$OUT" > "$OUT/peer.md" <<'PY'
import glob, json, re, sys
out = sys.argv[1]
print("| renderer | mode | frames | median ms | p95 ms | p99 ms | max ms | first ms |")
print("|---|---|---:|---:|---:|---:|---:|---:|")
for f in sorted(glob.glob(f"{out}/osg*.txt")):
    text = open(f).read()
    gl = re.search(r"GL_RENDERER=(.*?) GL_VERSION", text)
    via = re.search(r"GL_VERSION=.* via (.*)", text)  # the surface: GLX, or the EGL display of the pbuffer
    r = re.search(r"RESULT (.*)", text)
    if not r:
        print(f"| OpenSceneGraph | {f} | failed | | | | | |")
        continue
    v = dict(kv.split("=", 1) for kv in r.group(1).split())
    surface = f", {via.group(1)}" if via else ""
    print(f"| OpenSceneGraph 3.6 ({gl.group(1) if gl else '?'}{surface}) | {v['tag']} | {v['frames']} | {float(v['median']):.2f} | "
          f"{float(v['p95']):.2f} | {float(v['p99']):.2f} | {float(v['max']):.2f} | {float(v['first']):.2f} |")
b = json.load(open(f"{out}/farfield/bench.json"))
for name, m in b["modes"].items():
    print(f"| Farfield ({b['renderer'].split(' / ')[0]}) | {name} | {b['frames']} | {m['median_ms']:.2f} | {m['p95_ms']:.2f} | "
          f"{m['p99_ms']:.2f} | {m['max_ms']:.2f} | |")
PY
cat "$OUT/peer.md"
