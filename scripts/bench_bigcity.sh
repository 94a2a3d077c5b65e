#!/usr/bin/env bash
# The 100,000-block city end to end (docs/BENCHMARKS.md, "Whole cities: the 100,000-block city"): generation with
# the streamed .glb export, a 3,000-frame drive, a bake of the cells the drive visits in shards through the one-node
# Slurm (scripts/slurm/local-cluster.sh, bake-array.sh) checked against a single-process bake of the same cells
# (farfield merge --compare: identical records), then the drive walked with everything resident and under memory
# budgets (scripts/bench_streaming.sh). Peak RSS of every step (/usr/bin/time) next to its output.
#
#   scripts/bench_bigcity.sh OUT_DIR [SHARDS...]
#
# Environment: FARFIELD (binary; copy it out of the build tree first when others rebuild it), BLOCKS (100000),
# DETAIL (0), SEED (3), SIZE (walk frame size, 320x180), BUDGETS (MB, 0 = all resident; "0 256 16"), BAKE (the bake
# options, default below). Steps whose output exists are skipped, so a rerun continues.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
out=$(readlink -m "$1")
shift
shards=("$@")
[ ${#shards[@]} -gt 0 ] || shards=(2)
farfield=$(readlink -f "${FARFIELD:-$here/../build/release/bin/farfield}")
blocks=${BLOCKS:-100000} detail=${DETAIL:-0} seed=${SEED:-3}
mkdir -p "$out"
export FF_PROGRESS=0
scene=$out/city.glb path=$out/drive3000.json
# The cheap bake: PVS from few, small item buffers (a sample every 50 m, 64 px cube faces), the single depth-mesh
# impostor of each cell's far PVS objects from a station every 20 m, 512 px images, a 2 px bound.
read -r -a bake <<< "${BAKE:---pipeline pvs,near-far,single --layer-mesh depth-mesh --resolution 512 --station-spacing 20 --pvs-spacing 50 --pvs-face 64 --error-px 2}"
bake=("$scene" "${bake[@]}" --path "$path")

timed() {  # timed NAME COMMAND...: output in NAME.txt, wall time and peak RSS in NAME.time
  local name=$1
  shift
  /usr/bin/time -f "%e s, %M kB" -o "$out/$name.time" "$@" > "$out/$name.txt" 2>&1
  echo "$name: $(cat "$out/$name.time")"
}

[ -f "$scene" ] || timed gen "$farfield" gen city --blocks "$blocks" --detail "$detail" --seed "$seed" -o "$scene"
[ -f "$path" ] || timed path "$farfield" path street "$out/city.streets.json" --frames 3000 --fps 30 --seed 41 --car \
  -o "$path"
[ -f "$out/single.imp/index.json" ] || timed single "$farfield" bake "${bake[@]}" --list -o "$out/single.imp"

# Each Slurm task through a wrapper that logs its peak RSS ("ff-rss ...") into the task's log.
cat > "$out/farfield-rss.sh" <<EOF
#!/usr/bin/env bash
exec /usr/bin/time -f "ff-rss %e s, %M kB" $(printf '%q' "$farfield") "\$@"
EOF
chmod +x "$out/farfield-rss.sh"
export FF_SLURM_DIR=$out/slurm
"$here/slurm/local-cluster.sh" start
trap '"$here/slurm/local-cluster.sh" stop' EXIT
export SLURM_CONF=$FF_SLURM_DIR/slurm.conf
for n in "${shards[@]}"; do
  if [ ! -f "$out/$n/city.imp/index.json" ]; then
    rm -rf "$out/$n"
    mkdir -p "$out/$n"
    "$here/slurm/bake-array.sh" --shards "$n" -o "$out/$n/city.imp" --farfield "$out/farfield-rss.sh" --wait -- \
      "${bake[@]}"
  fi
  python3 "$here/slurm/shard-times.py" "$out/$n/city.imp.shards" --slots "$(nproc)" --json "$out/$n/times.json" |
    tee "$out/$n/times.txt"
  grep -h "ff-rss" "$out/$n/city.imp.shards/logs/"*.log | tee "$out/$n/rss.txt"
  "$farfield" merge --compare "$out/single.imp" "$out/$n/city.imp" | tee "$out/$n/compare.txt"
done

read -r -a budgets <<< "${BUDGETS:-0 256 16}"
SIZE=${SIZE:-320x180} FARFIELD=$farfield "$here/bench_streaming.sh" "$scene" "$path" "$out/${shards[0]}/city.imp" \
  "$out/walks" depth-mesh "${budgets[@]}"
for b in "${budgets[@]}"; do echo "walk $b: $(cat "$out/walks/walk-$b.time")"; done
