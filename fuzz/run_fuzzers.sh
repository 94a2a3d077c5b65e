#!/usr/bin/env bash
# Runs each fuzz target for SECONDS on its corpus (BUILD/corpus/<target>, grown in place), one after the other, and
# prints a table: executions, executions per second, libFuzzer's final coverage (cov: edges, ft: features), corpus
# size and crashes. A crash (sanitizer report, an exception other than farfield::Error, a timeout, running out of
# memory) stops that target (undefined behaviour of the checks fuzz/ubsan.supp makes recoverable is counted after it); its input is saved as BUILD/crashes/<target>/crash-* (or timeout-*, oom-*, leak-*) and
# the script exits non-zero. Logs: BUILD/logs/<target>.log.
#
# Usage: fuzz/run_fuzzers.sh BUILD_DIR SECONDS [TARGET...]   (targets: names without "fuzz_"; default all built)
# Extra libFuzzer flags: FUZZ_FLAGS="-runs=1000000". FUZZ_NICE (default 10) is the nice level of each run.
# FUZZ_CHUNK=S runs each target as a series of fresh processes of S seconds over the same corpus until SECONDS are
# spent (for a library that leaks on damaged input, whose RSS would otherwise reach the limit): executions are
# summed over the series, the rate is their mean, the coverage and corpus are the last run's. FUZZ_CHUNK_RUNS=N ends
# each process of the series after N executions instead (the leak grows per execution, so on a shared machine, where
# the rate varies, a count keeps the RSS bounded where a time does not; a process that only replayed its corpus
# before its seconds ran out explored nothing).
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:?usage: run_fuzzers.sh BUILD_DIR SECONDS [TARGET...]}"
seconds="${2:?usage: run_fuzzers.sh BUILD_DIR SECONDS [TARGET...]}"
shift 2
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for b in "$build"/bin/fuzz_*; do [ -x "$b" ] && targets+=("$(basename "$b" | sed 's/^fuzz_//')"); done
fi
mkdir -p "$build/logs"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=0}"
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$root/fuzz/lsan.supp}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:suppressions=$root/fuzz/ubsan.supp}"

failed=0
rows=()
for t in "${targets[@]}"; do
  bin="$build/bin/fuzz_$t"
  if [ ! -x "$bin" ]; then echo "run_fuzzers: no $bin (build the fuzz target first)" >&2; failed=1; continue; fi
  corpus="$build/corpus/$t"
  crashes="$build/crashes/$t"
  mkdir -p "$corpus" "$crashes"
  dict=()
  [ -f "$root/fuzz/$t.dict" ] && dict=("-dict=$root/fuzz/$t.dict")
  # A target's own flags (fuzz/TARGET.flags), e.g. a larger single-allocation limit where a library needs one.
  flags=()
  [ -f "$root/fuzz/$t.flags" ] && read -r -a flags < "$root/fuzz/$t.flags"
  log="$build/logs/$t.log"
  # Slow units (slow-unit-*: slower than 10 s, saved for a look) are not crashes.
  before=$(find "$crashes" -type f ! -name 'slow-unit-*' | wc -l)
  echo "fuzz_$t: ${seconds}s on $(find "$corpus" -type f | wc -l) inputs (log: $log)"
  chunk="${FUZZ_CHUNK:-$seconds}"
  left="$seconds"
  execs=0
  : > "$log"
  rc=0
  runs=()
  [ -n "${FUZZ_CHUNK_RUNS:-}" ] && runs=("-runs=$FUZZ_CHUNK_RUNS")
  while [ "$left" -gt 0 ] && [ "$rc" -eq 0 ]; do
    run=$(( left < chunk ? left : chunk ))
    started=$(date +%s)
    # shellcheck disable=SC2086
    nice -n "${FUZZ_NICE:-10}" "$bin" -max_total_time="$run" -timeout=30 -rss_limit_mb=2560 -print_final_stats=1 \
      -artifact_prefix="$crashes/" "${dict[@]}" "${flags[@]}" "${runs[@]}" ${FUZZ_FLAGS:-} "$corpus" > "$log.part" 2>&1
    rc=$?
    elapsed=$(( $(date +%s) - started ))
    [ ${#runs[@]} -gt 0 ] && run=$(( elapsed > 0 ? elapsed : 1 ))
    cat "$log.part" >> "$log"
    n=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log.part" | tail -1 | grep -o '[0-9]*$')
    execs=$((execs + ${n:-0}))
    left=$((left - run))
  done
  rm -f "$log.part"
  after=$(find "$crashes" -type f ! -name 'slow-unit-*' | wc -l)
  # Undefined behaviour of a check built to recover (fuzz/ubsan.supp) is printed, not fatal: still a finding.
  if [ "$rc" -eq 0 ] && grep -q "runtime error:" "$log"; then rc=1; fi
  rate=$((execs / seconds))
  status=$(grep -E '^#[0-9]+' "$log" | grep -E 'cov: ' | tail -1)
  cov=$(echo "$status" | grep -o 'cov: [0-9]*' | grep -o '[0-9]*')
  ft=$(echo "$status" | grep -o 'ft: [0-9]*' | grep -o '[0-9]*')
  corp=$(echo "$status" | grep -o 'corp: [0-9]*' | grep -o '[0-9]*')
  new=$((after - before))
  if [ "$rc" -ne 0 ] || [ "$new" -gt 0 ]; then
    failed=1
    [ "$new" -eq 0 ] && new="?"
    echo "fuzz_$t: CRASH (exit $rc); input under $crashes/, report at the end of $log" >&2
    grep -E 'ERROR: |FINDING|runtime error|SUMMARY' "$log" | head -5 >&2
  fi
  rows+=("$(printf '%-16s %12s %8s %7s %8s %7s %8s' "$t" "${execs:-0}" "${rate:-0}" "${cov:--}" "${ft:--}" \
           "${corp:--}" "$( [ "$rc" -eq 0 ] && [ "$new" = 0 ] && echo 0 || echo "$new")")")
done

printf '\n%-16s %12s %8s %7s %8s %7s %8s\n' target executions exec/s cov ft corpus crashes
for r in "${rows[@]}"; do echo "$r"; done
exit $failed
