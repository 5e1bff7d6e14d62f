#!/usr/bin/env bash
# ours_picture_route.sh: the picture route with OUR tools for the hours of hours.wea:
# gendaylit (real Radiance) for the sky, `rdc` picture mode for the 180-degree fisheye
# (RES px, -ab 2 -ad AD), `rglare` for DGP. Prints "hour DGP Ev" per hour; nothing is
# written to the repository. Compare with the *_evalglare.txt (rpict + evalglare) and with
# `rglare annual` (README.md in this folder).
# Usage: radiance-fixtures/glare/annual/ours_picture_route.sh  (RES=200 AD=32; builds --release)
set -euo pipefail
cd "$(dirname "$0")/../.."
source find_radiance.sh gendaylit ours_picture_route.sh
RES=${RES:-200}; AD=${AD:-32}
WORK=$(mktemp -d); trap 'rm -rf "$WORK"' EXIT
(cd .. && cargo build --release -q --bin rdc --bin rglare)
BIN=../target/release
VIEW="-vta -vp 3 1.5 1.2 -vd 0 -1 0 -vu 0 0 1 -vh 180 -vv 180"
LAT=$(awk '$1 == "latitude" {print $2}' glare/annual/hours.wea)
LON=$(awk '$1 == "longitude" {print $2}' glare/annual/hours.wea)
TZ=$(awk '$1 == "time_zone" {print $2}' glare/annual/hours.wea)
echo "# month day hour DGP Ev (rdc picture ${RES}px -ab 2 -ad $AD + rglare)"
tail -n +7 glare/annual/hours.wea | while read -r m d h dn df; do
	gendaylit $m $d $h -a $LAT -o $LON -m $TZ -W $dn $df > $WORK/h.sky
	cat skies/skyglow.rad >> $WORK/h.sky
	$BIN/rdc $VIEW -x $RES -y $RES -ab 2 -ad $AD scenes/furnished.rad $WORK/h.sky > $WORK/h.hdr
	echo "$m $d $h $($BIN/rglare -d $WORK/h.hdr 2>/dev/null | tail -1 | cut -d: -f2 | awk '{print $1, $3}')"
done
