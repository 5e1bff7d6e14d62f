#!/usr/bin/env bash
# make_annual_fixtures.sh: the picture route for the annual-glare cross-check, made by REAL
# Radiance. For each time step of hours.wea (14 hours of the bundled London Gatwick EPW,
# chosen to span the sun seen through the window, the sun in the field of view but behind
# the facade, the sun behind the viewer, intermediate, overcast and dark overcast skies):
# gendaylit for that hour (the .wea's direct-normal and diffuse-horizontal irradiance, the
# site of the .wea header), rpict of the furnished office (scenes/furnished.rad) through
# the 180-degree angular fisheye looking at the window, then `evalglare -d` on the picture.
# Only evalglare's output is kept (hour_<month>_<day>_<hour>_evalglare.txt); the pictures
# are written to a temporary folder (KEEP=dir keeps them there).
#
# Usage: radiance-fixtures/glare/annual/make_annual_fixtures.sh   (RES=800 by default)
#   RADIANCE_BIN=/path/to/radiance/bin  optional; RAYPATH defaults to ../lib beside it.
# hours.wea is made from examples/weather/*.epw with epw2wea and kept in this folder, so
# `rglare annual -w hours.wea` evaluates exactly these steps (tests/all/rglare_annual.rs).
# 800 px: a pixel of 0.225 deg, so the 0.533 deg sun disc covers ~4.4 pixels and rpict's
# one ray per pixel samples its area fairly (at 200 px it is one pixel hit or missed).
set -euo pipefail
cd "$(dirname "$0")/../.."

source find_radiance.sh rpict make_annual_fixtures.sh

OUT=glare/annual
WORK=${KEEP:-$(mktemp -d)}
[[ -n ${KEEP:-} ]] || trap 'rm -rf "$WORK"' EXIT
RES=${RES:-800}
OPTS="-ab 2 -ad 1024 -aa 0.1 -ar 64 -as 256 -ps 1 -pj 0.9"
VIEW="-vta -vp 3 1.5 1.2 -vd 0 -1 0 -vu 0 0 1 -vh 180 -vv 180"
EPW=$(ls ../examples/weather/*.epw | head -1)

# month day hour (local standard time, mid-interval as epw2wea writes it)
HOURS="1 14 12.5
2 12 12.5
10 12 9.5
10 12 12.5
12 13 11.5
11 20 9.5
3 21 12.5
4 11 12.5
6 16 12.5
7 10 16.5
6 16 8.5
6 17 12.5
3 20 12.5
12 12 12.5"

epw2wea "$EPW" $WORK/year.wea
head -6 $WORK/year.wea > $OUT/hours.wea
while read -r m d h; do
	awk -v m=$m -v d=$d -v h=$h 'NR > 6 && $1 == m && $2 == d && $3 + 0 == h + 0' $WORK/year.wea
done <<< "$HOURS" >> $OUT/hours.wea

LAT=$(awk '$1 == "latitude" {print $2}' $OUT/hours.wea)
LON=$(awk '$1 == "longitude" {print $2}' $OUT/hours.wea)   # degrees west, as gendaylit -o
TZ=$(awk '$1 == "time_zone" {print $2}' $OUT/hours.wea)     # meridian, degrees west

printf 'hour\tcommand\n' > $OUT/manifest.tsv
tail -n +7 $OUT/hours.wea | while read -r m d h dn df; do
	name=hour_${m}_${d}_${h}
	gendaylit $m $d $h -a $LAT -o $LON -m $TZ -W $dn $df > $WORK/$name.sky
	cat skies/skyglow.rad >> $WORK/$name.sky
	oconv scenes/furnished.rad $WORK/$name.sky > $WORK/$name.oct
	rpict $VIEW -x $RES -y $RES $OPTS $WORK/$name.oct > $WORK/$name.hdr
	evalglare -d $WORK/$name.hdr > $OUT/${name}_evalglare.txt
	printf '%s\t%s\n' $name "gendaylit $m $d $h -a $LAT -o $LON -m $TZ -W $dn $df; rpict $VIEW -x $RES -y $RES $OPTS" >> $OUT/manifest.tsv
	echo "$name: $(head -1 $OUT/${name}_evalglare.txt | cut -c1-60)" >&2
done
echo "evalglare: $(evalglare -v 2>&1 | head -1)" > $OUT/VERSION
