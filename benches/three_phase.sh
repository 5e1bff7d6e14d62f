#!/usr/bin/env bash
# The three-phase product V T D s for a year: rmtx against real dctimestep on the same
# inputs (the shading example's V: 165 sensors x 145 Klems patches, T: the blinds' BSDF XML,
# D: 145 x 146 sky patches, a London year: 146 x 8760), float output. Runs them alternately,
# RUNS times each (default 5), under /usr/bin/time, and prints the medians of CPU seconds
# (user + sys), wall seconds and peak memory, and the CPU ratio. Not a test.
# Usage: benches/three_phase.sh   (after `make shading-example`; RADIANCE_BIN overrides the
#        pyradiance bin/)
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -z "${RADIANCE_BIN:-}" ]; then
    root=$(python3 -c "import pyradiance,os;print(os.path.dirname(pyradiance.__file__))")
    RADIANCE_BIN=$root/bin
    export RAYPATH=${RAYPATH:-.:$root/lib}
fi
[ -x /usr/bin/time ] || { echo "benches/three_phase.sh: needs /usr/bin/time (Debian package 'time')"; exit 1; }
bin=${CARGO_TARGET_DIR:-target}/release
o=${OUT:-out}/shading
for f in V.mtx D.mtx sky.smx; do
    [ -f "$o/$f" ] || { echo "benches/three_phase.sh: no $o/$f: run 'make shading-example' first"; exit 1; }
done
t=tests/data/bsdf/blinds45.xml
runs=${RUNS:-5}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for i in $(seq "$runs"); do
    /usr/bin/time -f "%e %U %S %M" -a -o "$tmp/ours" "$bin/rmtx" -ff "$o/V.mtx" "$t" "$o/D.mtx" "$o/sky.smx" > /dev/null
    /usr/bin/time -f "%e %U %S %M" -a -o "$tmp/theirs" "$RADIANCE_BIN/dctimestep" -of "$o/V.mtx" "$t" "$o/D.mtx" "$o/sky.smx" > /dev/null
done
median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
row() {
    local f=$1
    printf "%-12s cpu %6.3f s   wall %6.3f s   peak %6.1f MB\n" "$2" \
        "$(awk '{print $2+$3}' "$f" | median)" "$(awk '{print $1}' "$f" | median)" \
        "$(awk '{print $4/1024}' "$f" | median)"
}
echo "V T D s for a year ($runs runs each, alternating, medians; load average $(cut -d' ' -f1-3 /proc/loadavg))"
row "$tmp/ours" "rmtx"
row "$tmp/theirs" "dctimestep"
awk -v a="$(awk '{print $2+$3}' "$tmp/ours" | median)" -v b="$(awk '{print $2+$3}' "$tmp/theirs" | median)" \
    'BEGIN {printf "dctimestep / rmtx CPU: %.2fx\n", b / a}'
