#!/usr/bin/env bash
# Time rspecsky against real gendaymtx on the full London IWEC year (8760 steps), MF 1 and
# MF 4, float output (-of) to a file: median of 3 runs of wall-clock and CPU (user + sys)
# seconds, and the ratio ours / gendaymtx. Not a test: numbers depend on the machine and
# its load. Usage: benches/rspecsky.sh [runs]   (RADIANCE_BIN overrides the pyradiance bin/)
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-3}
if [ -z "${RADIANCE_BIN:-}" ]; then
    root=$(python3 -c "import pyradiance,os;print(os.path.dirname(pyradiance.__file__))")
    RADIANCE_BIN=$root/bin
    export RAYPATH=${RAYPATH:-$root/lib}
fi
cargo build --release --quiet --bin rspecsky
ours=target/release/rspecsky
epw=examples/weather/GBR_London.Gatwick.037760_IWEC.epw
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# median WALL CPU of $runs runs of the given command (stdout to a scratch file)
measure() {
    for _ in $(seq "$runs"); do
        /usr/bin/time -f "%e %U %S" -o "$tmp/t" "$@" > "$tmp/out"
        awk '{printf "%s %.2f\n", $1, $2 + $3}' "$tmp/t"
    done | sort -n -k1,1 > "$tmp/w"
    wall=$(awk -v n="$runs" 'NR == int((n + 1) / 2) {print $1}' "$tmp/w")
    cpu=$(sort -n -k2,2 "$tmp/w" | awk -v n="$runs" 'NR == int((n + 1) / 2) {print $2}')
    echo "$wall $cpu"
}

printf "%-4s %-10s %8s %8s\n" MF program wall_s cpu_s
for mf in 1 4; do
    read -r rw rc < <(measure "$RADIANCE_BIN/gendaymtx" -m "$mf" -of "$epw")
    read -r ow oc < <(measure "$ours" -m "$mf" -of "$epw")
    printf "%-4s %-10s %8s %8s\n" "$mf" gendaymtx "$rw" "$rc"
    printf "%-4s %-10s %8s %8s\n" "$mf" rspecsky "$ow" "$oc"
    awk -v a="$ow" -v b="$rw" -v c="$oc" -v d="$rc" -v mf="$mf" 'BEGIN {
        printf "MF %s ratio rspecsky / gendaymtx: wall %.2f, cpu %.2f\n", mf,
            (b > 0 ? a / b : 0), (d > 0 ? c / d : 0) }'
done
echo "(median of $runs runs; $(nproc) cores; load $(cut -d' ' -f1-3 /proc/loadavg))"

# Point-in-time spectral skies (rspecsky genssky vs genssky, same sky, -r 128): the
# precomputation (fresh table folder each run, one run each: it takes about a minute) and a
# sky from cached tables (median of $runs runs).
echo
printf "%-22s %-10s %8s %8s\n" genssky_step program wall_s cpu_s
gs_args=(3 2 15.25 -a 42 -o 108 -m 110 -r 128 -n "$(nproc)")
for prog in genssky rspecsky; do
    if [ "$prog" = genssky ]; then cmd=("$RADIANCE_BIN/genssky"); else cmd=("$ours" genssky); fi
    rm -rf "$tmp/gs_$prog" && mkdir -p "$tmp/gs_$prog"
    /usr/bin/time -f "%e %U %S" -o "$tmp/t" "${cmd[@]}" "${gs_args[@]}" -p "$tmp/gs_$prog" > "$tmp/out"
    read -r pw pc < <(awk '{printf "%s %.2f\n", $1, $2 + $3}' "$tmp/t")
    printf "%-22s %-10s %8s %8s\n" precompute "$prog" "$pw" "$pc"
    read -r cw cc < <(measure "${cmd[@]}" "${gs_args[@]}" -p "$tmp/gs_$prog")
    printf "%-22s %-10s %8s %8s\n" "sky (cached tables)" "$prog" "$cw" "$cc"
done

# A year of physically based spectral sky matrices (MF 1, 20 bands, sun-up hours, float):
# rspecsky --model atmosphere against gensdaymtx on the same EPW. Both precompute atmosphere
# tables once per climate (London: summer and winter) and AOD; the first ("cold") run
# includes that, the second ("warm") reuses the tables. One run each (gensdaymtx takes
# minutes). gensdaymtx runs with -n $(nproc) threads for its precomputation. The EPW's
# per-record AODs (field 30) are set missing, so both use one AOD (0.115) and two table
# sets; with them, gensdaymtx would precompute one set per 0.01 of AOD (dozens, hours).
awk -F, -v OFS=, 'NR > 8 { $30 = 999 } 1' "$epw" > "$tmp/noaod.epw"
echo
printf "%-22s %-10s %8s %8s\n" "year_atmosphere" program wall_s cpu_s
for prog in gensdaymtx rspecsky; do
    if [ "$prog" = gensdaymtx ]; then
        cmd=("$RADIANCE_BIN/gensdaymtx" -n "$(nproc)" -u -m 1 -of -p "$tmp/gm_$prog")
    else
        cmd=("$ours" --model atmosphere -u -m 1 -of -l "${RAYPATH##*:}/mie_ca.dat" -p "$tmp/gm_$prog")
    fi
    rm -rf "$tmp/gm_$prog" && mkdir -p "$tmp/gm_$prog"
    for run in cold warm; do
        /usr/bin/time -f "%e %U %S" -o "$tmp/t" "${cmd[@]}" "$tmp/noaod.epw" > "$tmp/out" 2> "$tmp/err"
        read -r pw pc < <(awk '{printf "%s %.2f\n", $1, $2 + $3}' "$tmp/t")
        printf "%-22s %-10s %8s %8s\n" "year ($run tables)" "$prog" "$pw" "$pc"
    done
done
