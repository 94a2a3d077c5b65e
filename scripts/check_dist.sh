#!/usr/bin/env bash
# Proves a release tarball of scripts/make_dist.sh on a machine with nothing but a minimal Debian 12:
#   scripts/check_dist.sh TARBALL [ROOT_DIR]        (ROOT_DIR defaults to out/dist-root; run as root)
# 1. ROOT_DIR: `debootstrap --variant=minbase bookworm` plus only libglvnd and Mesa's EGL with llvmpipe, built once and
#    reused (ROOT_DIR/.farfield-dist-root marks a finished one);
# 2. the positive check, in a chroot with /proc (and /dev) mounted and an empty environment: every library the tool
#    loads (ldd of it, and of the libraries it opens with dlopen: share/farfield/dlopened.txt) comes from the
#    tarball's lib/ or is one it leaves out (glibc, libstdc++, libgcc_s, the GL dispatch), and every file of lib/ is
#    one of them; a
#    headless frame (render builtin:cubes), a short walkthrough benchmark on llvmpipe (gen city, path street, bench
#    --modes culled) and an OpenStreetMap import exported as 3D Tiles (PROJ with the tarball's proj.db: the root has
#    no /usr/share/proj);
# 3. the negative check: a copy of the unpacked tree without libassimp must fail to start.
# Exits non-zero when the positive check fails or the negative check does not.
set -euo pipefail

TARBALL=${1:?usage: check_dist.sh TARBALL [ROOT_DIR]}
ROOT=${2:-out/dist-root}
REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
[ "$(id -u)" -eq 0 ] || { echo "check_dist: needs root (debootstrap, chroot, mount)" >&2; exit 1; }
[ -f "$TARBALL" ] || { echo "check_dist: no tarball $TARBALL" >&2; exit 1; }
TARBALL=$(readlink -f "$TARBALL")
mkdir -p "$ROOT"
ROOT=$(readlink -f "$ROOT")
[ "$ROOT" != / ] || { echo "check_dist: ROOT_DIR must not be /" >&2; exit 1; }

packages=(libegl1 libgl1 libopengl0 libegl-mesa0 libgl1-mesa-dri)
stamp=$ROOT/.farfield-dist-root
log=$(mktemp)
mounted=()
cleanup() {
  local i
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do umount "${mounted[i]}" 2>/dev/null || umount -l "${mounted[i]}" || true; done
  mounted=()
  rm -f "$log"
}
trap cleanup EXIT
mount_root() {
  mountpoint -q "$ROOT/proc" || { mount -t proc proc "$ROOT/proc"; mounted+=("$ROOT/proc"); }
  # debootstrap makes /dev/null and friends itself, except inside some containers: bind the host's /dev then.
  if [ ! -c "$ROOT/dev/null" ] && ! mountpoint -q "$ROOT/dev"; then
    mount --bind /dev "$ROOT/dev"; mounted+=("$ROOT/dev")
  fi
}
# Runs a command in the root with an empty environment (nothing of this machine's PATH, LD_LIBRARY_PATH or DISPLAY).
inroot() { chroot "$ROOT" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root LANG=C.UTF-8 "$@"; }

t0=$SECONDS
# 1. The minimal root.
if [ -f "$stamp" ]; then
  echo "check_dist: reusing the minimal Debian 12 root $ROOT"
else
  if findmnt -rn -o TARGET | grep -q "^$ROOT/"; then echo "check_dist: something is mounted under $ROOT" >&2; exit 1; fi
  if ! command -v debootstrap >/dev/null; then
    echo "check_dist: installing debootstrap"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends debootstrap >/dev/null
  fi
  mirror=http://deb.debian.org/debian
  if ! timeout 10 bash -c 'exec 3<>/dev/tcp/deb.debian.org/80' 2>/dev/null; then
    # The mirror apt uses here: the first Debian archive in sources.list(.d), one-line or deb822 format.
    mirror=$(cat /etc/apt/sources.list /etc/apt/sources.list.d/*.list /etc/apt/sources.list.d/*.sources 2>/dev/null |
      grep -v '^\s*#' | grep -oE '(https?|file)://[^ ]*debian/?( |$)' | grep -v security | head -1 | tr -d ' ')
    [ -n "$mirror" ] || { echo "check_dist: deb.debian.org is unreachable and apt names no Debian mirror" >&2; exit 1; }
  fi
  echo "check_dist: debootstrap --variant=minbase bookworm $ROOT $mirror (a few minutes)"
  rm -rf "$ROOT"; mkdir -p "$ROOT"
  debootstrap --variant=minbase bookworm "$ROOT" "$mirror" >"$log" 2>&1 || { tail -20 "$log"; exit 1; }
  mount_root
  echo "check_dist: installing in the root only ${packages[*]}"
  { inroot apt-get update -qq &&
    inroot env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${packages[@]}" &&
    inroot apt-get clean; } >"$log" 2>&1 || { tail -20 "$log"; exit 1; }
  printf '%s\n' "${packages[@]}" >"$stamp"
fi
mount_root
echo "check_dist: the root has $(inroot dpkg-query -W -f='.\n' | wc -l) packages, /usr/share/proj $([ -e "$ROOT/usr/share/proj" ] && echo present || echo absent), /usr/share/gdal $([ -e "$ROOT/usr/share/gdal" ] && echo present || echo absent)"
t_root=$((SECONDS - t0))

# 2. The positive check.
rm -rf "$ROOT/opt/ff-check" "$ROOT/opt/ff-broken" "$ROOT/tmp/ff-check"
mkdir -p "$ROOT/opt/ff-check" "$ROOT/tmp/ff-check"
tar -C "$ROOT/opt/ff-check" -xJf "$TARBALL"
name=$(ls "$ROOT/opt/ff-check")
[[ $name =~ ^farfield-[0-9][^[:space:]]*$ ]] || { echo "check_dist: $TARBALL does not hold one farfield-<version>/" >&2; exit 1; }
ff=/opt/ff-check/$name/bin/farfield
work=/tmp/ff-check
cp "$REPO/tests/data/geodata/small_city.osm" "$ROOT$work/"
failures=()
step() {  # step LABEL COMMAND...: runs COMMAND in the root, keeps its output in $ROOT$work/LABEL.txt
  local label=$1; shift
  if inroot "$@" >"$ROOT$work/$label.txt" 2>&1; then echo "  ok    $label"; else
    echo "  FAIL  $label (exit $?):"; tail -5 "$ROOT$work/$label.txt" | sed 's/^/        /'; failures+=("$label"); fi
}
echo "check_dist: positive check in the root ($name)"
step version "$ff" --version
# Every object the loader maps: from the tarball's lib/, or glibc, the C++ runtime or the GL dispatch of the root.
inroot ldd "$ff" 2>&1 | sed 's|/bin/\.\./lib/|/lib/|' >"$ROOT$work/ldd.txt" || true
# The libraries the tool opens with dlopen (make_dist.sh lists them) and what they load, as ldd of each finds it.
dlopened_list=$ROOT/opt/ff-check/$name/share/farfield/dlopened.txt
if [ -f "$dlopened_list" ]; then
  while read -r d; do
    [ -n "$d" ] || continue
    echo "	$d => /opt/ff-check/$name/lib/$d (opened with dlopen)" >>"$ROOT$work/ldd.txt"
    if [ -f "$ROOT/opt/ff-check/$name/lib/$d" ]; then
      inroot ldd "/opt/ff-check/$name/lib/$d" >>"$ROOT$work/ldd.txt" 2>&1 || true
    else
      echo "	$d => not found" >>"$ROOT$work/ldd.txt"
    fi
  done <"$dlopened_list"
fi
bundled=$(grep "=> /opt/ff-check/$name/lib/" "$ROOT$work/ldd.txt" | awk '{print $1}' | sort -u | wc -l)
strays=$(grep '=>' "$ROOT$work/ldd.txt" | grep -v "=> /opt/ff-check/$name/lib/" | sort -u |
  grep -vE '^\s*(libc|libm|libdl|libpthread|librt|libresolv|libstdc\+\+|libgcc_s|libOpenGL|libGLdispatch|libEGL|libGLX|libGL)\.so' || true)
if [ -n "$strays" ] || [ "$bundled" -ne "$(ls "$ROOT/opt/ff-check/$name/lib" | wc -l)" ]; then
  echo "  FAIL  libraries: $bundled of $(ls "$ROOT/opt/ff-check/$name/lib" | wc -l) from lib/; elsewhere or missing:"
  echo "$strays" | sed 's/^/        /'; failures+=(libraries)
else
  echo "  ok    libraries: all $bundled of lib/ load from it, the rest are the root's glibc, libstdc++ and GL dispatch"
fi
step render "$ff" render builtin:cubes --eye 10,-12,8 --at 0,0,1 --fov 50 --size 320x180 -o $work/frame.png
frame_bytes=$(stat -c %s "$ROOT$work/frame.png" 2>/dev/null || echo 0)
if [ "$frame_bytes" -gt 0 ] && [ "$(head -c 8 "$ROOT$work/frame.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ]; then
  echo "  ok    frame.png: $frame_bytes bytes"
else echo "  FAIL  frame.png missing, empty or not a PNG"; failures+=(frame); fi
step gen "$ff" gen city --blocks 10 --seed 1 -o $work/city.glb
step path "$ff" path street $work/city.streets.json --frames 20 --seed 1 -o $work/path.json
step bench "$ff" bench $work/city.glb --path $work/path.json --modes culled --frames 5 --size 160x90 --samples 1 --no-plots \
  -o $work/bench
renderer=$(grep -o '"renderer": *"[^"]*"' "$ROOT$work/bench/bench.json" 2>/dev/null | head -1 || true)
if [[ $renderer == *llvmpipe* ]]; then echo "  ok    bench.json: $renderer"; else
  echo "  FAIL  bench.json does not name llvmpipe (${renderer:-no renderer})"; failures+=(renderer); fi
step import-osm "$ff" import osm $work/small_city.osm -o $work/osm.glb
step export-tiles-proj "$ff" export $work/osm.glb --tiles $work/tiles --size 320x180

# 3. The negative check: without one bundled library the tool must not start.
echo "check_dist: negative check (a copy of the tree without libassimp)"
cp -a "$ROOT/opt/ff-check" "$ROOT/opt/ff-broken"
removed=$(cd "$ROOT/opt/ff-broken/$name/lib" && ls libassimp.so.* | head -1)
rm "$ROOT/opt/ff-broken/$name/lib/$removed"
negative_ok=0
if inroot "/opt/ff-broken/$name/bin/farfield" --version >"$ROOT$work/broken.txt" 2>&1; then
  echo "  FAIL  farfield started without $removed: the check cannot tell a broken tarball"
elif grep -q "$removed" "$ROOT$work/broken.txt"; then
  negative_ok=1
  echo "  ok    farfield fails to start without $removed: $(head -1 "$ROOT$work/broken.txt")"
else
  echo "  FAIL  farfield failed without $removed, but not for it: $(head -1 "$ROOT$work/broken.txt")"
fi
rm -rf "$ROOT/opt/ff-broken"

echo "check_dist: summary: $(basename "$TARBALL") ($(awk -v b="$(stat -c %s "$TARBALL")" 'BEGIN {printf "%.1f MB", b / 1e6}')) in a minimal Debian 12 root" \
  "(${#packages[@]} packages added: libglvnd + Mesa llvmpipe); positive check $([ ${#failures[@]} -eq 0 ] && echo passed || echo "FAILED: ${failures[*]}")," \
  "negative check $([ $negative_ok -eq 1 ] && echo passed || echo FAILED); root ${t_root} s, checks $((SECONDS - t0 - t_root)) s;" \
  "outputs in $ROOT$work"
[ ${#failures[@]} -eq 0 ] && [ $negative_ok -eq 1 ]
