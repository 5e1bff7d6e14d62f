#!/usr/bin/env bash
# five_phase.sh: the five-phase result of `make shading-example` (examples/shading/: the
# example room, venetian blinds in its opening) computed by real Radiance alone, three
# independent runs, for tests/all/shading.rs to compare our five-phase chain with.
#
# The chain (Subramaniam 2017, "Daylighting simulations with Radiance using matrix-based
# methods"; the same terms as the Makefile's shading-example, whose rdc --flux / rdc --suns
# runs stand beside these rfluxmtx / rcontrib ones):
#   E5 = V T D s  -  Vd T Dd sd  +  Cds ssun
#   V, D    rfluxmtx, the lit room (materials.rad), window.rad as the Klems sender/receiver
#   Vd, Dd  rfluxmtx, the black room (materials_black.rad), -ab 1 for Vd, -ab 0 for Dd
#   T       tests/data/bsdf/blinds45.xml (dctimestep reads the Klems XML itself)
#   Cds     rcontrib, one `light` sun per MF 6 patch centre (reinsrc.cal with x1 = x2 = 0.5,
#           0.533 degrees), the black room with the slats as geometry (they keep their
#           reflectance), -ab 3: the sun through the slats, as the example's rdc --suns 6
#           --suns-ab run
#   s, sd, ssun  gendaymtx -A: the year's average sky (so every product is the annual mean
#           illuminance, a linear stand-in for the year: E summed over the hours = 8760 x
#           E of the average sky), total MF 1, sun only MF 1 (-d), sun only MF 6 (-5 0.533 -d)
# Only the suns the year's sky lights (non-zero rows of ssun) are traced: the others are
# multiplied by zero.
#
# Radiance has no seed option: run k prepends 7k copies of the first sensor to the sensor
# list (their rows dropped) and D / Dd use -c 250+k rays per patch, which reshuffles every
# sample (as tests/all/rdc_flux.rs). Settings are the Makefile's except D's -c (1000 there):
# one D at -c 1000 takes about 6 minutes here; the per-sensor totals average over D's
# entries, and the runs' own spread is what the test allows on top of its 2 % / 5 %.
#
# Writes five_phase/suns_m6_A.smx (ssun, read by the test for our Cds) and
# five_phase/radiance.tsv: per sensor, per run k, the photopic illuminance in lux
# (47.4 R + 119.9 G + 11.6 B) of each term: v3_k = V T D s, vd_k = Vd T Dd sd,
# cds_k = Cds ssun; the five-phase value is v3 - vd + cds.
#
# Usage: radiance-fixtures/shading/five_phase.sh   (about 20 CPU minutes)
set -euo pipefail
cd "$(dirname "$0")"
source ../find_radiance.sh rfluxmtx five_phase.sh
EX=../../examples/shading
SKYDOME=../../examples/room/skydome.rad
SENSORS=../../examples/room/sensors.pts
EPW=../../examples/weather/GBR_London.Gatwick.037760_IWEC.epw
T=../../tests/data/bsdf/blinds45.xml
LIT="$EX/materials.rad $EX/geometry.rad"
BLACK="$EX/materials_black.rad $EX/geometry.rad"
OUT=five_phase
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
mkdir -p "$OUT"

# Skies: the year's average, total and sun only at MF 1, the sun alone at MF 6.
gendaymtx -m 1 -A -of "$EPW" > "$W/s.smx"
gendaymtx -m 1 -A -d -of "$EPW" > "$W/sd.smx"
gendaymtx -m 6 -5 0.533 -d -A -of "$EPW" > "$OUT/suns_m6_A.smx"

# The lit suns: row b of ssun (b = 0 the ground) is MF 6 patch b; one light source each.
rmtxop -fa "$OUT/suns_m6_A.smx" | sed '1,/^$/d' \
	| awk '$1 + $2 + $3 > 0 {print NR - 1, $1, $2, $3}' > "$W/lit.txt"
NSUN=$(wc -l < "$W/lit.txt")
awk '{print $1}' "$W/lit.txt" | rcalc -e MF:6 -f reinsrc.cal -e 'Rbin=$1' \
	-o $'void light solar${Rbin} 0 0 3 1 1 1\nsolar${Rbin} source sun${Rbin} 0 0 4 ${Dx} ${Dy} ${Dz} 0.533' \
	> "$W/suns.rad"
awk '{print "solar" $1}' "$W/lit.txt" > "$W/suns.mod"
{
	printf '#?RADIANCE\nNROWS=%d\nNCOLS=1\nNCOMP=3\nFORMAT=ascii\n\n' "$NSUN"
	awk '{print $2, $3, $4}' "$W/lit.txt"
} > "$W/ssun.mtx"
oconv $BLACK "$EX/blinds.rad" "$W/suns.rad" > "$W/cds.oct"

# Photopic illuminance per sensor of a coefficient product, the k x 7 padding rows dropped.
lux() { rmtxop -fa -c 47.4 119.9 11.6 - | sed '1,/^$/d' | awk -v skip="$1" 'NR > skip {print $1}'; }

for k in 0 1 2; do
	{ for ((i = 0; i < 7 * k; i++)); do head -1 "$SENSORS"; done; cat "$SENSORS"; } > "$W/pts"
	c=$((250 + k))
	rfluxmtx -I+ -ab 5 -ad 10000 -lw 1e-5 -faf - "$EX/window.rad" $LIT < "$W/pts" > "$W/V.mtx"
	rfluxmtx -ab 2 -ad 1000 -lw 1e-4 -c $c -faf "$EX/window.rad" "$SKYDOME" $LIT > "$W/D.mtx"
	rfluxmtx -I+ -ab 1 -ad 10000 -lw 1e-5 -faf - "$EX/window.rad" $BLACK < "$W/pts" > "$W/Vd.mtx"
	rfluxmtx -ab 0 -c $c -faf "$EX/window.rad" "$SKYDOME" $BLACK > "$W/Dd.mtx"
	rcontrib -I+ -ab 3 -ad 256 -lw 1e-4 -faf -M "$W/suns.mod" "$W/cds.oct" < "$W/pts" > "$W/cds.mtx"
	dctimestep "$W/V.mtx" "$T" "$W/D.mtx" "$W/s.smx" | lux $((7 * k)) > "$W/v3_$k"
	dctimestep "$W/Vd.mtx" "$T" "$W/Dd.mtx" "$W/sd.smx" | lux $((7 * k)) > "$W/vd_$k"
	dctimestep "$W/cds.mtx" "$W/ssun.mtx" | lux $((7 * k)) > "$W/cds_$k"
	echo "five_phase.sh: run $k done ($NSUN suns)" >&2
done
{
	echo "# Real Radiance ($(rtrace -version)) five-phase terms of examples/shading, by radiance-fixtures/shading/five_phase.sh:"
	echo "# photopic illuminance (lux) under the year's average sky, per sensor of examples/room/sensors.pts; $NSUN lit MF 6 suns"
	printf 'sensor'
	for k in 0 1 2; do printf '\tv3_%d\tvd_%d\tcds_%d' $k $k $k; done
	printf '\n'
	paste <(seq 0 $(($(wc -l < "$SENSORS") - 1))) "$W"/v3_0 "$W"/vd_0 "$W"/cds_0 \
		"$W"/v3_1 "$W"/vd_1 "$W"/cds_1 "$W"/v3_2 "$W"/vd_2 "$W"/cds_2
} > "$OUT/radiance.tsv"
