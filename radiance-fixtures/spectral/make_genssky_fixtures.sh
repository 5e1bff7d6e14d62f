#!/usr/bin/env bash
# make_genssky_fixtures.sh: reference skies from REAL Radiance 6 genssky (issue 8) for
# tests/all/spectral_genssky.rs. Each case writes genssky_<name>.rad (its stdout, with the sky
# picture's path reduced to the file name) and genssky_<name>_sky.hsr (-r 48: 48 x 24
# pixels, 20 bands, about 24 kB). genssky precomputes its atmosphere tables (about a minute
# of CPU per climate/AOD) into a scratch folder that is deleted afterwards; its aerosol
# profile mie_ca.dat comes from RAYPATH and is NOT copied here.
#
# Usage: radiance-fixtures/spectral/make_genssky_fixtures.sh   (RADIANCE_BIN as in ../)
# Also writes genssky_manifest.tsv (case, wall-clock s on a shared machine, command).
set -euo pipefail
cd "$(dirname "$0")"
source ../find_radiance.sh genssky make_genssky_fixtures.sh
RES=48
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
# name | month day hour | options
CASES=(
	"boulder_mar|3 2 15.25|-a 42 -o 108 -m 110"
	"boulder_jun_aod03|6 21 12|-a 42 -o 108 -m 110 -d 0.3"
	"london_dec_c05|12 21 9.5|-a 51.5 -o 0.1 -m 0 -c 0.5"
	"london_jun_c1|6 21 10|-a 51.5 -o 0.1 -m 0 -c 1"
	"london_jun_L|6 21 10|-a 51.5 -o 0.1 -m 0 -L 80000 8000"
	"tropic_jan_y|1 15 11|-a 10 -o -80 -m -75 -y 2024"
)
printf 'case\twall_s\tcommand\n' >genssky_manifest.tsv
for c in "${CASES[@]}"; do
	IFS='|' read -r name when opts <<<"$c"
	# One scratch folder per case: genssky's cache name leaves out -g and rounds -d.
	mkdir -p "$WORK/$name"
	start=$(date +%s.%N)
	# shellcheck disable=SC2086
	genssky $when $opts -n 2 -r $RES -p "$WORK/$name" -f "$name" |
		grep -v '^# Pre-computing' |
		sed -e "s|^# .*genssky |# genssky |" -e "s|$WORK/$name/||g" >"genssky_$name.rad"
	end=$(date +%s.%N)
	cp "$WORK/$name/${name}_sky.hsr" "genssky_${name}_sky.hsr"
	printf '%s\t%.1f\t%s\n' "$name" "$(echo "$end - $start" | bc)" \
		"genssky $when $opts -n 2 -r $RES -f $name" >>genssky_manifest.tsv
	echo "$name done" >&2
done
