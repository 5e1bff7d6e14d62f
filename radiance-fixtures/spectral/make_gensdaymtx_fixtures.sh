#!/usr/bin/env bash
# make_gensdaymtx_fixtures.sh: reference spectral sky matrices from REAL Radiance 6
# gensdaymtx (issue 8) for tests/all/spectral_skymtx.rs. Each case cuts one day out of the
# bundled London IWEC EPW (header kept: gensdaymtx reads the site, AOD 0.206, total sky
# cover and the direct-normal / diffuse-horizontal illuminance fields) into
# gensdaymtx_<name>.epw and writes gensdaymtx_<name>.smx: `gensdaymtx -u -m 1 -of` (146
# patches x the day's sun-up hours x 20 bands, float, about 190 kB). gensdaymtx
# precomputes its atmosphere tables (minutes of CPU per climate/AOD) into a scratch folder
# that is deleted afterwards; both days share one climate (June, 51 deg N) and one AOD.
#
# Usage: radiance-fixtures/spectral/make_gensdaymtx_fixtures.sh   (RADIANCE_BIN as in ../)
set -euo pipefail
cd "$(dirname "$0")"
source ../find_radiance.sh gensdaymtx make_gensdaymtx_fixtures.sh
EPW=../../examples/weather/GBR_London.Gatwick.037760_IWEC.epw
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
# name | month | day   (June 28: mean sky cover 0.7/10 in daytime; June 8: 5/10)
CASES=("london_jun28|6|28" "london_jun08|6|8")
for c in "${CASES[@]}"; do
	IFS='|' read -r name mo da <<<"$c"
	awk -F, -v m="$mo" -v d="$da" 'NR <= 8 || ($2 == m && $3 == d)' "$EPW" >"gensdaymtx_$name.epw"
	start=$(date +%s)
	gensdaymtx -u -m 1 -of -n 2 -p "$WORK" "gensdaymtx_$name.epw" 2>"$WORK/log" >"$WORK/out" ||
		{ cat "$WORK/log" >&2; exit 1; }
	mv "$WORK/out" "gensdaymtx_$name.smx"
	echo "$name done in $(($(date +%s) - start)) s" >&2
done
