#!/usr/bin/env bash
# The GPU machine's run rehearsed on this machine (llvmpipe), before a session that is lent a GPU spends its 15
# minutes on it: `make dist`'s tarball in .gpu/ (as the device tool carries it), the shared DEM and models in
# .gpu/data/ when ../shared/data has them, and scripts/gpu/run-gpu-frame.sh with REHEARSE=1 (toy sizes; no libglvnd
# unpacked). Prints each stage's return codes and fails if any is not 0.
#   scripts/gpu/rehearse.sh [OUT_DIR] [STAGES]     (defaults: out/rehearse; every stage of run-gpu-frame.sh)
# With OSG_PEER=1 the OpenSceneGraph peer is built (scripts/build_osg_peer.sh) and put in the tarball's bin/ for the
# osg stage.
set -uo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
OUTD=$(realpath -m "${1:-$ROOT/out/rehearse}")
STAGES=${2:-smoke heldout model big demo check osg terrain paged crowd makedemo dynamic stream}
cd "$ROOT" || exit 1
BIN=build/release/bin/farfield
[ -x "$BIN" ] || { echo "rehearse: no $BIN (make build)" >&2; exit 1; }
rm -rf "$OUTD" && mkdir -p "$OUTD"
mkdir -p .gpu
extra=""
if [ -n "${OSG_PEER:-}" ]; then
  extra=$(bash scripts/build_osg_peer.sh build/osg-peer "$OUTD/peer-build") ||
    { echo "rehearse: the OpenSceneGraph peer did not build ($OUTD/peer-build)" >&2; exit 1; }
fi
tarball=$(ls .gpu/farfield-*.tar.xz 2>/dev/null | head -1)
# xz takes minutes: made again only for a newer build, or when the peer is wanted and missing or newer.
if [ -z "$tarball" ] || [ "$BIN" -nt "$tarball" ] ||
  { [ -n "$extra" ] && { [ "$extra" -nt "$tarball" ] || ! tar -tJf "$tarball" | grep -q /bin/osg_peer; }; }; then
  rm -f .gpu/farfield-*.tar.xz
  EXTRA_BINS="$extra" bash scripts/make_dist.sh "$BIN" .gpu > "$OUTD/dist.txt" 2>&1 || { cat "$OUTD/dist.txt"; exit 1; }
fi
dem=$ROOT/../shared/data/terrain/bigtujunga_srtm30m_utm11.tif
if [ -f "$dem" ]; then
  mkdir -p .gpu/data/terrain
  cp -f "$dem" .gpu/data/terrain/
fi
models=$ROOT/../shared/data/models
if [ -f "$models/CesiumMan.glb" ] && [ -f "$models/Fox.glb" ]; then
  mkdir -p .gpu/data/models
  cp -f "$models/CesiumMan.glb" "$models/Fox.glb" .gpu/data/models/
fi
grep -qx '.gpu/' .git/info/exclude 2>/dev/null || { mkdir -p .git/info; echo '.gpu/' >> .git/info/exclude; }
REHEARSE=1 SKIP_GL=1 OUT="$OUTD" STAGES="$STAGES" bash scripts/gpu/run-gpu-frame.sh > /dev/null 2>&1
echo "rehearsal of: $STAGES (log: $OUTD/log.txt)"
grep -E "^== |^rc " "$OUTD/log.txt"
grep -E " unreadable " "$OUTD/log.txt" | sed 's/^/warning: /'  # a bench.json a stage did not write
ls "$OUTD"/*.tgz 2>/dev/null | sed 's/^/kept: /'
bad=$(grep -cE "^rc [1-9]|SMOKE FAILED" "$OUTD/log.txt")
[ "$bad" -eq 0 ] || { echo "rehearse: $bad command(s) failed" >&2; exit 1; }
echo "rehearse: every command returned 0"
