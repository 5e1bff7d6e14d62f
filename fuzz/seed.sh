#!/usr/bin/env bash
# Fill fuzz/corpus/<target>/ (not committed) with small valid inputs to start from: the
# repository's example and test files, the binary seeds in fuzz/seeds/ (formats a fuzzer
# cannot find from nothing: E57, EXR, LAS, binary PLY, re-weighting files, PNG), and a few
# text files written here. Run from anywhere; existing corpus files are kept.
set -euo pipefail
cd "$(dirname "$0")"
r=..
c=corpus
for t in header matrix picture scene sensors view weather trace ply las e57 xyz readings \
    spectral_readings cal dat exr png legend points schedule table hours reweight; do
    mkdir -p "$c/$t"
done
put() { cat > "$c/$1/$2"; } # target, file name; the content on stdin

# The repository's own files.
cp $r/tests/data/picture/small.hdr $r/radiance-fixtures/sky/london_year_m1_A.smx $c/header/
cp $r/radiance-fixtures/sky/london_year_m1_A.smx $r/radiance-fixtures/sky/london_6hours_m1.smx \
    $r/radiance-fixtures/oracles/open_sensor_dc_run1.mtx $c/matrix/
cp $r/tests/data/picture/*.hdr $r/tests/data/picture/spec.hsr $c/picture/
for t in scene trace; do
    cp $r/tests/data/scene/every_type.rad $r/examples/room/room.rad $r/examples/room/skydome.rad \
        $r/examples/scan/rect.rad $r/examples/calib/model.rad $c/$t/
done
cat $r/examples/room/room.rad $r/examples/room/skydome.rad > $c/trace/room_sky.rad
cp $r/examples/room/sensors.pts $r/tests/data/sensors/bad_count.pts $r/tests/data/sensors/room.csv \
    $c/sensors/
cp $r/tests/data/view/*.vf $c/view/
cp $r/tests/data/weather/tiny.wea $r/tests/data/weather/london_2days.epw $c/weather/
cp $r/tests/data/scene/copper_spec.dat $r/tests/data/specdata/refl.dat \
    $r/tests/data/specdata/sky_alt.dat $r/radiance-fixtures/spectral/red_wall.dat $c/dat/
cp $r/tests/data/specdata/sky.cal $c/cal/
head -30 $r/examples/calib/measured.csv > $c/readings/measured.csv
head -10 $r/examples/calib-spectral/measured.csv > $c/spectral_readings/measured.csv
{ echo 8-18; head -12 $r/examples/weather/GBR_London.Gatwick.037760_IWEC.epw; } > $c/schedule/epw.txt

# Binary seeds.
cp seeds/scan.e57 $c/e57/
cp seeds/rgb.exr seeds/spectral_half.exr $c/exr/
cp seeds/rgb.las $c/las/
cp seeds/binary_le.ply $c/ply/
cp seeds/v2.rw $c/reweight/
cp seeds/mask.png $c/png/

# Small text seeds. Several targets split their input at a line `---` (see each target).
put ply ascii.ply <<'EOF'
ply
format ascii 1.0
comment station 0 0 1.5
element vertex 3
property float x
property float y
property float z
property float nx
property float ny
property float nz
property uchar red
property uchar green
property uchar blue
property uchar station
element face 1
property list uchar int vertex_indices
end_header
0 0 0 0 0 1 255 0 0 0
1 0 0 0 0 1 0 255 0 0
0 1 0 0 0 1 0 0 255 0
3 0 1 2
EOF
put xyz xyz.xyz <<'EOF'
# x y z
0 0 0
1 0 0
0 1 2.5
EOF
put xyz rgb_normals.xyz <<'EOF'
0 0 0 1 2 3 0 0 1
1 1 1 4 5 6 0 1 0
EOF
put readings wide.csv <<'EOF'
month,day,hour,s1,s2
6,21,12.5,500,600
6,21,13.5,510,
EOF
put readings columns.csv <<'EOF'
sensor=Channel,klx=Reading,month=M,day=D,hour=H
M,D,H,Channel,Reading
3,1,9.5,a,1.2
EOF
put spectral_readings responses.csv <<'EOF'
month,day,hour,sensor,450nm,550nm
6,21,12.5,s1,0.1,0.2
---
wavelength,450nm,550nm
400,0,0
450,1,0
500,0,0.5
550,0,1
600,0,0
EOF
put cal funcs.cal <<'EOF'
{ a comment }
sq3(x) = x*x*x;
half : .5;
arr(i) = select(i, 4, 5, 6);
A1 = if(Dx, sq3(2) + half, arr(2));
f(x) = x + noise3(Px, Py, Pz);
red = max(0, min(1, A1 ^ 2 / PI));
---
sq3(2) + arr(0) - -2^2 + floor(3.7)
EOF
put dat irregular.dat <<'EOF'
2
0 0 3 1 2 4
400 700 2
1 2 3 4 5 6
EOF
put legend legend.csv <<'EOF'
# colour, name[, known][, reference]
c08040, back_wall
ffffff, card_back, 0.9
4060ff, poster, , card_back
808080, grey, 0.2 0.3 0.4
EOF
put points points.csv <<'EOF'
x,y,rho
10, 20, 0.5
30 40 0.2 0.3 0.4
5,	6, 0.9 # comment
EOF
put schedule hours.txt <<'EOF'
8-18
# month day hour
1 1 8.5
1 1 9.5
3 21 12.5 100 200
EOF
put schedule flags.txt <<'EOF'
9-17
0
1
1
EOF
printf '# rmetrics\nsensor\tx\ty\tz\tDA300\tsDA\tUDI\n0\t0\t0\t0.8\t50\t1\t80\n1\t1\t0\t0.8\t70\t0\t60\nroom\t\t\t\t60\t0.5\t70\n' \
    | put table metrics.tsv
put hours chunks.txt <<'EOF'
0:730
#?RADIANCE
rmtx dc.mtx sky.smx
HOURS= 0:2 4
NROWS=3
NCOLS=2
NCOMP=3
FORMAT=float

---
#?RADIANCE
rmtx dc.mtx sky.smx
HOURS= 2:4 4
NROWS=3
NCOLS=2
NCOMP=3
FORMAT=float

EOF
put hours shard.txt <<'EOF'
1/4
#?RADIANCE
rdc -I
SHARD= 1/4 3 12
NROWS=3
NCOLS=146
NCOMP=3
FORMAT=float

EOF
echo "seeded $(find $c -type f | wc -l) files under fuzz/$c/"
