#!/bin/bash
# Starts a one-node Slurm cluster on this machine (as root): munged, slurmctld and slurmd with a
# generated configuration, key, state and logs in a temporary directory; runs COMMAND... with
# SLURM_CONF pointing at it (and FLIPSCOPE_SLURM=1); then stops exactly the daemons it started,
# by the PIDs they wrote, and removes the directory. Exits with COMMAND's status.
# CI: tests/farm/run-slurm.sh ctest --test-dir build -L slurm --output-on-failure
# Debian: slurm-wlm munge (.ci/install-deps). The controller schedules on every event
# (batch_sched_delay=0): with the default delay of 3 s each short task would wait that long.
set -eu
[ "$#" -gt 0 ] || { echo "usage: $0 COMMAND..." >&2; exit 2; }
for tool in munged slurmctld slurmd sbatch sinfo; do
  command -v "$tool" >/dev/null || { echo "run-slurm: $tool not found (Debian: slurm-wlm munge)" >&2; exit 2; }
done
dir=$(mktemp -d /tmp/flipscope-slurm.XXXXXX)
chmod 755 "$dir"
host=$(hostname -s)
stop() {
  for name in slurmd slurmctld munged; do
    [ -s "$dir/$name.pid" ] || continue
    pid=$(cat "$dir/$name.pid")
    kill "$pid" 2>/dev/null || continue
    i=0
    while kill -0 "$pid" 2>/dev/null && [ "$i" -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
    kill -9 "$pid" 2>/dev/null || true
  done
  rm -rf "$dir"
}
trap stop EXIT
trap 'exit 130' INT TERM

# munge: a random key of our own, a socket of our own.
mkdir -p "$dir/munge" "$dir/state" "$dir/spool"
dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
chmod 700 "$dir/munge"
chmod 400 "$dir/munge/munge.key"
munged --force --key-file="$dir/munge/munge.key" --socket="$dir/munge/socket" \
  --pid-file="$dir/munged.pid" --log-file="$dir/munged.log" --seed-file="$dir/munge/seed"

# Two TCP ports of our own: the first free pair from a PID-dependent start.
port_free() { ! (echo >"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
ctld_port=$((20000 + $$ % 20000))
while ! port_free "$ctld_port" || ! port_free $((ctld_port + 1)); do ctld_port=$((ctld_port + 2)); done
slurmd_port=$((ctld_port + 1))
cpus=$(nproc)
memory=$(awk '/MemTotal/ {print int($2 / 1024 * 0.9)}' /proc/meminfo)
cat >"$dir/slurm.conf" <<CONF
ClusterName=flipscope-test
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
AuthInfo=socket=$dir/munge/socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
SchedulerParameters=batch_sched_delay=0,sched_min_interval=0
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
MinJobAge=3600
KillWait=5
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$dir/slurm.conf"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
# The node is idle within seconds.
i=0
until sinfo -h -o %T 2>/dev/null | grep -q idle; do
  i=$((i + 1))
  if [ "$i" -gt 300 ]; then
    echo "run-slurm: the node did not come up; logs:" >&2
    tail -n 30 "$dir"/*.log >&2
    exit 1
  fi
  sleep 0.1
done
echo "run-slurm: one-node cluster up ($host, $cpus CPUs, ${memory} MB; SLURM_CONF=$SLURM_CONF)"
export FLIPSCOPE_SLURM=1
status=0
"$@" || status=$?
exit "$status"
