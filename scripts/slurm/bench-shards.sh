#!/usr/bin/env bash
# Bake time of a set of the default city's cells for 1, 2, 4 and 8 shards through the one-node Slurm, next to a
# single-process bake of the same cells (docs/BENCHMARKS.md, "Whole cities: shards, resume, streaming").
#
#   scripts/slurm/bench-shards.sh SCENE OUT_DIR "CELLS" [SHARD COUNTS...] [-- more bake options]
#
# For each count N: bake-array.sh --shards N --wait, then shard-times.py (per-shard work, fixed cost per task,
# scheduling overhead) into OUT_DIR/N/times.json, and farfield merge --compare against the single-process bake.
# Starts the local cluster (local-cluster.sh, state in OUT_DIR/slurm) and stops it on exit. FARFIELD names the
# binary (default build/release/bin/farfield; copy it elsewhere first when others rebuild the tree).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
scene=$1 out=$2 cells=$3
shift 3
counts=()
while [ $# -gt 0 ] && [ "$1" != -- ]; do counts+=("$1"); shift; done
[ $# -gt 0 ] && shift
[ ${#counts[@]} -gt 0 ] || counts=(1 2 4 8)
farfield=${FARFIELD:-$here/../../build/release/bin/farfield}
mkdir -p "$out"
export FF_SLURM_DIR=$(readlink -m "$out/slurm") FF_PROGRESS=0
"$here/local-cluster.sh" start
trap '"$here/local-cluster.sh" stop' EXIT
export SLURM_CONF=$FF_SLURM_DIR/slurm.conf
slots=$(nproc)
bake=("$scene" --pipeline pvs,near-far,single,mmi --cells "$cells" "$@")

if [ ! -f "$out/single.imp/index.json" ]; then
  /usr/bin/time -f "%e s, %M kB" -o "$out/single.time" "$farfield" bake "${bake[@]}" -o "$out/single.imp" \
    > "$out/single.txt" 2>&1
fi
echo "single process: $(cat "$out/single.time"); $(grep '^wall:' "$out/single.txt")"
for n in "${counts[@]}"; do
  rm -rf "$out/$n"
  mkdir -p "$out/$n"
  "$here/bake-array.sh" --shards "$n" -o "$out/$n/city.imp" --farfield "$farfield" --wait -- "${bake[@]}"
  python3 "$here/shard-times.py" "$out/$n/city.imp.shards" --slots "$slots" --json "$out/$n/times.json" |
    tee "$out/$n/times.txt"
  "$farfield" merge --compare "$out/single.imp" "$out/$n/city.imp" | tee "$out/$n/compare.txt"
done
