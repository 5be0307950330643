#!/usr/bin/env bash
# A single-node Slurm on this machine for the sweep tests: munged, slurmctld and slurmd on
# localhost, one partition of one node, no systemd, everything under one temporary directory.
#
#   tests/slurm/cluster.sh start   # starts the daemons, waits for the node; prints SLURM_CONF=...
#   tests/slurm/cluster.sh stop    # stops what `start` started
#   tests/slurm/cluster.sh status  # sinfo
#
# Needs Debian's `slurm-wlm` and `munge` packages and root (the daemons run as root, as the
# sweep test's jobs do). The directory is $VIBROBED_SLURM_DIR, default ${TMPDIR:-/tmp}/vibrobed-slurm;
# client commands find the cluster through SLURM_CONF=$dir/slurm.conf (the test looks there too).
set -euo pipefail

dir="${VIBROBED_SLURM_DIR:-${TMPDIR:-/tmp}/vibrobed-slurm}"
conf="$dir/slurm.conf"
export SLURM_CONF="$conf"

die() { echo "cluster.sh: $*" >&2; exit 1; }

# Stops the daemon whose pid is in file $1 (if it is running) and waits for it to go.
stop_pidfile() {
  local file="$1" pid
  [[ -f "$file" ]] || return 0
  pid="$(cat "$file" 2>/dev/null || true)"
  if [[ -n "$pid" ]] && kill -0 "$pid" 2>/dev/null; then
    kill "$pid" 2>/dev/null || true
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -0 "$pid" 2>/dev/null && kill -9 "$pid" 2>/dev/null || true
  fi
  rm -f "$file"
}

start() {
  for cmd in munged slurmctld slurmd sinfo; do
    command -v "$cmd" >/dev/null || die "$cmd not found (apt-get install slurm-wlm munge)"
  done
  [[ "$(id -u)" == 0 ]] || die "must run as root"
  if [[ -f "$dir/slurmctld.pid" ]] && kill -0 "$(cat "$dir/slurmctld.pid")" 2>/dev/null; then
    echo "cluster.sh: already running (SLURM_CONF=$conf)"
    return 0
  fi
  mkdir -p "$dir/state" "$dir/spool" "$dir/munge"
  local host cpus mem
  host="$(hostname -s)"
  cpus="$(nproc)"
  mem="$(awk '/MemTotal/ { printf "%d", $2 / 1024 * 0.8 }' /proc/meminfo)"

  # munge: the package's key, our own socket, pid and log files.
  [[ -s /etc/munge/munge.key ]] || { mkdir -p /etc/munge; mungekey --create --keyfile=/etc/munge/munge.key 2>/dev/null || create-munge-key -f; }
  chown munge:munge /etc/munge/munge.key 2>/dev/null || true
  chmod 400 /etc/munge/munge.key
  chown munge:munge "$dir/munge"
  chmod 755 "$dir/munge"
  local socket="$dir/munge/munge.socket"
  runuser -u munge -- munged --socket="$socket" --pid-file="$dir/munge/munged.pid" \
    --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munged.seed" \
    || die "munged did not start (see $dir/munge/munged.log)"

  cat > "$conf" <<CONF
ClusterName=vibrobed
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
SlurmctldPort=6817
SlurmdPort=6818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
MinJobAge=300
KillWait=5
Waittime=0
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF

  slurmctld -f "$conf" -i || die "slurmctld did not start (see $dir/slurmctld.log)"
  slurmd -f "$conf" || die "slurmd did not start (see $dir/slurmd.log)"
  for _ in $(seq 60); do
    if sinfo -h -o '%T' 2>/dev/null | grep -qE '^(idle|mixed|allocated)'; then
      echo "cluster.sh: up: $(sinfo -h -o '%P %D %T' | head -1)"
      echo "SLURM_CONF=$conf"
      return 0
    fi
    sleep 1
  done
  echo "--- sinfo"; sinfo 2>&1 || true
  echo "--- slurmctld.log"; tail -20 "$dir/slurmctld.log" 2>/dev/null || true
  echo "--- slurmd.log"; tail -20 "$dir/slurmd.log" 2>/dev/null || true
  die "the node did not come up within 60 s"
}

stop() {
  if [[ -f "$conf" ]] && command -v scancel >/dev/null; then
    scancel --quiet --user="$(id -un)" 2>/dev/null || true
  fi
  stop_pidfile "$dir/slurmd.pid"
  stop_pidfile "$dir/slurmctld.pid"
  stop_pidfile "$dir/munge/munged.pid"
  echo "cluster.sh: stopped"
}

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  status) sinfo ;;
  *) echo "usage: $0 start|stop|status" >&2; exit 2 ;;
esac
