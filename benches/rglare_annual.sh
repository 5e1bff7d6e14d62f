#!/usr/bin/env bash
# benches/rglare_annual.sh: annual glare for one view, imageless (`rglare annual`, every
# step of the bundled EPW, DGP for all occupied hours 8-18) against the picture route
# (for every occupied daylight hour: gendaylit + oconv + rpict of a fisheye + evalglare),
# the picture route timed on a few hours and extrapolated to the year's occupied daylight
# hours. View: the furnished office, 180-degree angular fisheye facing the window.
# Usage: benches/rglare_annual.sh   (needs pyradiance or RADIANCE_BIN; builds rglare --release)
#   PIC_RES=800 (picture size), PIC_HOURS=3 (hours rendered), RAYS=64 (grid), AB=2, AD=512
#   (both routes at -ab 2: a view ray counts its bounces from the surface it hits, as rpict)
set -euo pipefail
cd "$(dirname "$0")/.."
source radiance-fixtures/find_radiance.sh evalglare "$0"
T=${BENCH_DIR:-$(mktemp -d)}
F=radiance-fixtures
EPW=$(ls examples/weather/*.epw | head -1)
PIC_RES=${PIC_RES:-800}; PIC_HOURS=${PIC_HOURS:-3}; RAYS=${RAYS:-64}; AB=${AB:-2}; AD=${AD:-512}
VIEW="-vta -vp 3 1.5 1.2 -vd 0 -1 0 -vu 0 0 1 -vh 180 -vv 180"
cargo build --release --bin rglare -q
now() { date +%s.%N; }

s=$(now)
target/release/rglare annual -w "$EPW" $VIEW --rays $RAYS -ab $AB -ad $AD $F/scenes/furnished.rad > $T/annual.txt
e=$(now)
t_annual=$(echo "$e - $s" | bc)
grep '^#' $T/annual.txt | sed -n '2p;6,9p'

# occupied daylight hours of the year: 8 <= hour < 18 with any daylight (the picture route
# renders only those; dark hours need no picture)
epw2wea "$EPW" $T/year.wea
n_day=$(awk 'NR > 6 && $3 >= 8 && $3 < 18 && $4 + $5 > 0' $T/year.wea | wc -l)
LAT=$(awk '$1 == "latitude" {print $2}' $T/year.wea)
LON=$(awk '$1 == "longitude" {print $2}' $T/year.wea)
TZ=$(awk '$1 == "time_zone" {print $2}' $T/year.wea)
# a few hours spread over the year (every 150th occupied daylight hour)
awk 'NR > 6 && $3 >= 8 && $3 < 18 && $4 + $5 > 0' $T/year.wea | awk 'NR % 150 == 1' | head -$PIC_HOURS > $T/pick.txt
s=$(now)
while read -r m d h dn df; do
	gendaylit $m $d $h -a $LAT -o $LON -m $TZ -W $dn $df > $T/h.sky
	cat $F/skies/skyglow.rad >> $T/h.sky
	oconv $F/scenes/furnished.rad $T/h.sky > $T/h.oct
	rpict $VIEW -x $PIC_RES -y $PIC_RES -ab 2 -ad 1024 -aa 0.1 -ar 64 -as 256 -ps 1 -pj 0.9 $T/h.oct > $T/h.hdr
	evalglare $T/h.hdr > /dev/null
done < $T/pick.txt
e=$(now)
t_pic=$(echo "($e - $s) / $PIC_HOURS" | bc -l)
t_year=$(echo "$t_pic * $n_day" | bc -l)
printf 'imageless (rglare annual, %s steps, %sx%s rays, -ab %s -ad %s): %.1f s\n' \
	"$(grep -vc '^#' $T/annual.txt)" $RAYS $RAYS $AB $AD $t_annual
printf 'picture route: %.1f s per hour (rpict %s px + evalglare) x %d occupied daylight hours = %.0f s\n' \
	$t_pic $PIC_RES $n_day $t_year
printf 'ratio picture route / imageless: %.0f\n' "$(echo "$t_year / $t_annual" | bc -l)"
