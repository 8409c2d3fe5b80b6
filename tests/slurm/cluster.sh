#!/usr/bin/env bash
# A single-node Slurm cluster for tests, in one folder, run as root:
#
#   tests/slurm/cluster.sh start DIR [OWNER_PID]
#                                      # munged, slurmctld and slurmd; waits until the node is idle;
#                                      # with OWNER_PID, a watchdog stops them once that process is gone,
#                                      # even if it was killed (a test's time-out)
#   tests/slurm/cluster.sh stop DIR    # stops the three daemons and waits until they are gone
#   tests/slurm/cluster.sh logs DIR    # prints the daemons' logs
#
# Everything lives in DIR: a fresh munge key and socket (a munged of the
# system, if any, is left alone), slurm.conf (clients find it through
# SLURM_CONF=DIR/slurm.conf), the controller's state, slurmd's spool, pid
# files and logs. The node is this machine as `slurmd -C` sees it (its CPUs
# and real memory). There is no systemd or cgroup here, so processes are
# tracked by process group (proctrack/pgid) and tasks are not confined
# (task/none). CPUs are consumable (select/cons_tres, CR_CPU), and the
# partition lets up to 8 jobs share a CPU (OverSubscribe=FORCE:8), so a job
# array of more tasks than CPUs runs all at once, as on a farm. Packages:
# slurmctld slurmd slurm-client munge (.ci/setup installs them).
set -euo pipefail

usage() { echo "usage: $0 start DIR [OWNER_PID] | stop DIR | logs DIR" >&2; exit 2; }
[ $# -eq 2 ] || { [ $# -eq 3 ] && [ "$1" = start ]; } || usage
action=$1
[ "$action" = start ] && mkdir -p "$2"
[ -d "$2" ] || exit 0   # stop or logs of a cluster whose folder is gone: nothing left
dir=$(cd "$2" && pwd)
owner=${3:-}
conf=$dir/slurm.conf
export SLURM_CONF=$conf

# A TCP port on 127.0.0.1 that nothing listens on, from FROM upwards.
free_port() {
  local p=$1
  while (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null; do p=$((p + 1)); done
  echo "$p"
}

# Stops the daemon of pid file $1 (TERM, then KILL after 20 s).
stop_daemon() {
  local pidfile=$1 pid i
  [ -s "$pidfile" ] || return 0
  pid=$(cat "$pidfile")
  if kill -0 "$pid" 2>/dev/null; then
    kill -TERM "$pid" 2>/dev/null || true
    for i in $(seq 200); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    if kill -0 "$pid" 2>/dev/null; then
      echo "cluster.sh: $(basename "$pidfile" .pid) (pid $pid) did not stop in 20 s: killing it" >&2
      kill -KILL "$pid" 2>/dev/null || true
    fi
  fi
  rm -f "$pidfile"
}

print_logs() {
  local f
  for f in "$dir"/log/*.log; do
    [ -f "$f" ] || continue
    echo "----- $f (last 60 lines)"
    tail -n 60 "$f"
  done
}

case $action in
start)
  for tool in munged slurmctld slurmd sinfo; do
    command -v "$tool" >/dev/null || { echo "cluster.sh: $tool is missing: run bash .ci/setup (it installs slurmctld slurmd slurm-client munge)" >&2; exit 1; }
  done
  mkdir -p "$dir/munge" "$dir/run" "$dir/log" "$dir/state" "$dir/spool"
  chmod 700 "$dir/munge"   # munged wants its key private,
  chmod 755 "$dir" "$dir/run"   # and its socket's folders searchable by all (DIR's parents too)
  head -c 1024 /dev/urandom > "$dir/munge/munge.key"
  chmod 400 "$dir/munge/munge.key"
  munged --key-file="$dir/munge/munge.key" --socket="$dir/run/munge.socket" \
    --pid-file="$dir/run/munged.pid" --log-file="$dir/log/munged.log" --seed-file="$dir/munge/munged.seed"

  host=$(hostname -s)
  # The node line as slurmd measures this machine, without its uptime.
  node=$(slurmd -C | head -n 1)
  case $node in NodeName=*) ;; *) echo "cluster.sh: slurmd -C printed no node line: $node" >&2; exit 1 ;; esac
  ctld_port=$(free_port 16817)
  slurmd_port=$(free_port $((ctld_port + 1)))
  cat > "$conf" <<EOF
# Written by tests/slurm/cluster.sh for one test run.
ClusterName=skybake-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/run/munge.socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/pgid
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
MailProg=/bin/true
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
SchedulerParameters=sched_interval=1
ReturnToService=2
# Finished jobs stay visible to scontrol for 10 minutes (there is no accounting database).
MinJobAge=600
KillWait=5
InactiveLimit=0
Waittime=0
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP OverSubscribe=FORCE:8
EOF
  sed -i 's/ UpTime=[^ ]*//' "$conf"
  slurmctld   # both fork into the background and write their pid files
  slurmd
  for i in $(seq 300); do
    state=$(sinfo -h -N -o '%t' 2>/dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.1
  done
  if [ "$state" != idle ]; then
    echo "cluster.sh: the node is not idle after 30 s (state: '${state}'): the daemons' logs follow" >&2
    print_logs >&2
    exit 1
  fi
  if [ -n "$owner" ]; then
    # Detached (its own session, not a child of the owner), so that killing
    # the owner's process tree leaves it to clean up.
    setsid bash -c 'while kill -0 "$1" 2>/dev/null; do sleep 1; done; exec bash "$2" stop "$3"' \
      watchdog "$owner" "$0" "$dir" </dev/null >>"$dir/log/watchdog.log" 2>&1 &
    echo $! > "$dir/run/watchdog.pid"
  fi
  echo "cluster.sh: Slurm up in $dir ($node), SLURM_CONF=$conf"
  ;;
stop)
  # Jobs first, so no task is left running without its slurmd.
  if [ -s "$dir/run/slurmctld.pid" ] && kill -0 "$(cat "$dir/run/slurmctld.pid")" 2>/dev/null; then
    scancel --full --signal=KILL --user=root 2>/dev/null || true
    scancel --user=root 2>/dev/null || true
    for i in $(seq 100); do [ -z "$(squeue -h -t running 2>/dev/null)" ] && break; sleep 0.1; done
  fi
  stop_daemon "$dir/run/slurmd.pid"
  stop_daemon "$dir/run/slurmctld.pid"
  stop_daemon "$dir/run/munged.pid"
  if [ -s "$dir/run/watchdog.pid" ]; then
    w=$(cat "$dir/run/watchdog.pid")
    rm -f "$dir/run/watchdog.pid"
    # The watchdog runs this stop itself: then it is this process.
    [ "$w" = "$$" ] || [ "$w" = "$PPID" ] || kill "$w" 2>/dev/null || true
  fi
  ;;
logs) print_logs ;;
*) usage ;;
esac
