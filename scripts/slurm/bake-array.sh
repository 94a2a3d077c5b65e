#!/usr/bin/env bash
# A sharded bake on Slurm: an array job of N tasks, task K running `farfield bake ... --shard K/N --resume` into its
# own shard database, and a merge job that starts when every task has succeeded (--dependency=afterok) and joins
# the shards with `farfield merge` into one database.
#
#   scripts/slurm/bake-array.sh --shards N -o city.imp [options] -- SCENE [farfield bake options]
#
#   --shards N            number of shards (array tasks)
#   -o DIR                the merged database; shards go to DIR.shards/shard-K-of-N.imp, logs to DIR.shards/logs
#   --farfield PATH       the farfield binary (default: farfield on PATH, else build/release/bin/farfield)
#   --cpus-per-task C     CPUs per task (default 1: the GL thread; give 2 or more for mesh workers)
#   --gpus-per-task G     GPUs per task (default 0: none requested; on a GPU cluster give 1): each task renders on
#                         the GPU Slurm gave it (the EGL device whose EGL_CUDA_DEVICE_NV is that GPU, found by
#                         gpu::preferredEglDevices from SLURM_STEP_GPUS / SLURM_JOB_GPUS / CUDA_VISIBLE_DEVICES)
#   --mem M               memory per task (sbatch --mem, e.g. 8G)
#   --time T              time limit per task (sbatch --time)
#   --partition P         partition (sbatch --partition)
#   --sbatch "ARGS"       more sbatch arguments for both jobs (word-split)
#   --wait                wait for the merge job; exit with its status (and print the logs of failed jobs)
#
# A task that dies (node failure, preemption, time limit) can be run again as it is: every task bakes with
# --resume, so a requeued task (sbatch --requeue, or `scontrol requeue JOBID_K`) continues from its journal, and
# a task whose shard is complete returns at once. Re-running the whole script with the same arguments resumes every
# shard the same way. The merge job is cancelled by Slurm if a task fails (--kill-on-invalid-dep=yes); after fixing
# the cause, re-run the script. Each log starts with "ff-task K start EPOCH" and ends with "ff-task K end EPOCH
# status S" (the merge: "ff-merge ..."), from which scripts/slurm/shard-times.sh reports per-shard work and the
# scheduling overhead.
set -euo pipefail

shards="" out="" farfield="" cpus=1 gpus=0 mem="" time_limit="" partition="" extra="" wait=0
while [ $# -gt 0 ]; do
  case $1 in
    --shards) shards=$2; shift 2 ;;
    -o|--output) out=$2; shift 2 ;;
    --farfield) farfield=$2; shift 2 ;;
    --cpus-per-task) cpus=$2; shift 2 ;;
    --gpus-per-task) gpus=$2; shift 2 ;;
    --mem) mem=$2; shift 2 ;;
    --time) time_limit=$2; shift 2 ;;
    --partition) partition=$2; shift 2 ;;
    --sbatch) extra=$2; shift 2 ;;
    --wait) wait=1; shift ;;
    --) shift; break ;;
    *) echo "bake-array: unknown option '$1' (see the header of $0)" >&2; exit 2 ;;
  esac
done
[ $# -ge 1 ] || { echo "bake-array: give the scene and bake options after --" >&2; exit 2; }
[[ $shards =~ ^[1-9][0-9]*$ ]] || { echo "bake-array: --shards N with N >= 1 is needed" >&2; exit 2; }
[ -n "$out" ] || { echo "bake-array: -o DIR is needed" >&2; exit 2; }
for a in "$@"; do
  case $a in
    -o|--output|--shard|--resume) echo "bake-array: '$a' is set by the script, not a bake option to pass" >&2; exit 2 ;;
  esac
done
if [ -z "$farfield" ]; then
  farfield=$(command -v farfield || true)
  [ -n "$farfield" ] || farfield="$(cd "$(dirname "$0")/../.." && pwd)/build/release/bin/farfield"
fi
[ -x "$farfield" ] || { echo "bake-array: farfield binary not found: $farfield (--farfield PATH)" >&2; exit 2; }
farfield=$(readlink -f "$farfield")
out=$(readlink -m "$out")
work="$out.shards"
mkdir -p "$work/logs"

# The bake command, quoted once for the job scripts.
bake_args=$(printf ' %q' "$@")
common=(--cpus-per-task="$cpus")
[ -n "$mem" ] && common+=(--mem="$mem")
[ -n "$time_limit" ] && common+=(--time="$time_limit")
[ -n "$partition" ] && common+=(--partition="$partition")
[ "$gpus" != 0 ] && common+=(--gpus-per-task="$gpus")
read -r -a extra_args <<< "$extra"

shard_dirs=()
for ((k = 0; k < shards; ++k)); do shard_dirs+=("$(printf '%s/shard-%d-of-%d.imp' "$work" "$k" "$shards")"); done

cat > "$work/bake-task.sh" <<JOB
#!/usr/bin/env bash
# Array task K of a sharded bake (written by scripts/slurm/bake-array.sh).
k=\${SLURM_ARRAY_TASK_ID:?not an array task}
echo "ff-task \$k start \$(date +%s.%N) host \$(hostname -s) gpus \${SLURM_STEP_GPUS:-\${SLURM_JOB_GPUS:-none}}"
export FF_PROGRESS=0
status=0
$(printf '%q' "$farfield") bake$bake_args --shard "\$k/$shards" --resume \\
  -o "$(printf '%q' "$work")/shard-\$k-of-$shards.imp" || status=\$?
echo "ff-task \$k end \$(date +%s.%N) status \$status"
exit \$status
JOB
cat > "$work/merge.sh" <<JOB
#!/usr/bin/env bash
# The merge job of a sharded bake (written by scripts/slurm/bake-array.sh).
echo "ff-merge start \$(date +%s.%N)"
status=0
$(printf '%q' "$farfield") merge$(printf ' %q' "${shard_dirs[@]}") -o $(printf '%q' "$out") || status=\$?
echo "ff-merge end \$(date +%s.%N) status \$status"
exit \$status
JOB
chmod +x "$work/bake-task.sh" "$work/merge.sh"

echo "ff-submit $(date +%s.%N)" > "$work/logs/submit.log"
array=$(sbatch --parsable --job-name=ff-bake --array=0-$((shards - 1)) --requeue "${common[@]}" "${extra_args[@]}" \
  --output="$work/logs/task-%a.log" "$work/bake-task.sh")
array=${array%%;*}
merge_args=(--parsable --job-name=ff-merge --dependency=afterok:"$array" --kill-on-invalid-dep=yes --cpus-per-task=1
            "${extra_args[@]}" --output="$work/logs/merge.log")
[ -n "$partition" ] && merge_args+=(--partition="$partition")
[ -n "$time_limit" ] && merge_args+=(--time="$time_limit")
echo "bake-array: array job $array ($shards tasks), logs in $work/logs"
if [ $wait = 1 ]; then
  merge=$(sbatch "${merge_args[@]}" "$work/merge.sh")
  merge=${merge%%;*}
  # Poll the merge job (sbatch --wait backs off to half-minute polls); it ends, fails or is cancelled (a task failed).
  state=""
  while :; do
    state=$(scontrol show job -o "$merge" 2> /dev/null | grep -o 'JobState=[A-Z_]*' | cut -d= -f2 || true)
    case $state in
      PENDING|RUNNING|CONFIGURING|COMPLETING|REQUEUED|RESIZING|SUSPENDED|"") ;;
      *) break ;;
    esac
    [ -z "$state" ] && ! squeue -h -j "$merge" > /dev/null 2>&1 && break
    sleep 0.5
  done
  status=1
  [ "$state" = COMPLETED ] && status=0
  echo "bake-array: merge job $merge: ${state:-gone} (status $status)"
  if [ $status != 0 ]; then
    for f in "$work"/logs/task-*.log "$work"/logs/merge.log; do
      grep -q "status 0$" "$f" 2> /dev/null || { echo "--- $f"; tail -n 20 "$f"; }
    done
  fi
  exit $status
fi
merge=$(sbatch "${merge_args[@]}" "$work/merge.sh")
echo "bake-array: merge job ${merge%%;*} -> $out (after every task succeeds)"
