#!/bin/bash
# Start a single-host Slurm (slurmctld + slurmd + munged, daemon mode: no systemd, works in a
# container) for examples/slurm and tests/all/slurm.rs (`make test` runs it first). Installs
# Debian's slurm-wlm and munge with apt-get when missing (as root, or through sudo when it
# needs no password). Everything (slurm.conf, munge key and socket, state, spool, logs, pid
# files) lives under $SLURM_HOME (default /tmp/rdaylight-slurm); clients find it through
#   export SLURM_CONF=$SLURM_HOME/slurm.conf
# Idempotent: when the node already answers, nothing is started. Stop with stop.sh.
# On failure the last line on standard error says why (`slurm: cannot start: ...`): the
# Slurm test repeats it as its failure message.
set -euo pipefail
SLURM_HOME=${SLURM_HOME:-/tmp/rdaylight-slurm}
export SLURM_CONF=$SLURM_HOME/slurm.conf

fail() {
    echo "slurm: cannot start: $*" >&2
    exit 1
}

if [ -f "$SLURM_CONF" ] && command -v sinfo >/dev/null &&
    timeout 5 sinfo -h -o %T 2>/dev/null | grep -Eq '^(idle|mixed|allocated)'; then
    echo "slurm: already running ($SLURM_CONF)"
    exit 0
fi

# The daemons run as root (slurmd starts jobs as their users; munged guards the key):
# without root, run this script through sudo when that needs no password.
if [ "$(id -u)" != 0 ]; then
    if command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
        exec sudo -n --preserve-env=SLURM_HOME bash "$0" "$@"
    fi
    fail "needs root (the daemons run as root) and sudo without a password is not available"
fi

if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null ||
    ! command -v munged >/dev/null || ! command -v sbatch >/dev/null; then
    command -v apt-get >/dev/null ||
        fail "slurm-wlm and munge are not installed and there is no apt-get to install them"
    echo "slurm: installing slurm-wlm and munge (apt-get)"
    # Packages' own services may try to start through systemd, absent in containers: the
    # installation succeeds anyway, and our daemons below use their own files and ports.
    if ! { apt-get update -q >/dev/null &&
        DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
            slurm-wlm munge >/dev/null; }; then
        fail "apt-get install slurm-wlm munge failed (network, or no Debian archive?)"
    fi
    for c in slurmctld slurmd munged sbatch sinfo; do
        command -v "$c" >/dev/null || fail "apt-get installed slurm-wlm and munge but $c is not on PATH"
    done
fi

mkdir -p "$SLURM_HOME"/{state,spool,log,run,munge} || fail "cannot create $SLURM_HOME"
# 755: clients of any user reach the socket; the key inside is readable by root only.
chmod 755 "$SLURM_HOME/munge"
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
        --seed-file="$SLURM_HOME/munge/munged.seed" ||
        fail "munged did not start (log: $SLURM_HOME/log/munged.log)"
    munge -n -S "$SOCKET" >/dev/null 2>&1 || fail "munged does not answer on $SOCKET"
fi

HOST=$(hostname -s)
[ -n "$HOST" ] || fail "hostname -s is empty"
# The node line as slurmd itself detects it (CPUs, sockets, cores, threads, memory), so
# the node is not drained for a mismatch; only the first line (the second is UpTime=).
# Addresses are given (127.0.0.1), so nothing depends on the host name resolving.
NODE=$(slurmd -C 2>/dev/null | head -n 1 | sed "s/^NodeName=[^ ]*/NodeName=$HOST NodeAddr=127.0.0.1/")
case $NODE in NodeName=*CPUs=*) ;; *) fail "slurmd -C did not describe this node: '$NODE'" ;; esac
# slurmd always initialises a cgroup plugin, and autodetection fails both where no cgroup
# file system is mounted (a bare chroot) and where cgroup2 is (most containers): 22.05's
# cgroup/v2 then wants systemd and dbus, and slurmd exits with "Unable to initialize cgroup
# plugin" (both measured with Debian 12's slurm-wlm 22.05.8). Nothing here uses cgroups,
# so: "disabled" where Slurm has it (24.05 and later), else cgroup/v1, which initialises
# without touching the hierarchy (measured with 22.05.8: slurmd starts and runs jobs with
# no cgroup file system, with cgroup2 mounted, and with v1 controllers).
VERSION=$(slurmd -V 2>/dev/null | awk '{print $2}')
MAJOR=${VERSION%%.*}
MINOR=${VERSION#*.}
MINOR=${MINOR%%.*}
if [[ $MAJOR =~ ^[0-9]+$ && $MINOR =~ ^[0-9]+$ ]] && ((10#$MAJOR * 100 + 10#$MINOR >= 2405)); then
    CGROUP=disabled
else
    CGROUP=cgroup/v1
fi
cat > "$SLURM_HOME/cgroup.conf" <<CONF
# Written by examples/slurm/start.sh for slurmd $VERSION: no cgroups (see start.sh).
CgroupPlugin=$CGROUP
CONF
cat > "$SLURM_CONF" <<CONF
# Written by examples/slurm/start.sh: one node, one partition, no cgroups, no accounting.
ClusterName=rdaylight
SlurmctldHost=$HOST(127.0.0.1)
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

# running NAME: the daemon of our pid file is alive (and is that daemon: a pid file left
# by a previous container may name a pid now reused by another program).
running() {
    local pid
    pid=$(cat "$SLURM_HOME/run/$1.pid" 2>/dev/null) || return 1
    [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = "$1" ]
}
running slurmctld || slurmctld -f "$SLURM_CONF" ||
    fail "slurmctld did not start (log: $SLURM_HOME/log/slurmctld.log)"
running slurmd || slurmd -f "$SLURM_CONF" ||
    fail "slurmd did not start (log: $SLURM_HOME/log/slurmd.log)"
for _ in $(seq 60); do
    if sinfo -h -o %T 2>/dev/null | grep -q '^idle'; then
        echo "slurm: node $HOST idle ($SLURM_CONF)"
        exit 0
    fi
    sleep 1
done
sinfo -N -l >&2 || true
tail -n 20 "$SLURM_HOME"/log/*.log >&2 || true
fail "node $HOST not idle after 60 s ($(sinfo -h -N -o '%T %E' 2>&1 | head -n 1); logs in $SLURM_HOME/log)"
