#!/usr/bin/env bash
# make.sh: build the Klems BSDF XML fixtures in tests/data/bsdf/ with REAL Radiance tools
# only, the way genBSDF does it (genBSDF itself is not in the pyradiance package): the
# device sits in z < 0 with its front facing +Z, `rfluxmtx` sends rays from a Klems-full
# sender just outside each face to two Klems-full glow hemispheres (one per side), and
# `rmtxop -t -c y` + `wrapBSDF` turn the two rfluxmtx matrices into the four XML blocks
# (Transmission/Reflection Front/Back, photopic "Visible" only).
#
# Usage:  radiance-fixtures/bsdf/make.sh        (from anywhere)
#   RADIANCE_BIN=/path/to/radiance/bin  optional (see ../find_radiance.sh)
#   NPROC=2                             optional rfluxmtx -n (default 1: shared box)
#   BSDF_ONLY=blinds45                  optional: make only this fixture (blinds45,
#                                       shade10 or lobe_tt)
#   BSDF_SAMPLES=500                    rays per sender patch for the blinds (rfluxmtx -c)
#   SHADE_SAMPLES=100                   the same for the shade (every ray hits the fabric
#                                       and spawns -ad ambient rays: 5 x the blinds' cost)
# Writes tests/data/bsdf/{blinds45,shade10}.xml (Klems full) and lobe_tt.xml (a 3-rank
# tensor tree of an analytic BSDF, by bsdf2ttree). Monte Carlo: each run differs in noise.
set -euo pipefail
cd "$(dirname "$0")"
source ../find_radiance.sh rfluxmtx make.sh
NPROC=${NPROC:-1}
NSAMP=${BSDF_SAMPLES:-500}
SHADE_NSAMP=${SHADE_SAMPLES:-100}
OUT=../../tests/data/bsdf
WORK=work
rm -rf "$WORK"; mkdir -p "$WORK" "$OUT"
# genBSDF's rfluxmtx settings (-ab 5 -ad 700 -lw 3e-6), -w- to keep the log quiet.
RFLUX="rfluxmtx -ab 5 -ad 700 -lw 3e-6 -w- -n $NPROC"
FEPS=1e-5

want() { [[ -z ${BSDF_ONLY:-} || ${BSDF_ONLY} == "$1" ]]; }
round4() { awk '{ for (i = 1; i <= NF; i++) $i = sprintf("%.4g", $i); print }'; }

# One device: $1 name, $2 scene file (device in z < 0, front at z = 0 facing +Z), $3 rays
# per sender patch.
make_klems() {
	local name=$1 scene=$2 nsamp=$3
	read -r x0 x1 y0 y1 z0 z1 < <(getbbox -h -w "$scene")
	oconv -w "$scene" > "$WORK/$name.oct"
	# Receivers: the hemisphere in front (+Z, "face") and behind (-Z); u=-Y as genBSDF.
	cat > "$WORK/receivers.rad" <<RCV
#@rfluxmtx h=-kf u=-Y o=$WORK/$name.face.mtx
void glow receiver_face
0
0
4 1 1 1 0
receiver_face source f_receiver
0
0
4 0 0 1 180
#@rfluxmtx h=+kf u=-Y o=$WORK/$name.behind.mtx
void glow receiver_behind
0
0
4 1 1 1 0
receiver_behind source b_receiver
0
0
4 0 0 -1 180
RCV
	# Senders as genBSDF's: "fwd" just behind the device (z < zmin, its polygon normal -Z,
	# h=-kf flipping the sampled hemisphere to +Z), "bwd" just in front (z > zmax, h=+kf).
	cat > "$WORK/fsender.rad" <<SND
#@rfluxmtx u=-Y h=-kf
void polygon fwd_sender
0
0
12
	$x0	$y0	$(awk "BEGIN{print $z0-$FEPS}")
	$x0	$y1	$(awk "BEGIN{print $z0-$FEPS}")
	$x1	$y1	$(awk "BEGIN{print $z0-$FEPS}")
	$x1	$y0	$(awk "BEGIN{print $z0-$FEPS}")
SND
	cat > "$WORK/bsender.rad" <<SND
#@rfluxmtx u=-Y h=+kf
void polygon bwd_sender
0
0
12
	$x0	$y0	$(awk "BEGIN{print $z1+$FEPS}")
	$x1	$y0	$(awk "BEGIN{print $z1+$FEPS}")
	$x1	$y1	$(awk "BEGIN{print $z1+$FEPS}")
	$x0	$y1	$(awk "BEGIN{print $z1+$FEPS}")
SND
	local wrap="wrapBSDF -a kf -f t=$(awk "BEGIN{print -($z0)}");w=$(awk "BEGIN{print $x1-($x0)}");h=$(awk "BEGIN{print $y1-($y0)}")"
	local forw sender trans refl tt rt
	for forw in 0 1; do
		if [[ $forw == 1 ]]; then sender=fsender; tt=tf; rt=rf; trans=face; refl=behind
		else sender=bsender; tt=tb; rt=rb; trans=behind; refl=face; fi
		$RFLUX -c "$nsamp" -ff "$WORK/$sender.rad" "$WORK/receivers.rad" -i "$WORK/$name.oct"
		# rmtxop -t: rows become incident patches as wrapBSDF expects; -c y: photopic Y. awk
		# only rounds to 4 significant digits (the Monte Carlo noise is far larger) to keep
		# the committed files small.
		rmtxop -fa -t -c y "$WORK/$name.$trans.mtx" | getinfo - | round4 > "$WORK/$name.$tt.dat"
		rmtxop -fa -t -c y "$WORK/$name.$refl.mtx" | getinfo - | round4 > "$WORK/$name.$rt.dat"
		wrap="$wrap -$tt $WORK/$name.$tt.dat -$rt $WORK/$name.$rt.dat"
	done
	# -s Visible once before the data: every block is photopic. -c divides each outgoing
	# row by its patch's projected solid angle: rfluxmtx gives flux fractions, a BSDF is
	# per projected solid angle (wrapBSDF(1); genBSDF does the same).
	wrap=${wrap/-a kf/-a kf -c -s Visible}
	$wrap -C "rdaylight radiance-fixtures/bsdf/make.sh: $name" > "$OUT/$name.xml"
}

# (a) Venetian blinds: 20 slats of 25 mm, 1 m x 0.5 m, tilted 45 degrees, reflectance 0.5
# (plastic, no specularity). genblinds puts the slats' depth along x, their length along y
# and stacks them along z; -ry 90 turns the depth to -z (into z < 0) and the stack to x,
# -rz 90 then stacks them along y (the up direction of the senders' u=-Y frame) with
# their length along x.
cat > "$WORK/blinds45.rad" <<'EOF2'
void plastic slat_mat
0
0
5 0.5 0.5 0.5 0 0
EOF2
genblinds slat_mat blinds 0.025 1 0.5 20 45 | xform -ry 90 -rz 90 > "$WORK/blinds_raw.rad"
read -r bx0 bx1 by0 by1 bz0 bz1 < <(getbbox -h -w "$WORK/blinds_raw.rad")
xform -t "$(awk "BEGIN{print -($bx0+$bx1)/2}")" "$(awk "BEGIN{print -($by0+$by1)/2}")" \
	"$(awk "BEGIN{print -($bz1)-0.001}")" "$WORK/blinds_raw.rad" >> "$WORK/blinds45.rad"
want blinds45 && make_klems blinds45 "$WORK/blinds45.rad" "$NSAMP"

# (b) Roller shade: one diffusing sheet 1 mm behind z = 0, Radiance `trans`: colour 0.6,
# trans 0.35 of which tspec 0.45 passes straight through, so the openness (specular
# transmittance) is 0.6 x 0.35 x 0.45 = 0.0945, diffuse transmittance 0.1155, diffuse
# reflectance 0.6 x 0.65 = 0.39.
cat > "$WORK/shade10.rad" <<'EOF2'
void trans shade_fabric
0
0
7 0.6 0.6 0.6 0 0 0.35 0.45
shade_fabric polygon shade
0
0
12
	-0.5 -0.25 -0.001
	 0.5 -0.25 -0.001
	 0.5  0.25 -0.001
	-0.5  0.25 -0.001
EOF2
want shade10 && make_klems shade10 "$WORK/shade10.rad" "$SHADE_NSAMP"

# (c) A tensor tree (isotropic, rank 3, up to 2^5 per dimension, both incident sides) of an
# analytic, reciprocal BSDF (bsdf2ttree cannot resample Klems XML): front and back
# reflection Lambertian 0.2/pi; transmission 0.05/pi plus a Phong-like lobe
# 0.5 max(0, -i.o)^20 around the straight-through direction (vectors point away from the
# surface, so straight through is o = -i).
want lobe_tt && bsdf2ttree -p -t3 -g 5 +forward +backward \
	-e 'tt(ix,iy,iz,ox,oy,oz) = if(-iz*oz, .05/PI + .5*max(0, -(ix*ox+iy*oy+iz*oz))^20, .2/PI)' \
	tt > "$OUT/lobe_tt.xml"

rm -rf "$WORK"
