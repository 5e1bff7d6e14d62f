#!/usr/bin/env bash
# Peak memory (max RSS, /usr/bin/time -v's "Maximum resident set size") of every step of
# the main job (`make`, the Makefile's `example` target, same commands and options), then
# rmtx against real dctimestep at MF 4 on the same inputs (165 sensors x 2306 patches,
# 2306 x 8760 sky). One run each: peak memory does not depend on the machine's load, the
# seconds beside it do (wall, and CPU = user + sys). Not a test.
# Usage: benches/memory.sh            (RADIANCE_BIN overrides the pyradiance bin/;
#        RDC_OPTS the main job's rdc settings, as in the Makefile)
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -z "${RADIANCE_BIN:-}" ]; then
    root=$(python3 -c "import pyradiance,os;print(os.path.dirname(pyradiance.__file__))")
    RADIANCE_BIN=$root/bin
    export RAYPATH=${RAYPATH:-.:$root/lib}
fi
[ -x /usr/bin/time ] || { echo "benches/memory.sh: needs /usr/bin/time (Debian package 'time')"; exit 1; }
cargo build --release --quiet --bins
bin=${CARGO_TARGET_DIR:-target}/release
room=examples/room
epw=examples/weather/GBR_London.Gatwick.037760_IWEC.epw
pts=$room/sensors.pts
rdc_opts=${RDC_OPTS:--ab 5 -ad 10000 -lw 1e-5 -s 1}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# step NAME OUT CMD...: run CMD (stdout to OUT) under /usr/bin/time and print one row.
step() {
    local name=$1 out=$2
    shift 2
    /usr/bin/time -f "%M %e %U %S" -o "$tmp/t" "$@" > "$out"
    awk -v n="$name" '{printf "%-34s %9.1f %8.2f %8.2f\n", n, $1 / 1024, $2, $3 + $4}' "$tmp/t" \
        | tee -a "$tmp/rows"
}

echo "main job (make):"
printf "%-34s %9s %8s %8s\n" step peak_MB wall_s cpu_s
step "rinfo (inputs)" /dev/null "$bin/rinfo" $room/room.rad $pts $epw
# shellcheck disable=SC2086 # rdc_opts is a list of options
step "rdc -m 1 (sky coefficients)" "$tmp/dc.mtx" \
    "$bin/rdc" -I $rdc_opts -m 1 -faf $room/room.rad $room/skydome.rad < $pts
step "rdc --suns 6 (sun coefficients)" "$tmp/sun.mtx" \
    "$bin/rdc" -I --suns 6 -ad 1 -faf $room/room.rad $room/skydome.rad < $pts
step "rspecsky -m 1 (sky matrix)" "$tmp/sky.smx" "$bin/rspecsky" -m 1 -of $epw
step "rspecsky -m 6 -5 0.533 -d (suns)" "$tmp/sky_sun.smx" "$bin/rspecsky" -m 6 -5 0.533 -d -of $epw
step "rmtx dc x sky (illuminance)" "$tmp/ill.mtx" \
    "$bin/rmtx" -ff -c 47.4 119.9 11.6 "$tmp/dc.mtx" "$tmp/sky.smx"
step "rmtx sun x suns (direct sun)" "$tmp/direct_sun.mtx" \
    "$bin/rmtx" -ff -c 47.4 119.9 11.6 "$tmp/sun.mtx" "$tmp/sky_sun.smx"
rm -f "$tmp/sky_sun.smx"
step "rmetrics (metrics)" /dev/null "$bin/rmetrics" -w $epw --pts $pts \
    --direct-sun "$tmp/direct_sun.mtx" --json "$tmp/metrics.json" -o "$tmp/metrics.tsv" "$tmp/ill.mtx"
step "rmetrics --map ASE (one of 5 maps)" /dev/null "$bin/rmetrics" -w $epw --pts $pts \
    --direct-sun "$tmp/direct_sun.mtx" --map ASE --png "$tmp/ASE.png" "$tmp/ill.mtx"
echo "whole job: peak $(awk '{print $(NF - 2)}' "$tmp/rows" | sort -g | tail -n 1) MB"
echo "room: $(grep '^room' "$tmp/metrics.tsv")"

# MF 4: coefficients at the main job's settings (how many are zero sets the product's
# work, not its memory), the sky from rspecsky (gendaymtx's format); both products read
# the same two files.
echo
echo "matrix product at MF 4 (165 x 2306 x 3 coefficients, 2306 x 8760 x 3 sky, float):"
printf "%-34s %9s %8s %8s\n" program peak_MB wall_s cpu_s
# shellcheck disable=SC2086
"$bin/rdc" -I $rdc_opts -m 4 -faf $room/room.rad $room/skydome.rad < $pts > "$tmp/dc4.mtx"
"$bin/rspecsky" -m 4 -of $epw > "$tmp/sky4.smx"
step "dctimestep dc4 sky4 (Radiance)" "$tmp/ill4_radiance.mtx" \
    "$RADIANCE_BIN/dctimestep" -of "$tmp/dc4.mtx" "$tmp/sky4.smx"
step "rmtx dc4 sky4" "$tmp/ill4.mtx" "$bin/rmtx" -ff "$tmp/dc4.mtx" "$tmp/sky4.smx"
echo "($(nproc) cores; load $(cut -d' ' -f1-3 /proc/loadavg); $(uname -srm))"
