#!/bin/bash
# Resume the workflow of run.sh after a failure (what `make slurm-resume` runs): check every
# shard in $OUT against its manifest (rmtx --verify: the SHARD= line, rows, size and the
# FNV-1a hash of the bytes rdc wrote), submit again only the array indices that are
# missing, incomplete or corrupt, then the merge after them, and wait. Finished shards are
# never recomputed (coefficients.sbatch also skips a complete shard, so a requeued or
# repeated task costs nothing). With every shard complete only the merge runs. Same
# settings as run.sh (N, OUT, BIN, RDC_OPTS, SENSORS, TIMEOUT) and the header dates run.sh
# used ($OUT/epoch). Exit status 0 when the merge completes and, if run.sh left the
# unsharded dc.single.mtx, equals it byte for byte.
set -euo pipefail
HERE=$(dirname "$0")
# shellcheck source=examples/slurm/jobs.sh
source "$HERE/jobs.sh"
if ! [ -d "$OUT" ]; then
    echo "slurm-resume: no $OUT: nothing to resume (run make slurm-example first)" >&2
    exit 1
fi
if [ -f "$OUT/epoch" ]; then
    SOURCE_DATE_EPOCH=$(cat "$OUT/epoch")
    export SOURCE_DATE_EPOCH
fi
bash "$HERE/start.sh"
export SLURM_CONF=${SLURM_HOME:-/tmp/rdaylight-slurm}/slurm.conf

todo=()
for ((k = 0; k < N; k++)); do
    if verdict=$(shard_complete "$k"); then
        echo "slurm-resume: $verdict"
    else
        echo "slurm-resume: ${verdict:-$OUT/dc.$k.mtx: no verdict}; submitting shard $k again"
        todo+=("$k")
    fi
done
rm -f "$OUT/dc.mtx"
deps=()
if [ ${#todo[@]} -gt 0 ]; then
    list=$(IFS=,; echo "${todo[*]}")
    array=$(sbatch --parsable --array="$list" --chdir="$PWD" --output="$OUT/%x.%A_%a.log" \
        --export=ALL "$HERE/coefficients.sbatch")
    deps=(--dependency=afterok:"$array" --kill-on-invalid-dep=yes)
    echo "slurm-resume: shards ${todo[*]} of $N resubmitted as array job $array"
else
    echo "slurm-resume: all $N shards complete; only the merge runs"
fi
merge=$(sbatch --parsable "${deps[@]}" --chdir="$PWD" --output="$OUT/%x.%j.log" \
    --export=ALL "$HERE/merge.sbatch")
start=$(date +%s)
wait_jobs "$TIMEOUT" ${array:+"$array"} "$merge"
state=$(job_state "$merge")
echo "slurm-resume: merge job $merge $state after $(($(date +%s) - start)) s"
if [ "$state" != COMPLETED ]; then
    tail -n 5 "$OUT"/*.log >&2 || true
    exit 1
fi
grep '^room' "$OUT/metrics.tsv"
if [ -f "$OUT/dc.single.mtx" ]; then
    if cmp "$OUT/dc.mtx" "$OUT/dc.single.mtx"; then
        echo "slurm-resume: merged dc.mtx = single-run dc.mtx, byte for byte"
    else
        echo "slurm-resume: merged dc.mtx differs from the single run" >&2
        exit 1
    fi
fi
