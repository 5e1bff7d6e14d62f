#!/bin/bash
# Stop the daemons examples/slurm/start.sh started (by their pid files only, and only when
# the pid still belongs to that daemon).
SLURM_HOME=${SLURM_HOME:-/tmp/rdaylight-slurm}
for d in slurmd slurmctld munged; do
    file=$SLURM_HOME/run/$d.pid
    pid=$(cat "$file" 2>/dev/null) || continue
    if [ "$(cat "/proc/$pid/comm" 2>/dev/null)" = "$d" ] && kill "$pid" 2>/dev/null; then
        # Wait for the daemon to exit, so a following start.sh finds its port free.
        for _ in $(seq 40); do kill -0 "$pid" 2>/dev/null || break; sleep 0.25; done
        echo "slurm: stopped $d ($pid)"
    fi
    rm -f "$file"
done
