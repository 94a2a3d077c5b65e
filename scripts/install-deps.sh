#!/usr/bin/env bash
# Installs every Debian package Farfield's build, tests, benchmarks and demo need.
# Idempotent: packages already present are skipped; apt-get runs only when something is missing.
# Uses sudo when not run as root.
set -euo pipefail

packages=(
  # toolchain
  cmake g++ make pkg-config
  # math, GL, windowing, UI
  libglm-dev libepoxy-dev libegl-dev libgl-dev libgl1-mesa-dri libegl-mesa0 libglfw3-dev libimgui-dev xvfb xauth
  # import / export / formats
  libassimp-dev libtinygltf-dev nlohmann-json3-dev libstb-dev libpng-dev libzstd-dev
  # geometry, GIS
  libcgal-dev libgmp-dev libmpfr-dev libmeshoptimizer-dev libgdal-dev libosmium2-dev libproj-dev libexpat1-dev libbz2-dev zlib1g-dev
  # CLI, threads, tests, benchmarks, plots
  libcli11-dev libtbb-dev libgtest-dev libgmock-dev libbenchmark-dev python3 python3-matplotlib python3-numpy
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then sudo="sudo"; else
    echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1
  fi
fi

echo "install-deps: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
