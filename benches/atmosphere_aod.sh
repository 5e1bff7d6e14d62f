#!/usr/bin/env bash
# How much the AOD interpolation of `rspecsky --model atmosphere` costs in accuracy, and
# what it saves in time. A weather file's per-record aerosol optical depths are not given
# tables of their own: each record's column is interpolated between the tables of the two
# bracketing AOD_NODES (crates/physics/src/sky/atmosphere_matrix.rs). For AODs half-way
# between nodes (the worst place for an interpolation) this compares the interpolated matrix
# (the AOD written into the EPW) with the exact one (`--aod`, the value's own tables) on
# five London June days, and prints per AOD the largest relative difference of the
# patch-summed sky+sun radiance per band over the steps brighter than 1 % of the brightest,
# and the 95th percentile over patches x bands x steps of the per-patch difference.
# Then the cold time of a whole London year with its real AOD column (empty table cache).
# Usage: benches/atmosphere_aod.sh     (about 10 table sets of ~20 CPU-s each, cached in a
# scratch folder that is removed at the end)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet --bin rspecsky
ours=$PWD/target/release/rspecsky
epw=examples/weather/GBR_London.Gatwick.037760_IWEC.epw
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export XDG_CACHE_HOME=$tmp/cache

# June 8-12, every record's AOD (field 30) set to $1.
days() {
    awk -F, -v OFS=, -v aod="$1" 'NR <= 8 { print; next }
        $2 == 6 && $3 >= 8 && $3 <= 12 { $30 = aod; print }' "$epw"
}

printf "%-6s %-12s %26s %22s\n" AOD matrix "max band sum diff (%)" "p95 patch diff (%)"
for a in 0.025 0.075 0.15 0.25 0.4; do
    days "$a" > "$tmp/d.epw"
    "$ours" --model atmosphere -u -m 1 -of "$tmp/d.epw" > "$tmp/interp.smx"
    "$ours" --model atmosphere -u -m 1 --aod "$a" -of "$tmp/d.epw" > "$tmp/exact.smx"
    python3 - "$tmp/interp.smx" "$tmp/exact.smx" "$a" <<'EOF'
import sys, numpy as np
def load(p):
    b = open(p, 'rb').read()
    head, _, body = b.partition(b'\n\n')
    h = dict(l.split('=', 1) for l in head.decode().splitlines() if '=' in l)
    nr, nc, nk = int(h['NROWS']), int(h['NCOLS']), int(h['NCOMP'])
    return np.frombuffer(body, dtype='<f4').reshape(nr, nc, nk).astype(float)
i, e, a = load(sys.argv[1]), load(sys.argv[2]), sys.argv[3]
band_i, band_e = i[1:].sum(0), e[1:].sum(0)          # steps x bands, sky rows only
tot = band_e.sum(1)
keep = tot > 0.01 * tot.max()
rel = np.abs(band_i[keep] - band_e[keep]) / np.maximum(band_e[keep], 1e-30)
pe = e[1:, keep]
bright = pe > 1e-3 * pe.max()
prel = np.abs(i[1:, keep] - pe)[bright] / pe[bright]
print(f"{a:6s} {'interpolated':12s} {100 * rel.max():26.3f} {100 * np.percentile(prel, 95):22.3f}")
EOF
done

# Cold year: London's real AOD column (0.04-0.21), empty table cache.
rm -rf "$XDG_CACHE_HOME"
/usr/bin/time -f "%e %U %S" -o "$tmp/t" "$ours" --model atmosphere -m 1 -of "$epw" > "$tmp/year.smx"
read -r w u s < "$tmp/t"
sets=$(ls "$XDG_CACHE_HOME"/rdaylight/atmos_data | wc -l)
echo "cold London year with its AOD column: $sets table sets, wall $w s, CPU $(echo "$u + $s" | bc) s"
echo "($(nproc) cores; load $(cut -d' ' -f1-3 /proc/loadavg))"
