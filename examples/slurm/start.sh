#!/bin/bash
# Start a single-host Slurm (slurmctld + slurmd + munged, daemon mode: no systemd, works in a
# container) for examples/slurm. Installs Debian's slurm-wlm and munge with apt-get when
# missing. Everything (slurm.conf, munge key and socket, state, spool, logs, pid files) lives
# under $SLURM_HOME (default /tmp/rdaylight-slurm); clients find it through
#   export SLURM_CONF=$SLURM_HOME/slurm.conf
# Idempotent: when the node already answers, nothing is started. Stop with stop.sh.
set -euo pipefail
SLURM_HOME=${SLURM_HOME:-/tmp/rdaylight-slurm}
export SLURM_CONF=$SLURM_HOME/slurm.conf

if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null; then
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y slurm-wlm munge
fi

if [ -f "$SLURM_CONF" ] && timeout 5 sinfo -h -o %T 2>/dev/null | grep -Eq '^(idle|mixed|allocated)'; then
    echo "slurm: already running ($SLURM_CONF)"
    exit 0
fi

mkdir -p "$SLURM_HOME"/{state,spool,log,run,munge}
chmod 700 "$SLURM_HOME/munge"
# munge: our own key and socket, so no system munge set-up is needed or touched.
if [ ! -s "$SLURM_HOME/munge/munge.key" ]; then
    dd if=/dev/urandom of="$SLURM_HOME/munge/munge.key" bs=1024 count=1 status=none
    chmod 400 "$SLURM_HOME/munge/munge.key"
fi
SOCKET=$SLURM_HOME/munge/munge.socket
if ! [ -S "$SOCKET" ] || ! munge -n -S "$SOCKET" >/dev/null 2>&1; then
    rm -f "$SOCKET" "$SOCKET.lock"
    # --force: munged refuses to run as root or with a key outside /etc without it.
    munged --force --key-file="$SLURM_HOME/munge/munge.key" --socket="$SOCKET" \
        --pid-file="$SLURM_HOME/run/munged.pid" --log-file="$SLURM_HOME/log/munged.log" \
        --seed-file="$SLURM_HOME/munge/munged.seed"
fi

HOST=$(hostname -s)
# The node line as slurmd itself detects it (CPUs, sockets, cores, threads, memory), so
# the node is not drained for a mismatch; only the first line (the second is UpTime=).
NODE=$(slurmd -C | head -n 1 | sed "s/^NodeName=[^ ]*/NodeName=$HOST/")
cat > "$SLURM_CONF" <<CONF
# Written by examples/slurm/start.sh: one node, one partition, no cgroups, no accounting.
ClusterName=rdaylight
SlurmctldHost=$HOST
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$SOCKET
CredType=cred/munge
SlurmctldPort=6817
SlurmdPort=6818
StateSaveLocation=$SLURM_HOME/state
SlurmdSpoolDir=$SLURM_HOME/spool
SlurmctldPidFile=$SLURM_HOME/run/slurmctld.pid
SlurmdPidFile=$SLURM_HOME/run/slurmd.pid
SlurmctldLogFile=$SLURM_HOME/log/slurmctld.log
SlurmdLogFile=$SLURM_HOME/log/slurmd.log
# Containers: no cgroup hierarchy to manage, so track processes by /proc and bind nothing.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
# Keep finished jobs visible to scontrol for 10 minutes (no accounting database for sacct).
MinJobAge=600
$NODE State=UNKNOWN
PartitionName=main Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF

if ! [ -f "$SLURM_HOME/run/slurmctld.pid" ] || ! kill -0 "$(cat "$SLURM_HOME/run/slurmctld.pid")" 2>/dev/null; then
    slurmctld -f "$SLURM_CONF"
fi
if ! [ -f "$SLURM_HOME/run/slurmd.pid" ] || ! kill -0 "$(cat "$SLURM_HOME/run/slurmd.pid")" 2>/dev/null; then
    slurmd -f "$SLURM_CONF"
fi
for _ in $(seq 60); do
    if sinfo -h -o %T 2>/dev/null | grep -q '^idle'; then
        echo "slurm: node $HOST idle ($SLURM_CONF)"
        exit 0
    fi
    sleep 1
done
echo "slurm: node $HOST not idle after 60 s; logs in $SLURM_HOME/log" >&2
sinfo -N -l >&2 || true
tail -n 20 "$SLURM_HOME"/log/*.log >&2 || true
exit 1
