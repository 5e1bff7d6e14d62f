#!/usr/bin/env bash
# make_calib_fixtures.sh: per-step illuminance truths for rcalib's forward model (issue 22),
# made by REAL Radiance. For each time step of steps.wea (London Gatwick site; clear,
# intermediate, overcast and faint-sun skies, see README.md): gendaylit with the step's
# direct-normal and diffuse-horizontal irradiance (-W), the sky and ground glow of
# ../skies/skyglow.rad, each scene of SCENES (office: ../scenes/office.rad, the example
# office with its 46 x 20 m exterior ground polygon; office_open: the same without it,
# written here as office_open.rad, so that the sensors see gendaylit's ground glow through
# the window as in models without an exterior ground), then rtrace -I for the 8 sensors of
# sensors.pts at converged settings, twice: run 2 is made independent of run 1
# by one cheap dummy ray first (a sensor high above the room looking at the sky: it only
# moves the random sequence on), which the script drops. Radiance has no seed option.
#
# Outputs (small, committed):
#   truth.tsv      scene, step, month, day, hour, dni, dhi, sensor, lux_run1, lux_run2
#                  (lux = 179 (0.265 R + 0.670 G + 0.065 B), rmtxop -c 47.4 119.9 11.6)
#   gendaylit.tsv  step, epsilon, delta, A1 (diffuse normalisation), A2 (ground), solar
#                  radiance, as gendaylit printed them
#   VERSION        rtrace -version
# Usage: radiance-fixtures/calib/make_calib_fixtures.sh   (AD=131072, SCENES="office
#   office_open" by default; about 25 CPU-minutes per scene)
#   RADIANCE_BIN=/path/to/radiance/bin  optional; RAYPATH defaults to ../lib beside it.
set -euo pipefail
cd "$(dirname "$0")/.."

source find_radiance.sh rtrace make_calib_fixtures.sh

OUT=calib
WORK=${KEEP:-$(mktemp -d)}
[[ -n ${KEEP:-} ]] || trap 'rm -rf "$WORK"' EXIT
AD=${AD:-131072}
# -aa 0 -as 0: pure Monte Carlo (radiance-notes 12.14: -as reads low); -ab 12 with -lw 1e-6
# costs the same as -ab 8 here (roulette ends the paths) and leaves no truncation bias.
OPTS="-h -I -ab 12 -ad $AD -aa 0 -as 0 -lw 1e-6"
DUMMY="3 -50 100 0 0 1"
SCENES=${SCENES:-office office_open}
awk '/^# --- exterior ground/ {skip = 1} !skip' scenes/office.rad > $OUT/office_open.rad

LAT=$(awk '$1 == "latitude" {print $2}' $OUT/steps.wea)
LON=$(awk '$1 == "longitude" {print $2}' $OUT/steps.wea)   # degrees west, as gendaylit -o
TZ=$(awk '$1 == "time_zone" {print $2}' $OUT/steps.wea)     # meridian, degrees west

printf 'scene\tstep\tmonth\tday\thour\tdni\tdhi\tsensor\tlux_run1\tlux_run2\n' > $WORK/truth.tsv
printf 'step\tepsilon\tdelta\tA1\tA2\tsolar\n' > $WORK/gendaylit.tsv
n=0
tail -n +7 $OUT/steps.wea | while read -r m d h dn df; do
	n=$((n + 1))
	gendaylit $m $d $h -a $LAT -o $LON -m $TZ -W $dn $df > $WORK/s$n.sky
	eps=$(awk '/epsilon, delta/ {print $(NF-2), $(NF-1)}' $WORK/s$n.sky)
	solar=$(awk '/^void light solar/ {getline; getline; getline; print $2}' $WORK/s$n.sky)
	args=$(awk '/^2 skybright perezlum.cal/ {getline; getline; print $2, $3}' $WORK/s$n.sky)
	printf '%s\t%s\t%s\t%s\t%s\t%s\n' $n $eps $args $solar | tr ' ' '\t' >> $WORK/gendaylit.tsv
	cat skies/skyglow.rad >> $WORK/s$n.sky
	for scene in $SCENES; do
		file=scenes/$scene.rad
		[[ -f $file ]] || file=$OUT/$scene.rad
		oconv $file $WORK/s$n.sky > $WORK/s$n.oct
		rtrace $OPTS $WORK/s$n.oct < $OUT/sensors.pts > $WORK/r1
		{ echo "$DUMMY"; cat $OUT/sensors.pts; } | rtrace $OPTS $WORK/s$n.oct | tail -n +2 > $WORK/r2
		paste $WORK/r1 $WORK/r2 | awk -v s=$scene -v n=$n -v m=$m -v d=$d -v h=$h -v dn=$dn \
			-v df=$df '{ printf "%s\t%d\t%d\t%d\t%s\t%s\t%s\t%d\t%.6g\t%.6g\n", s, n, m, d,
			h, dn, df, NR, 47.4*$1 + 119.9*$2 + 11.6*$3, 47.4*$4 + 119.9*$5 + 11.6*$6 }' \
			>> $WORK/truth.tsv
		echo "$scene step $n ($m $d $h, $dn $df, epsilon $eps): done" >&2
	done
done
cp $WORK/truth.tsv $WORK/gendaylit.tsv $OUT/
rtrace -version > $OUT/VERSION
