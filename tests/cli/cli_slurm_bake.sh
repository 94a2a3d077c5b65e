#!/bin/bash
# A 4-shard bake through a one-node Slurm (scripts/slurm/local-cluster.sh, bake-array.sh) gives the records of a
# single-process bake of the same cells (farfield merge --compare). Prints "SKIPPED: ..." and exits 0 where Slurm
# cannot start (slurm-wlm or munge missing, or the daemons fail); the daemons it started are stopped on every exit.
# Usage: cli_slurm_bake.sh FARFIELD WORK SOURCE_DIR
set -u
FARFIELD=$1
WORK=$2
SOURCE_DIR=$3
rm -rf "$WORK" && mkdir -p "$WORK" || exit 1
export FF_PROGRESS=0
export FF_SLURM_DIR="$WORK/slurm"
export FF_SLURM_PORT=$(( 17000 + ($$ % 2000) * 2 ))  # apart from another cluster on this machine
CLUSTER="$SOURCE_DIR/scripts/slurm/local-cluster.sh"
fail() { echo "FAILED: $*"; exit 1; }

teardown() {
  "$CLUSTER" stop > /dev/null 2>&1
  for f in "$FF_SLURM_DIR"/*.pid; do
    [ -f "$f" ] && kill -0 "$(cat "$f")" 2> /dev/null && echo "FAILED: a daemon outlived the teardown: $f"
  done
}
trap teardown EXIT

"$CLUSTER" start > "$WORK/start.log" 2>&1
rc=$?
if [ $rc -eq 3 ]; then
  echo "SKIPPED: Slurm cannot start here:"
  cat "$WORK/start.log"
  exit 0
fi
[ $rc -eq 0 ] || fail "local-cluster start: exit $rc: $(cat "$WORK/start.log")"
export SLURM_CONF="$FF_SLURM_DIR/slurm.conf"

"$FARFIELD" gen city --blocks 10 --detail 0 --seed 22 --objects buildings -o "$WORK/city.glb" > /dev/null ||
  fail "gen city"
BAKE=("$WORK/city.glb" --pipeline pvs,near-far,single,mmi --resolution 64 --pvs-face 32 --pvs-spacing 12
      --grid-cells 12 --station-spacing 20 --cells 1,5,9,13,17,21,25)
"$FARFIELD" bake "${BAKE[@]}" -o "$WORK/single.imp" > "$WORK/single.log" 2>&1 ||
  fail "single-process bake: $(cat "$WORK/single.log")"
"$SOURCE_DIR/scripts/slurm/bake-array.sh" --shards 4 -o "$WORK/sharded.imp" --farfield "$FARFIELD" --wait \
  -- "${BAKE[@]}" || fail "bake-array.sh"
for k in 0 1 2 3; do
  grep -q "^shard:  *$k/4" "$WORK/sharded.imp.shards/logs/task-$k.log" || fail "task $k baked no shard"
done
"$FARFIELD" merge --compare "$WORK/single.imp" "$WORK/sharded.imp" || fail "the merged shards differ"
echo "PASSED: 4 shards through Slurm equal the single-process bake"
