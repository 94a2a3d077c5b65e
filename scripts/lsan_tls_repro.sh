#!/usr/bin/env bash
# Shows why `make test-asan` sets ASAN_OPTIONS=intercept_tls_get_addr=0 (Makefile; docs/DESIGN-NOTES.md, Sanitizer
# build). A program loads a library with a thread-local pointer, holds a heap block only through it, and shifts where
# malloc places the library's dynamic TLS block by allocating N small blocks first. Where the TLS block starts 16 bytes
# past a page boundary, the sanitizer runtime's __tls_get_addr interceptor takes it for an old glibc block with a
# header and records the two words before it as the block's bounds; LeakSanitizer's tracer dies reading them at exit.
# Prints the crashes with the interceptor on and off; fails if any run with it off crashes or reports a leak (the
# block held only through TLS must still be found).
# Usage: scripts/lsan_tls_repro.sh [CC]   (default gcc; clang works too)
set -euo pipefail
cc=${1:-gcc}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cat >"$dir/lib.c" <<'C'
__thread void* held_through_tls;
void* hold(void* p) { held_through_tls = p; return &held_through_tls; }
C
cat >"$dir/main.c" <<'C'
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
int main(int argc, char** argv) {
  static void* shift[512];
  int n = argc > 1 ? atoi(argv[1]) : 0;
  for (int i = 0; i < n && i < 512; ++i) shift[i] = malloc(8);
  void* lib = dlopen(argv[2], RTLD_NOW);
  if (!lib) { fprintf(stderr, "%s\n", dlerror()); return 2; }
  void* (*hold)(void*) = (void* (*)(void*))dlsym(lib, "hold");
  unsigned long tls = (unsigned long)hold(malloc(100));
  printf("%lu\n", tls % 4096);
  fflush(stdout);  /* before the leak check at exit, which may die */
  return 0;
}
C
"$cc" -shared -fPIC -o "$dir/lib.so" "$dir/lib.c"
"$cc" -fsanitize=address -g -o "$dir/main" "$dir/main.c" -ldl
runs=300
for option in 1 0; do
  crashes=0 leaks=0 at16=0
  for n in $(seq 0 $((runs - 1))); do
    status=0
    out=$(ASAN_OPTIONS=detect_leaks=1:intercept_tls_get_addr=$option "$dir/main" "$n" "$dir/lib.so" 2>&1) || status=$?
    [ "$(head -n1 <<<"$out")" = 16 ] && at16=$((at16 + 1))
    if grep -q "Tracer caught signal" <<<"$out"; then crashes=$((crashes + 1))
    elif [ "$status" != 0 ]; then leaks=$((leaks + 1)); fi
  done
  echo "intercept_tls_get_addr=$option: $runs runs, $at16 with the TLS block 16 bytes past a page, $crashes tracer" \
       "crashes, $leaks leak reports"
done
[ "$crashes" = 0 ] && [ "$leaks" = 0 ]  # the last pass: the interceptor off
