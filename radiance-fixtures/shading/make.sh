#!/usr/bin/env bash
# make.sh: the venetian blinds of examples/shading/ as geometry, made with real Radiance's
# genblinds, in the same orientation as the BSDF of tests/data/bsdf/blinds45.xml (made by
# ../bsdf/make.sh from the same slats): 25 mm slats, 25 mm apart, tilted 45 degrees,
# reflectance 0.5, here across the example room's 4.8 x 1.6 m window opening.
#
# The BSDF's device frame (genBSDF's): width along X, height along Y (the material's up
# vector), the room on +Z, the device in z < 0. ../bsdf/make.sh turns genblinds' output
# into it with `xform -ry 90 -rz 90`. The example window faces the room along +Y with up
# +Z, so device (x, y, z) goes to room (-x, z, y): `xform -rx 90 -rz 180`. Then the slats
# are moved onto the opening (x 0.6..5.4, z 0.9..2.5), their room-side edge 1 mm outside
# the window plane y = 0, as the BSDF device sits 1 mm behind z = 0.
#
# Usage: radiance-fixtures/shading/make.sh   (writes examples/shading/blinds.rad)
set -euo pipefail
cd "$(dirname "$0")"
source ../find_radiance.sh genblinds make.sh
OUT=../../examples/shading/blinds.rad
TMP=$(mktemp)
trap 'rm -f "$TMP"' EXIT
# 64 slats over 1.6 m: the 25 mm pitch of the BSDF's 20 slats over 0.5 m.
genblinds slat_mat blinds 0.025 4.8 1.6 64 45 | xform -ry 90 -rz 90 -rx 90 -rz 180 > "$TMP"
read -r x0 x1 y0 y1 z0 z1 < <(getbbox -h -w "$TMP")
{
	echo "# Venetian blinds across the window opening (radiance-fixtures/shading/make.sh):"
	echo "# genblinds slat_mat blinds 0.025 4.8 1.6 64 45 | xform -ry 90 -rz 90 -rx 90 -rz 180,"
	echo "# moved onto the opening. slat_mat is defined by the scene's material file."
	xform -t "$(awk "BEGIN{print 3.0-($x0+$x1)/2}")" "$(awk "BEGIN{print -0.001-($y1)}")" \
		"$(awk "BEGIN{print 1.7-($z0+$z1)/2}")" "$TMP" | grep -v '^#' | sed '/^$/d'
} > "$OUT"
getbbox -h -w "$OUT" >&2
