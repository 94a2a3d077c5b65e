#!/bin/bash
# farfield bake --resume after kill -9 at random moments: the directory first holds an earlier, smaller bake; a
# larger bake into it is killed (SIGKILL) a few times at random moments and resumed. After every kill the directory
# still holds a whole, readable database (the earlier one, or the new one when the kill came after its index was in
# place), and the resumed bake's records equal those of an uninterrupted bake (farfield merge --compare).
# Usage: cli_bake_resume.sh FARFIELD WORK
set -u
FARFIELD=$1
WORK=$2
rm -rf "$WORK" && mkdir -p "$WORK" || exit 1
export FF_PROGRESS=0
fail() { echo "FAILED: $*"; exit 1; }

"$FARFIELD" gen city --blocks 10 --detail 0 --seed 21 --objects buildings -o "$WORK/city.glb" > /dev/null || fail "gen city"
CELLS=2,6,10,14,18
ARGS=(bake "$WORK/city.glb" --pipeline pvs,near-far,single,mmi --resolution 96 --pvs-face 48 --pvs-spacing 12
      --grid-cells 12 --station-spacing 20)
bake() {  # bake OUT CELLS [more args]
  local out=$1 cells=$2
  shift 2
  "$FARFIELD" "${ARGS[@]}" --cells "$cells" -o "$out" "$@"
}

start=$(date +%s%N)
bake "$WORK/reference.imp" $CELLS > "$WORK/reference.log" 2>&1 || fail "reference bake: $(cat "$WORK/reference.log")"
full_ms=$(( ($(date +%s%N) - start) / 1000000 ))
bake "$WORK/earlier.imp" 2 > /dev/null 2>&1 || fail "earlier bake"
bake "$WORK/killed.imp" 2 > /dev/null 2>&1 || fail "earlier bake into killed.imp"
echo "uninterrupted bake: ${full_ms} ms"

RANDOM=$(( $(date +%s) % 32768 ))
resume=""
kills=0
for attempt in 1 2 3; do
  delay_ms=$(( full_ms * (15 + RANDOM % 50) / 100 ))
  "$FARFIELD" "${ARGS[@]}" --cells $CELLS -o "$WORK/killed.imp" $resume > "$WORK/killed.$attempt.log" 2>&1 &
  pid=$!  # farfield itself, not a subshell
  sleep "$(printf '%d.%03d' $((delay_ms / 1000)) $((delay_ms % 1000)))"
  kill -9 $pid 2> /dev/null
  wait $pid
  rc=$?
  journal=0
  [ -f "$WORK/killed.imp/bake.journal" ] && journal=$(( $(wc -l < "$WORK/killed.imp/bake.journal") - 1 ))
  echo "attempt $attempt: killed after ${delay_ms} ms (exit $rc), journal holds $journal finished cells"
  [ $rc -eq 137 ] && kills=$((kills + 1))
  # A whole database at every moment: the earlier one, or (killed after the index was replaced) the new one.
  if ! "$FARFIELD" merge --compare "$WORK/killed.imp" "$WORK/earlier.imp" > "$WORK/cmp.log" 2>&1 &&
     ! "$FARFIELD" merge --compare "$WORK/killed.imp" "$WORK/reference.imp" >> "$WORK/cmp.log" 2>&1; then
    fail "after kill $attempt the directory holds neither database: $(cat "$WORK/cmp.log")"
  fi
  resume=--resume
  [ $rc -eq 0 ] && break  # finished before the kill: nothing left to interrupt
done
[ $kills -gt 0 ] || fail "no bake was killed while running (the machine is too fast for the delays?)"

bake "$WORK/killed.imp" $CELLS --resume > "$WORK/resume.log" 2>&1 || fail "resume: $(cat "$WORK/resume.log")"
grep -E "^resume:" "$WORK/resume.log"
"$FARFIELD" merge --compare "$WORK/killed.imp" "$WORK/reference.imp" || fail "resumed records differ"
[ ! -f "$WORK/killed.imp/bake.journal" ] || fail "the journal outlived the finished bake"
echo "PASSED: $kills kills, resumed bake equals the uninterrupted one"
