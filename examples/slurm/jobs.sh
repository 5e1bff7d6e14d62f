#!/bin/bash
# Shared by run.sh and resume.sh (sourced): wait for Slurm jobs without an accounting
# database (squeue while they are known, scontrol for the final state: sacct needs one),
# and the settings both take from the environment, with their defaults.

N=${N:-3}
OUT=${OUT:-out/slurm}
BIN=${BIN:-target/release}
ROOM=${ROOM:-examples/room}
SENSORS=${SENSORS:-$ROOM/sensors.pts}
RDC_OPTS=${RDC_OPTS:--ab 5 -ad 10000 -lw 1e-5 -s 1}
TIMEOUT=${TIMEOUT:-1800}
export N OUT BIN ROOM SENSORS RDC_OPTS

# wait_jobs TIMEOUT JOB...: wait until none of the jobs is queued or running; after TIMEOUT
# seconds cancel them and fail.
wait_jobs() {
    local timeout=$1 start ids
    shift
    ids=$(IFS=,; echo "$*")
    start=$(date +%s)
    while [ -n "$(squeue -h -j "$ids" 2>/dev/null)" ]; do
        if (($(date +%s) - start > timeout)); then
            echo "slurm: jobs $ids not done after $timeout s; cancelling" >&2
            scancel "$@" || true
            return 1
        fi
        sleep 2
    done
}

# job_state JOB: COMPLETED, FAILED, CANCELLED, ... (scontrol keeps finished jobs for
# MinJobAge seconds: start.sh sets 600).
job_state() {
    scontrol show job "$1" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | head -n 1 | cut -d= -f2
}

# shard_complete K: dc.K.mtx in $OUT is complete and matches its manifest dc.K.json (rmtx
# --verify: SHARD= line, rows, size, FNV-1a hash of the bytes rdc wrote). Prints the
# verdict line.
shard_complete() {
    "$BIN/rmtx" --verify "$OUT/dc.$1.mtx" --manifests "$OUT/dc.$1.json" 2>/dev/null
}
