#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for the tests and benchmarks of sharded bakes (bake-array.sh).
#
#   scripts/slurm/local-cluster.sh start [--cpus N]   start munged, slurmctld and slurmd; prints the env to use
#   scripts/slurm/local-cluster.sh env                print "export SLURM_CONF=..." for this cluster
#   scripts/slurm/local-cluster.sh status             sinfo of the running cluster
#   scripts/slurm/local-cluster.sh stop               stop the daemons this script started and remove nothing else
#
# Everything lives in one state directory, $FF_SLURM_DIR (default /tmp/ff-slurm-$USER): slurm.conf, its own munge
# key and socket, state, spool, logs and pid files; the system's Slurm and munge configuration is neither read nor
# changed. Debian's slurm-wlm and munge provide the daemons (scripts/install-deps.sh). Slurm runs without cgroups:
# proctrack/linuxproc (processes tracked by their parent process id), task/none, no accounting, so it works in a
# container; slurmctld and slurmd listen on localhost at $FF_SLURM_PORT and $FF_SLURM_PORT + 1 (default 16817).
# The node is this host (hostname -s) with --cpus CPUs (default: all) and one partition, "farfield".
#
# `start` exits 3 when a daemon cannot start (its log is printed) after stopping whatever it started, so a caller
# can tell "Slurm is not available here" from a failure of its own. `stop` only signals the pids recorded in the
# state directory, and waits for them to exit.
set -euo pipefail

DIR=${FF_SLURM_DIR:-/tmp/ff-slurm-${USER:-$(id -un)}}
PORT=${FF_SLURM_PORT:-16817}
HOST=$(hostname -s)
ME=$(id -un)

die() { echo "local-cluster: $*" >&2; exit "${2:-1}"; }

pid_alive() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2> /dev/null; }

stop_one() {  # stop_one PIDFILE NAME
  local pidfile=$1 name=$2 pid
  [ -f "$pidfile" ] || return 0
  pid=$(cat "$pidfile")
  if kill -0 "$pid" 2> /dev/null; then
    kill "$pid" 2> /dev/null || true
    for _ in $(seq 1 50); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
    if kill -0 "$pid" 2> /dev/null; then
      echo "local-cluster: $name ($pid) did not stop on SIGTERM: SIGKILL" >&2
      kill -9 "$pid" 2> /dev/null || true
    fi
  fi
  rm -f "$pidfile"
}

stop() {
  # Jobs first (their processes are children of slurmstepd), then the daemons in reverse order of start.
  if pid_alive "$DIR/slurmctld.pid"; then
    SLURM_CONF="$DIR/slurm.conf" scancel --quiet --user="$ME" 2> /dev/null || true
  fi
  stop_one "$DIR/slurmd.pid" slurmd
  stop_one "$DIR/slurmctld.pid" slurmctld
  stop_one "$DIR/munged.pid" munged
}

write_conf() {
  local cpus=$1 mem
  mem=$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)
  cat > "$DIR/slurm.conf" <<CONF
# Written by scripts/slurm/local-cluster.sh: a one-node cluster without cgroups.
ClusterName=farfield-local
SlurmctldHost=$HOST(127.0.0.1)
SlurmUser=$ME
SlurmdUser=$ME
SlurmctldPort=$PORT
SlurmdPort=$((PORT + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$DIR/munge.socket
StateSaveLocation=$DIR/state
SlurmdSpoolDir=$DIR/spool
SlurmctldPidFile=$DIR/slurmctld.pid
SlurmdPidFile=$DIR/slurmd.pid
SlurmctldLogFile=$DIR/slurmctld.log
SlurmdLogFile=$DIR/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
MinJobAge=300
KillWait=5
Waittime=0
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=farfield Nodes=$HOST Default=YES MaxTime=INFINITE State=UP OverSubscribe=NO
CONF
  # No cgroups: nothing in cgroup.conf is used with proctrack/linuxproc and task/none, but slurmd reads the file.
  echo "CgroupPlugin=autodetect" > "$DIR/cgroup.conf"
}

start() {
  local cpus
  cpus=$(nproc)
  while [ $# -gt 0 ]; do
    case $1 in
      --cpus) cpus=$2; shift 2 ;;
      *) die "unknown option $1 (start [--cpus N])" ;;
    esac
  done
  for tool in munged slurmctld slurmd sinfo; do
    command -v "$tool" > /dev/null || PATH=$PATH:/usr/sbin command -v "$tool" > /dev/null ||
      die "$tool not found (install slurm-wlm and munge: scripts/install-deps.sh)" 3
  done
  export PATH=$PATH:/usr/sbin
  if pid_alive "$DIR/slurmctld.pid" && pid_alive "$DIR/slurmd.pid"; then
    echo "local-cluster: already running ($DIR)"
    echo "export SLURM_CONF=$DIR/slurm.conf"
    return 0
  fi
  stop
  mkdir -p "$DIR/state" "$DIR/spool" "$DIR/munge"
  chmod 700 "$DIR/munge"
  write_conf "$cpus"
  # munge: its own key and socket.
  if [ ! -f "$DIR/munge/munge.key" ]; then
    dd if=/dev/urandom of="$DIR/munge/munge.key" bs=1024 count=1 status=none
    chmod 400 "$DIR/munge/munge.key"
  fi
  local failed=""
  munged --force --key-file="$DIR/munge/munge.key" --socket="$DIR/munge.socket" --pid-file="$DIR/munged.pid" \
    --log-file="$DIR/munged.log" --seed-file="$DIR/munge/munged.seed" 2> "$DIR/munged.err" || failed=munged
  if [ -z "$failed" ]; then
    SLURM_CONF="$DIR/slurm.conf" slurmctld -f "$DIR/slurm.conf" 2> "$DIR/slurmctld.err" || failed=slurmctld
  fi
  if [ -z "$failed" ]; then
    SLURM_CONF="$DIR/slurm.conf" slurmd -f "$DIR/slurm.conf" 2> "$DIR/slurmd.err" || failed=slurmd
  fi
  # Wait for the node to be idle (slurmd registered with slurmctld).
  if [ -z "$failed" ]; then
    local state=""
    for _ in $(seq 1 100); do
      state=$(SLURM_CONF="$DIR/slurm.conf" sinfo -h -N -o '%T' 2> /dev/null | head -1 || true)
      [ "$state" = idle ] && break
      sleep 0.2
    done
    [ "$state" = idle ] || failed="slurmd registration (node state '${state:-none}')"
  fi
  if [ -n "$failed" ]; then
    echo "local-cluster: $failed did not start; logs in $DIR:" >&2
    for f in munged.err munged.log slurmctld.err slurmctld.log slurmd.err slurmd.log; do
      [ -s "$DIR/$f" ] && { echo "--- $f" >&2; tail -n 15 "$DIR/$f" >&2; }
    done
    stop
    exit 3
  fi
  echo "local-cluster: node $HOST with $cpus CPUs, partition farfield ($DIR)"
  echo "export SLURM_CONF=$DIR/slurm.conf"
}

case ${1:-} in
  start) shift; start "$@" ;;
  stop) stop; echo "local-cluster: stopped ($DIR)" ;;
  env) echo "export SLURM_CONF=$DIR/slurm.conf" ;;
  status) SLURM_CONF="$DIR/slurm.conf" sinfo -N ;;
  *) die "usage: $0 start [--cpus N] | stop | env | status" ;;
esac
