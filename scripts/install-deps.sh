#!/usr/bin/env bash
# Installs every Debian package Farfield's build, tests, benchmarks and demo need.
# Idempotent: packages already present are skipped; apt-get runs only when something is missing.
# Uses sudo when not run as root.
set -euo pipefail

packages=(
  # toolchain (clang and its compiler-rt: the libFuzzer targets of `make fuzz`)
  cmake g++ make pkg-config clang libclang-rt-14-dev
  # math, GL, windowing, UI
  libglm-dev libepoxy-dev libegl-dev libgl-dev libgl1-mesa-dri libegl-mesa0 libglfw3-dev libimgui-dev xvfb xauth
  # import / export / formats
  libassimp-dev libtinygltf-dev nlohmann-json3-dev libstb-dev libpng-dev libzstd-dev libxxhash-dev
  # geometry, GIS
  libcgal-dev libgmp-dev libmpfr-dev libmeshoptimizer-dev libgdal-dev libosmium2-dev libproj-dev libexpat1-dev libbz2-dev zlib1g-dev
  libcitygml-dev
  # CLI, threads, tests, benchmarks, plots
  libcli11-dev libtbb-dev libgtest-dev libgmock-dev libbenchmark-dev python3 python3-matplotlib python3-numpy
  # a second GLSL compiler over the programs the tests link (the Khronos reference front end: scripts/check_shaders.sh)
  glslang-tools
  # sharded bakes: a one-node Slurm for the tests and benchmarks (scripts/slurm/local-cluster.sh)
  slurm-wlm munge
  # the release tarball of `make dist` (scripts/make_dist.sh): RUNPATHs of the tool and its bundled libraries, and the
  # X11 extensions GLFW opens with dlopen for `farfield view` (bundled too: ldd does not list them)
  patchelf libxcursor1 libxrandr2 libxinerama1 libxi6 libxxf86vm1
)

# node and npm run the Khronos glTF validator in the tests (npm only for tools that exist nowhere else); a node
# already installed (with its npm) is kept.
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then packages+=(nodejs npm); fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# The glTF validator, at the version pinned by tools/gltf-validator/package-lock.json, into that folder's
# node_modules (git-ignored; the only network use outside apt-get; never at build time).
install_gltf_validator() {
  local dir
  dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/tools/gltf-validator"
  if [ -f "$dir/node_modules/gltf-validator/package.json" ] &&
     [ "$(node -p "require('$dir/node_modules/gltf-validator/package.json').version")" = \
       "$(node -p "require('$dir/package-lock.json').packages['node_modules/gltf-validator'].version")" ]; then
    return
  fi
  echo "install-deps: installing the glTF validator (npm ci in $dir)"
  (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
}

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  install_gltf_validator
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
install_gltf_validator
echo "install-deps: done"
