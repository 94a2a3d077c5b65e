#!/usr/bin/env bash
# Release tarball for a machine without Debian's development packages (a bare GPU node): `make dist`, or
#   scripts/make_dist.sh BINARY [OUT_DIR]        (OUT_DIR defaults to out/dist)
# writes OUT_DIR/farfield-<version>-linux-x86_64.tar.xz holding farfield-<version>/
#   bin/farfield                the stripped tool, RUNPATH $ORIGIN/../lib
#   lib/                        every shared library ldd lists for it, and the X11 extensions GLFW opens with dlopen
#                               (with theirs), under its SONAME, each with RUNPATH $ORIGIN (so that the libraries' own
#                               dependencies come from lib/ too, not only the tool's), except glibc's, libstdc++,
#                               libgcc_s and the GL dispatch libraries that a GPU driver provides
#   share/proj, share/gdal      PROJ's proj.db and GDAL's data; the tool points PROJ_DATA/PROJ_LIB and GDAL_DATA at them
#                               when they are unset (apps/farfield/main.cpp). PROJ_GRIDS=0 leaves out PROJ's datum-shift
#                               and geoid grids (*.gsb, *.gtx, *.tif: 5 MB of the tarball), which no benchmark needs:
#                               the GPU machine's bundle, whose working tree must stay under the device's 64 MiB
#   share/farfield/             tools/plot_bench.py, tools/plot_terrain.py, README.md
#   share/doc/PACKAGE/copyright of every bundled library's Debian package
# The target machine needs glibc, libstdc++ and libglvnd (libEGL, libOpenGL) of at least Debian 12's versions and an
# EGL driver. Needs patchelf (scripts/install-deps.sh). scripts/check_dist.sh proves a tarball on a minimal Debian 12.
# EXTRA_BINS (space-separated executables, e.g. the OpenSceneGraph peer build/osg-peer/bin/osg_peer) go into bin/ beside
# the tool, their libraries into lib/ likewise (scripts/gpu/rehearse.sh with OSG_PEER=1: the peer on a GPU machine).
set -euo pipefail

BIN=${1:?usage: make_dist.sh BINARY [OUT_DIR]}
OUT_DIR=${2:-out/dist}
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
command -v patchelf >/dev/null || { echo "make_dist: patchelf is missing (apt-get install patchelf)" >&2; exit 1; }
[ -x "$BIN" ] || { echo "make_dist: no executable $BIN" >&2; exit 1; }

version=$("$BIN" --version | awk '{print $NF}')
[[ $version =~ ^[0-9]+\.[0-9]+\.[0-9]+ ]] || { echo "make_dist: unexpected version '$version'" >&2; exit 1; }
name=farfield-$version
tarball=$OUT_DIR/$name-linux-x86_64.tar.xz

# Left out: glibc (libc, libm, libdl, libpthread, librt, libresolv, the loader), the C++ runtime, and the GL dispatch
# libraries, which must be the GPU machine's own so that its driver is found.
skip='^(libc|libm|libdl|libpthread|librt|libresolv|ld-linux-x86-64|libstdc\+\+|libgcc_s|libEGL|libGL|libGLX|libOpenGL|libGLdispatch|libGLESv2|libvulkan)\.so'

mkdir -p "$OUT_DIR"
stage=$(mktemp -d "$OUT_DIR/.stage.XXXXXX")
trap 'rm -rf "$stage"' EXIT
pkg=$stage/$name
mkdir -p "$pkg/bin" "$pkg/lib" "$pkg/share/farfield" "$pkg/share/doc"

read -r -a extra_bins <<< "${EXTRA_BINS:-}"
for b in "$BIN" "${extra_bins[@]}"; do
  [ -x "$b" ] || { echo "make_dist: no executable $b" >&2; exit 1; }
  target=$pkg/bin/$(basename "$b")
  [ "$b" = "$BIN" ] && target=$pkg/bin/farfield
  cp "$b" "$target"
  strip "$target"
  # shellcheck disable=SC2016  # $ORIGIN is for the loader, not the shell
  patchelf --set-rpath '$ORIGIN/../lib' "$target"
done

# The Debian package that holds a library: dpkg knows each file under the path it was packaged with, which after the
# /usr merge may be /lib/... or /usr/lib/..., of the file or of its symlink.
package_of() {
  local lib=$1 real c p
  real=$(readlink -f "$lib")
  for c in "$lib" "$real" "${lib#/usr}" "/usr${lib#/usr}" "${real#/usr}" "/usr${real#/usr}"; do
    p=$(dpkg -S "$c" 2>/dev/null | head -1 | cut -d: -f1) && [ -n "$p" ] && { echo "$p"; return; }
  done
  return 1
}

missing=$(for b in "$BIN" "${extra_bins[@]}"; do ldd "$b"; done | awk '/not found/ {print $1}')
[ -z "$missing" ] || { echo "make_dist: ldd finds no ${missing//$'\n'/ }" >&2; exit 1; }
# GLFW opens the X11 extensions with dlopen when `farfield view` makes a window: ldd does not list them, so they and
# their own libraries are added by name.
dlopened=()
for d in libXcursor.so.1 libXrandr.so.2 libXinerama.so.1 libXi.so.6 libXxf86vm.so.1; do
  path=$("$(command -v ldconfig || echo /sbin/ldconfig)" -p | awk -v n="$d" '$1 == n && /x86-64/ {print $NF; exit}')
  [ -n "$path" ] || { echo "make_dist: $d (an X11 extension GLFW opens) is missing" >&2; exit 1; }
  dlopened+=("$path")
done
# "needed path" lines of every library to bundle, each once.
libraries() {
  for b in "$BIN" "${extra_bins[@]}"; do ldd "$b" | awk '$2 == "=>" && $3 ~ /^\// {print $1, $3}'; done
  for path in "${dlopened[@]}"; do
    echo "$(basename "$path") $path"
    ldd "$path" | awk '$2 == "=>" && $3 ~ /^\// {print $1, $3}'
  done
}
count=0
declare -A packages=()
while read -r needed path; do
  [[ $needed =~ $skip ]] && continue
  soname=$(patchelf --print-soname "$path" 2>/dev/null || true)
  soname=${soname:-$needed}
  cp -L "$path" "$pkg/lib/$soname"
  chmod u+w "$pkg/lib/$soname"
  # shellcheck disable=SC2016
  patchelf --set-rpath '$ORIGIN' "$pkg/lib/$soname"
  count=$((count + 1))
  p=$(package_of "$path") || { echo "make_dist: no Debian package owns $path" >&2; exit 1; }
  packages[$p]=1
done < <(libraries | sort -u -k1,1)
[ "$count" -gt 0 ] || { echo "make_dist: ldd listed no libraries for $BIN" >&2; exit 1; }

# Data the libraries read at run time, with their packages' copyright files.
for dir in proj gdal; do
  [ -d "/usr/share/$dir" ] || { echo "make_dist: /usr/share/$dir is missing" >&2; exit 1; }
  cp -rL "/usr/share/$dir" "$pkg/share/$dir"
  [ "$dir" = proj ] && [ "${PROJ_GRIDS:-1}" = 0 ] && find "$pkg/share/proj" -type f \( -name '*.gsb' -o -name '*.gtx' \
    -o -name '*.tif' \) -delete
  for f in "/usr/share/$dir"/*; do
    p=$(dpkg -S "$f" 2>/dev/null | head -1 | cut -d: -f1 || true)
    [ -z "$p" ] || packages[$p]=1
  done
done
[ -f "$pkg/share/proj/proj.db" ] || { echo "make_dist: no proj.db in /usr/share/proj" >&2; exit 1; }

for p in "${!packages[@]}"; do
  mkdir -p "$pkg/share/doc/$p"
  cp -L "/usr/share/doc/$p/copyright" "$pkg/share/doc/$p/copyright" ||
    { echo "make_dist: no copyright file for $p" >&2; exit 1; }
done

cp "$ROOT/tools/plot_bench.py" "$ROOT/tools/plot_terrain.py" "$ROOT/README.md" "$pkg/share/farfield/"
# The libraries loaded with dlopen, which ldd of the tool does not list (scripts/check_dist.sh checks them too).
for path in "${dlopened[@]}"; do basename "$path"; done > "$pkg/share/farfield/dlopened.txt"

rm -f "$tarball"
# xz's x86 branch filter turns relative call addresses into absolute ones before LZMA2, so that the same call in a
# library's code repeats: 6 % smaller than plain -9 on this tarball (49.5 against 52.5 MB), which any xz unpacks.
tar -C "$stage" --sort=name --owner=0 --group=0 --numeric-owner -cf - "$name" | xz --x86 --lzma2=preset=9 -T2 \
  >"$tarball.tmp"
mv "$tarball.tmp" "$tarball"
echo "make_dist: $tarball"
bytes=$(stat -c %s "$tarball")
echo "make_dist: $(awk -v b="$bytes" 'BEGIN {printf "%.1f MB (%.1f MiB)", b / 1e6, b / 1048576}'), unpacked" \
  "$(du -sm "$pkg" | cut -f1) MiB; $count libraries in lib/ (copyrights of ${#packages[@]} Debian packages)," \
  "PROJ's and GDAL's data in share/"
