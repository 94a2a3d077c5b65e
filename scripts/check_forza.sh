#!/usr/bin/env bash
# Real data check: the TORCS track "forza" (Monza) from Debian's torcs-data package, an AC3D model of about 3,900
# objects and 130 textures. Installs torcs-data when it is absent (a 333 MB download, so not part of
# scripts/install-deps.sh; apt-get, through sudo when not root), imports the track with `farfield info` (which prints
# the import's warnings: textures missing or unreadable, drawn as checkerboards, faces skipped, AC3D objects with
# several textures), and renders an overview and a view along the track with `farfield render`.
# Writes OUT/info.txt, OUT/forza.png (the overview), OUT/forza_track.png and OUT/render.txt.
# Usage: scripts/check_forza.sh [FARFIELD] [OUT]   (defaults: build/release/bin/farfield, out/forza)
set -euo pipefail
FARFIELD=${1:-build/release/bin/farfield}
OUT=${2:-out/forza}
TRACKS=/usr/share/games/torcs/tracks

find_track() { find "$TRACKS" -path '*/forza/*' \( -name '*.ac' -o -name '*.acc' \) 2>/dev/null | head -n 1; }

track=$(find_track || true)
if [ -z "$track" ]; then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then sudo="sudo"; else
      echo "check_forza: need root or sudo to install torcs-data" >&2; exit 1
    fi
  fi
  echo "check_forza: installing torcs-data (about 333 MB)"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends torcs-data >/dev/null
  track=$(find_track || true)
fi
if [ -z "$track" ]; then
  echo "check_forza: no forza .ac/.acc file under $TRACKS after installing torcs-data" >&2
  exit 1
fi
if [ ! -x "$FARFIELD" ]; then
  echo "check_forza: $FARFIELD not built (make build-cli)" >&2
  exit 1
fi
mkdir -p "$OUT"

echo "== import $track"
"$FARFIELD" info "$track" | tee "$OUT/info.txt"

# Cameras from the scene bounds: an overview from high above the south side of the track, and a view from 60 m above
# the north-west part of the track (its main straight, pits and grandstands in the Debian package's model) looking
# west along it.
read -r lx ly lz hx hy hz < <(sed -n 's/^bounds: *\[\(.*\), \(.*\), \(.*\)\] \.\. \[\(.*\), \(.*\), \(.*\)\] m$/\1 \2 \3 \4 \5 \6/p' "$OUT/info.txt")
cams=$(python3 - "$lx" "$ly" "$lz" "$hx" "$hy" "$hz" <<'EOF'
import sys
lx, ly, lz, hx, hy, hz = map(float, sys.argv[1:])
cx, cy = (lx + hx) / 2, (ly + hy) / 2
size = max(hx - lx, hy - ly)
overview = f"{cx:.1f},{ly - 0.35 * size:.1f},{lz + 0.75 * size:.1f} {cx:.1f},{cy:.1f},{lz:.1f}"
w, h = hx - lx, hy - ly
track = f"{lx + 0.437 * w:.1f},{ly + 0.906 * h:.1f},{lz + 63:.1f} {lx + 0.234 * w:.1f},{ly + 0.852 * h:.1f},{lz + 3:.1f}"
print(overview, track)
EOF
)
read -r eye at eye2 at2 <<< "$cams"
echo "== render the overview (eye $eye, at $at)"
"$FARFIELD" render "$track" --eye "$eye" --at "$at" --fov 50 --size 1280x720 --far 20000 -o "$OUT/forza.png" | tee "$OUT/render.txt"
echo "== render along the track (eye $eye2, at $at2)"
"$FARFIELD" render "$track" --eye "$eye2" --at "$at2" --fov 60 --size 1280x720 -o "$OUT/forza_track.png" | tee -a "$OUT/render.txt"
echo "wrote $OUT/info.txt, $OUT/forza.png, $OUT/forza_track.png, $OUT/render.txt"
