#!/usr/bin/env bash
# make_glare_fixtures.sh: glare test pictures for `rglare` made by REAL Radiance (rpict,
# pcomb) and each picture's real `evalglare -d` output (evalglare 3.x), written beside it as
# <name>_evalglare.txt. Also writes manifest.tsv (name, view type, command).
#
# Usage: radiance-fixtures/glare/make_glare_fixtures.sh   (works in radiance-fixtures/)
#   RADIANCE_BIN=/path/to/radiance/bin  optional; RAYPATH defaults to ../lib beside it.
# Cases: the office and the furnished office (scenes/) under the clear (sun in the window),
# intermediate and overcast gendaylit skies (skies/), seen through 180-degree angular
# (-vta) and hemispherical (-vth) fisheyes and perspective (-vtv) views; low-light pictures
# are real renders scaled with `pcomb -s` (Ev well below 1000 lx). Small (200 px), -ab 2:
# glare metrics need a smooth picture, not a converged one.
set -euo pipefail
cd "$(dirname "$0")/.."

source find_radiance.sh rpict make_glare_fixtures.sh

OUT=glare
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
RES="-x 200 -y 200"
OPTS="-ab 2 -ad 256 -aa 0.15 -ar 32 -as 64 -ps 1"
MAN=$OUT/manifest.tsv
printf 'name\tview\tcommand\n' > $MAN

for s in office furnished; do
	for c in clear intermediate overcast; do
		oconv scenes/$s.rad skies/${c}_gendaylit.rad skies/skyglow.rad > $WORK/${s}_$c.oct
	done
done

# name  view-type  view options
VIEWS=(
	"window vta -vta -vp 3 1.5 1.2 -vd 0 -1 0 -vu 0 0 1 -vh 180 -vv 180"
	"along vta -vta -vp 0.6 2 1.2 -vd 1 0 0 -vu 0 0 1 -vh 180 -vv 180"
	"back vth -vth -vp 3 4 1.2 -vd 0 -1 0 -vu 0 0 1 -vh 180 -vv 180"
	"persp vtv -vtv -vp 3 3.5 1.2 -vd 0 -1 0.35 -vu 0 0 1 -vh 70 -vv 60"
)
render() { # scene sky viewline
	local s=$1 c=$2 name=$3 vt=$4; shift 4
	local f=$OUT/${s}_${c}_$name.hdr
	local cmd="rpict $* $RES $OPTS oct/${s}_$c.oct > $f"
	rpict "$@" $RES $OPTS $WORK/${s}_$c.oct > $f
	printf '%s\t%s\t%s\n' "$(basename $f .hdr)" "$vt" "$cmd" >> $MAN
}
for s in furnished office; do
	for c in clear intermediate overcast; do
		for v in "${VIEWS[@]}"; do
			set -- $v
			# the office's window/along fisheyes already exist in pictures/
			if [[ $s == office && ( $1 == window || $1 == along ) ]]; then continue; fi
			render $s $c "$@"
		done
	done
done

# low light: real renders scaled down (pcomb writes the scaled values, no EXPOSURE line)
lowlight() { # source-name factor
	local src=$1 k=$2 f=$OUT/${1}_low.hdr
	pcomb -s $k $OUT/$src.hdr > $f
	printf '%s\t%s\t%s\n' "${src}_low" "$(awk -F'\t' -v n=$src '$1==n{print $2}' $MAN)" \
		"pcomb -s $k $src.hdr > ${src}_low.hdr" >> $MAN
}
lowlight furnished_overcast_window 0.1
lowlight furnished_overcast_along 0.05
lowlight furnished_intermediate_back 0.03
lowlight office_overcast_persp 0.1

for f in $OUT/*.hdr; do
	evalglare -d $f > ${f%.hdr}_evalglare.txt
done
echo "evalglare: $(evalglare -v 2>&1 | head -1)" > $OUT/VERSION
