#!/usr/bin/env bash
# Builds the OpenSceneGraph peer (bench/osg_peer) and prints the path of its executable; installs Debian's
# libopenscenegraph-dev first where it is missing (the project does not install it by default). Used by
# scripts/bench_peer_osg.sh and scripts/gpu/rehearse.sh (OSG_PEER=1).
#   scripts/build_osg_peer.sh [BUILD_DIR] [LOG_DIR]      (defaults: build/osg-peer; the logs in BUILD_DIR)
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
build=$(readlink -m "${1:-$here/build/osg-peer}")
logs=$(readlink -m "${2:-$build}")
mkdir -p "$logs"
if ! dpkg-query -W -f='${Status}' libopenscenegraph-dev 2>/dev/null | grep -q "install ok installed"; then
  echo "build_osg_peer: installing libopenscenegraph-dev (apt-get)" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo=sudo
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -q libopenscenegraph-dev > "$logs/apt.txt"
fi
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release -DFF_BUILD_TESTS=OFF -DFF_BUILD_BENCH=OFF \
  -DFF_BUILD_OSG_PEER=ON > "$logs/cmake.txt"
cmake --build "$build" -j "$(nproc)" --target osg_peer > "$logs/build.txt"
echo "$build/bin/osg_peer"
