#!/bin/bash
# The Slurm workflow end to end (what `make slurm-example` runs): start Slurm (start.sh),
# submit the coefficients as an array of N shards and the merge depending on it, wait for
# both (squeue; scontrol for the final state: there is no accounting database for sacct),
# print the room metrics, run the same coefficients unsharded here and compare dc.mtx byte
# for byte. Settings from the environment: N (3), OUT (out/slurm), RDC_OPTS, SENSORS,
# TIMEOUT (seconds, 1800), BIN (target/release). Exit status 0 only when the merge equals
# the single run.
set -euo pipefail
HERE=$(dirname "$0")
# shellcheck source=examples/slurm/jobs.sh
source "$HERE/jobs.sh"
# One date for every header: shards, merge and the single run then match byte for byte.
# Kept in $OUT/epoch so that resume.sh gives the shards it reruns the same dates.
export SOURCE_DATE_EPOCH=${SOURCE_DATE_EPOCH:-$(date +%s)}
bash "$HERE/start.sh"
export SLURM_CONF=${SLURM_HOME:-/tmp/rdaylight-slurm}/slurm.conf
mkdir -p "$OUT"
rm -f "$OUT"/dc.*.mtx "$OUT"/dc.*.json "$OUT"/dc.*.part "$OUT/dc.mtx" "$OUT/dc.single.mtx"
echo "$SOURCE_DATE_EPOCH" > "$OUT/epoch"
array=$(sbatch --parsable --array=0-$((N - 1)) --chdir="$PWD" --output="$OUT/%x.%A_%a.log" \
    --export=ALL "$HERE/coefficients.sbatch")
merge=$(sbatch --parsable --dependency=afterok:"$array" --kill-on-invalid-dep=yes \
    --chdir="$PWD" --output="$OUT/%x.%j.log" --export=ALL "$HERE/merge.sbatch")
echo "slurm: coefficients array job $array (N=$N shards), merge job $merge"
start=$(date +%s)
wait_jobs "$TIMEOUT" "$array" "$merge"
state=$(job_state "$merge")
echo "slurm: merge job $merge $state after $(($(date +%s) - start)) s"
if [ "$state" != COMPLETED ]; then
    tail -n 5 "$OUT"/*.log >&2 || true
    exit 1
fi
echo "Room means (occupied 8-18 h, every day), from the merged coefficients:"
grep -v '^#' "$OUT/metrics.tsv" | head -n 1
grep '^room' "$OUT/metrics.tsv"
# shellcheck disable=SC2086
"$BIN/rdc" -I $RDC_OPTS -m 1 -faf "$ROOM/room.rad" "$ROOM/skydome.rad" < "$SENSORS" > "$OUT/dc.single.mtx"
if cmp "$OUT/dc.mtx" "$OUT/dc.single.mtx"; then
    echo "slurm: merged dc.mtx of $N shards = single-run dc.mtx, byte for byte ($(wc -c < "$OUT/dc.mtx") bytes)"
else
    echo "slurm: merged dc.mtx differs from the single run" >&2
    exit 1
fi
