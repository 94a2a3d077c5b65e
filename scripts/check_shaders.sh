#!/usr/bin/env bash
# Every GLSL program a run linked, through a second compiler: the Khronos reference front end, glslangValidator
# (Debian's glslang-tools). The tests compile Farfield's shaders through Mesa; a GPU machine compiles them through
# its vendor's compiler, and a program one accepts and the other refuses costs a GPU session. Each program's stages
# are compiled and linked as OpenGL GLSL, then compiled to SPIR-V for OpenGL (-G), whose stricter rules catch what a
# lenient front end lets through.
#
# Usage: scripts/check_shaders.sh DIR    (DIR: what FF_SHADER_DUMP=DIR wrote: src/farfield/gpu/shader_dump.h;
#                                         `make test` sets it to <build>/shader-dump and runs this last)
# Exit 0: every program accepted; 1: a program refused (its errors printed) or the check could not fail;
# 77: nothing to check (no glslangValidator, or no program in DIR), with the reason.
set -uo pipefail
dir=${1:?usage: check_shaders.sh DIR}
if ! command -v glslangValidator > /dev/null 2>&1; then
  echo "SKIPPED: no glslangValidator (scripts/install-deps.sh installs glslang-tools)"
  exit 77
fi
programs=()
for p in "$dir"/*/; do
  case $p in *.tmp*) continue ;; esac
  [ -d "$p" ] && programs+=("${p%/}")
done
if [ ${#programs[@]} -eq 0 ]; then
  echo "SKIPPED: no program in $dir (run the tests with FF_SHADER_DUMP=$dir, as make test does)"
  exit 77
fi

# The check must be able to fail: a program with a type error is refused by both of its runs.
bad=$(mktemp -d)
trap 'rm -rf "$bad"' EXIT
printf '#version 450 core\nlayout(location = 0) out vec4 o;\nvoid main() { o = vec3(1.0); }\n' > "$bad/bad.frag"
if glslangValidator -l "$bad/bad.frag" > /dev/null 2>&1 ||
  glslangValidator -G -o /dev/null -l "$bad/bad.frag" > /dev/null 2>&1; then
  echo "check_shaders: glslangValidator accepted a program with a type error: this check cannot fail"
  exit 1
fi

failed=0
for p in "${programs[@]}"; do
  for run in "-l" "-G --auto-map-locations --auto-map-bindings -o /dev/null -l"; do
    # shellcheck disable=SC2086  # $run is a list of options
    if ! out=$(glslangValidator $run "$p"/* 2>&1); then
      failed=$((failed + 1))
      echo "REFUSED ($run): $(cd "$p" && ls | tr '\n' ' ')in $p"
      echo "$out" | grep -v '^$' | head -20
      break
    fi
  done
done
stages=$(find "${programs[@]}" -type f | sed 's|.*/||' | sort -u | tr '\n' ' ')
version=$(glslangValidator --version 2>/dev/null | head -1 | sed 's/^Glslang Version: //')
echo "check_shaders: ${#programs[@]} programs (glslang $version," \
  "stages $stages): $((${#programs[@]} - failed)) accepted, $failed refused"
[ $failed -eq 0 ]
