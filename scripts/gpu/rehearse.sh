#!/usr/bin/env bash
# The GPU machine's run rehearsed on this machine (llvmpipe), before a session that is lent a GPU spends its 15
# minutes on it: `make dist`'s tarball in .gpu/ (as the device tool carries it), the shared DEM and models in
# .gpu/data/ when ../shared/data has them, libglvnd's packages in .gl/ (downloaded once), and
# scripts/gpu/run-gpu-frame.sh with REHEARSE=1 (toy sizes; no libglvnd unpacked). Prints each stage's return codes and
# fails if any is not 0, if a device call carrying .gpu and .gl would send more than the device's 64 MiB, or if OUT
# holds more files than the device returns (8 of 16 MiB).
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
  PROJ_GRIDS=0 EXTRA_BINS="$extra" bash scripts/make_dist.sh "$BIN" .gpu > "$OUTD/dist.txt" 2>&1 ||
    { cat "$OUTD/dist.txt"; exit 1; }
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
# libglvnd's packages for the GPU machine, which has no GL dispatch libraries (the device tool's README).
grep -qx '/.gl/' .git/info/exclude 2>/dev/null || echo '/.gl/' >> .git/info/exclude
if [ "$(ls .gl/*.deb 2>/dev/null | wc -l)" -lt 7 ]; then
  mkdir -p .gl /tmp/amd64/partial
  o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
  # shellcheck disable=SC2086  # $o is a list of options
  { apt-get $o update && (cd .gl && apt-get $o download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 \
    libgles2); } > "$OUTD/gl-debs.txt" 2>&1 ||
    echo "warning: libglvnd's packages not downloaded into .gl/ ($OUTD/gl-debs.txt)"
fi
# What a device call sends: the tracked files, the untracked ones git does not ignore, and the carried .gpu and .gl;
# the device refuses more than 64 MiB.
sent=$( { git ls-files -z; git ls-files -z --others --exclude-standard; } | xargs -0 -r stat -c %s 2>/dev/null |
  awk '{s += $1} END {print s + 0}')
carried=$(du -sb .gpu .gl 2>/dev/null | awk '{s += $1} END {print s + 0}')
mib=$(awk -v b=$((sent + carried)) 'BEGIN {printf "%.1f", b / 1048576}')
echo "a device call with carry [.gpu, .gl] sends $mib MiB (repository $((sent / 1048576)) MiB, .gpu and .gl" \
  "$((carried / 1048576)) MiB; the limit is 64 MiB)" | tee "$OUTD/travel.txt"
[ $((sent + carried)) -le $((64 * 1048576)) ] || { echo "rehearse: over the device's 64 MiB" >&2; exit 1; }
REHEARSE=1 SKIP_GL=1 OUT="$OUTD" STAGES="$STAGES" bash scripts/gpu/run-gpu-frame.sh > /dev/null 2>&1
echo "rehearsal of: $STAGES (log: $OUTD/log.txt)"
grep -E "^== |^rc " "$OUTD/log.txt"
grep -E " unreadable " "$OUTD/log.txt" | sed 's/^/warning: /'  # a bench.json a stage did not write
cat "$OUTD"/results.tar* 2>/dev/null | tar -tf - 2>/dev/null | grep '\.tgz$' | sed 's/^/kept: /'
# The device returns at most 8 files of OUT, each of at most 16 MiB.
n=$(find "$OUTD" -maxdepth 1 -type f \( -name 'results.tar*' -o -name log.txt \) | wc -l)
big=$(find "$OUTD" -maxdepth 1 -type f \( -name 'results.tar*' -o -name log.txt \) -size +16M | wc -l)
[ "$n" -le 8 ] && [ "$big" -eq 0 ] ||
  { echo "rehearse: $n files in OUT, $big over 16 MiB: the device returns 8 of 16 MiB" >&2; exit 1; }
bad=$(grep -cE "^rc [1-9]|SMOKE FAILED" "$OUTD/log.txt")
[ "$bad" -eq 0 ] || { echo "rehearse: $bad command(s) failed" >&2; exit 1; }
echo "rehearse: every command returned 0"
