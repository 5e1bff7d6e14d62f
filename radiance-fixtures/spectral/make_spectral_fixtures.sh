#!/usr/bin/env bash
# make_spectral_fixtures.sh: the spectral fixture (issue 8) made with REAL Radiance 6:
# a small room with spectral glazing (`spectrum` on glass), a spectral wall (`specfile` of a
# measured ColorChecker reflectance), RGB walls and floor (converted to bands by Radiance's
# own rule), lit by a gensky clear sky whose sun and sky glows carry CIE daylight spectra.
# References: rtrace -cs $NCS -co sensor irradiances and view radiances (three independent
# runs: mean and spread) and rcontrib -cs $NCS Reinhart MF:1 sky coefficients under a uniform
# 360-degree glow (three runs). Writes manifest.tsv (file, kind, CPU s, spread, command).
#
# Usage: radiance-fixtures/spectral/make_spectral_fixtures.sh   (RADIANCE_BIN as in ../)
# Needs bash, awk, python3 (standard library), ../../data/spectra/*.csv.
#
# Independent Monte Carlo runs: Radiance has no seed, so run r prepends K_r copies of the
# first ray and drops their output rows (as ../make_fixtures.sh does).
set -euo pipefail
cd "$(dirname "$0")"
source ../find_radiance.sh rtrace make_spectral_fixtures.sh
NCS=18
VERSION=$(rtrace -version)
RT_OPTS="-h -ab 5 -ad 4096 -aa 0 -as 0 -lw 1e-5 -cs $NCS -co+"
DC_OPTS="-I+ -ab 5 -ad 10000 -lw 1e-5 -cs $NCS"
SITE="-a 51.15 -o 0.18 -m 0"
PADS=(0 17 41)
WORK=tmp
rm -rf "$WORK" ./*.mtx ./*.txt ./*.dat ./*.rad ./*.pts manifest.tsv
mkdir -p "$WORK"
LOG=$WORK/log.tsv
: >"$LOG"

run() { # run OUT KIND CMD (CPU time logged)
	local out=$1 kind=$2 cmd=$3 t
	t=$( { TIMEFORMAT='%3U %3S'; time bash -c "set -o pipefail; $cmd" >/dev/null 2>>"$WORK/stderr.txt"; } 2>&1 ) || {
		echo "make_spectral_fixtures.sh: failed: $cmd" >&2; tail -n 20 "$WORK/stderr.txt" >&2; exit 1; }
	printf '%s\t%s\t%s\t%s\n' "$out" "$kind" "$(awk '{print $1+$2}' <<<"$t")" "$cmd" >>"$LOG"
}
pad() { echo "awk -v k=$1 'NR==1{for(i=0;i<k;i++)print}1' $2"; }

# ---------------------------------------------------------------- spectra (python, stdlib)
cat >"$WORK/spectra.py" <<'PY'
import csv, sys
def table(path):
    rows = [r for r in csv.reader(open(path)) if r and r[0].strip()[0].isdigit()]
    return {float(r[0]): [float(x) for x in r[1:]] for r in rows}
def daylight(cct):
    # CIE 15:2004 eq. 3.3-3.5 (CIE daylight of a correlated colour temperature).
    t = cct
    x = (-4.6070e9/t**3 + 2.9678e6/t**2 + 0.09911e3/t + 0.244063) if t <= 7000 else \
        (-2.0064e9/t**3 + 1.9018e6/t**2 + 0.24748e3/t + 0.237040)
    y = -3.0*x*x + 2.87*x - 0.275
    m = 0.0241 + 0.2562*x - 0.7341*y
    m1 = (-1.3515 - 1.7703*x + 5.9114*y)/m
    m2 = (0.0300 - 31.4424*x + 30.0717*y)/m
    d = table('../../data/spectra/cie_daylight_components.csv')
    return [d[w][0] + m1*d[w][1] + m2*d[w][2] for w in range(380, 781, 20)]
what = sys.argv[1]
if what == 'daylight':          # 21 values 380..780 step 20, mean 1
    v = daylight(float(sys.argv[2])); s = sum(v)/len(v)
    print(' '.join('%.5f' % (x/s) for x in v))
elif what == 'patch':           # specfile data file of a ColorChecker patch (5 nm)
    col = int(sys.argv[2])
    t = table('../../data/spectra/macbeth_colorchecker24.csv')
    ws = sorted(w for w in t if 380 <= w <= 780)
    print('# ColorChecker patch %d reflectance (data/spectra/macbeth_colorchecker24.csv)' % col)
    print('1\n%g %g %d' % (ws[0], ws[-1], len(ws)))
    print('\n'.join('%g' % t[w][col-1] for w in ws))
PY
SUN=$(python3 $WORK/spectra.py daylight 5000)
SKY=$(python3 $WORK/spectra.py daylight 10000)
run red_wall.dat input "python3 $WORK/spectra.py patch 15 > red_wall.dat"

# ---------------------------------------------------------------- scene
# 4 m (x) by 5 m (y) by 3 m room, window 3 x 1.5 m in the south wall (y = 0), normals in.
# Glazing: a synthetic green-blue tint (transmittance falls off in the red), written as a
# Radiance 6 `spectrum` on `glass` with transmissivity 1.
GLZ="0.55 0.62 0.70 0.76 0.80 0.82 0.83 0.83 0.82 0.80 0.76 0.71 0.65 0.58 0.51 0.45 0.40 0.36 0.33 0.31 0.30"
cat >"$WORK/room.txt" <<ROOM
# Spectral fixture room (make_spectral_fixtures.sh). Radiance 6 spectral modifiers.
void specfile red_spec 1 red_wall.dat 0 0
red_spec plastic red_wall 0 0 5 1 1 1 0 0
void plastic ceiling_mat 0 0 5 .8 .8 .8 0 0
void plastic floor_mat 0 0 5 .35 .25 .15 0 0
void plastic wall_mat 0 0 5 .5 .55 .6 0 0
void spectrum glazing_spec 0 0 23 380 780 $GLZ
glazing_spec glass pane 0 0 3 1 1 1
floor_mat polygon floor 0 0 12 0 0 0 4 0 0 4 5 0 0 5 0
ceiling_mat polygon ceiling 0 0 12 0 0 3 0 5 3 4 5 3 4 0 3
wall_mat polygon north 0 0 12 0 5 0 4 5 0 4 5 3 0 5 3
red_wall polygon east 0 0 12 4 0 0 4 0 3 4 5 3 4 5 0
wall_mat polygon west 0 0 12 0 0 0 0 5 0 0 5 3 0 0 3
wall_mat polygon south_low 0 0 12 0 0 0 0 0 .9 4 0 .9 4 0 0
wall_mat polygon south_high 0 0 12 0 0 2.4 0 0 3 4 0 3 4 0 2.4
wall_mat polygon south_left 0 0 12 0 0 .9 0 0 2.4 .5 0 2.4 .5 0 .9
wall_mat polygon south_right 0 0 12 3.5 0 .9 3.5 0 2.4 4 0 2.4 4 0 .9
pane polygon window 0 0 12 .5 0 .9 .5 0 2.4 3.5 0 2.4 3.5 0 .9
ROOM
run room.rad input "cp $WORK/room.txt room.rad"
run sky_clear.rad input "{ echo '# gensky 3 21 12 +s $SITE with CIE daylight spectra: sun 5000 K, sky 10000 K (mean 1)'; echo 'void spectrum sun_spec 0 0 23 380 780 $SUN'; gensky 3 21 12 +s $SITE | sed 's/^void light solar/sun_spec light solar/'; echo 'skyfunc spectrum sky_spec 0 0 23 380 780 $SKY'; echo 'sky_spec glow skyglow 0 0 4 1 1 1 0'; echo 'skyglow source sky 0 0 4 0 0 1 180'; echo 'skyfunc glow groundglow 0 0 4 1 1 1 0'; echo 'groundglow source ground 0 0 4 0 0 -1 180'; } > sky_clear.rad"
run sky_glow360.rad input "printf '%s\n' '# Uniform unit glow on every direction (rcontrib sky coefficients).' 'void glow skyglow 0 0 4 1 1 1 0' 'skyglow source sky 0 0 4 0 0 1 360' > sky_glow360.rad"
# Sensors: five upward at 0.8 m (the first in the sun patch), two vertical at eye height.
run sensors.pts input "printf '%s\n' '2 1 .8 0 0 1' '2 2.5 .8 0 0 1' '2 4 .8 0 0 1' '1 2.5 .8 0 0 1' '3 2.5 .8 0 0 1' '2 2.5 1.2 1 0 0' '2 2.5 1.2 0 1 0' > sensors.pts"
# View rays: at the red wall, out of the window (sky through the glazing), at the floor.
run views.pts input "printf '%s\n' '2 2.5 1.2 1 0 0' '2 2.5 1.2 0 -1 .3' '2 2.5 1.2 0 0 -1' > views.pts"
NSENS=$(wc -l < sensors.pts)
run $WORK/clear.oct scratch "oconv room.rad sky_clear.rad > $WORK/clear.oct"
run $WORK/glow.oct scratch "oconv room.rad sky_glow360.rad > $WORK/glow.oct"

# ---------------------------------------------------------------- references
cat >"$WORK/tool.py" <<'PY'
import statistics, sys
def header_split(path):
    data = open(path).read()
    if data.startswith('#?RADIANCE'):
        i = data.index('\n\n') + 2
        return data[:i], data[i:]
    return '', data
def rows(path):
    _, body = header_split(path)
    return [[float(x) for x in l.split()] for l in body.splitlines() if l.strip()]
cmd, a = sys.argv[1], sys.argv[2:]
if cmd == 'drop':        # drop k leading rows of an ascii matrix (fix NROWS)
    src, k, dst = a[0], int(a[1]), a[2]
    head, body = header_split(src)
    lines = [l for l in body.splitlines() if l.strip()][k:]
    head = '\n'.join(('NROWS=%d' % len(lines)) if l.startswith('NROWS=') else l
                     for l in head.split('\n'))
    open(dst, 'w').write(head + '\n'.join(lines) + '\n')
elif cmd == 'spread':    # max over values of max_run |run - mean| / mean; band totals for dc
    ncs, dc, runs = int(a[0]), a[1] == 'dc', [rows(p) for p in a[2:]]
    def reduce(m):       # per row: band values (dc: summed over patches)
        out = []
        for r in m:
            if dc:
                n = len(r) // ncs
                out.append([sum(r[p*ncs + b] for p in range(n)) for b in range(ncs)])
            else:
                out.append(r)
        return out
    rr = [reduce(m) for m in runs]
    worst = []
    for i in range(len(rr[0])):
        for b in range(len(rr[0][i])):
            vals = [m[i][b] for m in rr]
            mu = statistics.mean(vals)
            if mu > 0:
                worst.append(max(abs(v - mu) for v in vals) / mu)
    print('%.4f\t%.4f' % (statistics.median(worst), max(worst)))
PY
for r in 1 2 3; do
	k=${PADS[$((r - 1))]}
	run irr_run$r.txt mc "$(pad $k sensors.pts) | rtrace -I $RT_OPTS $WORK/clear.oct | tail -n +$((k + 1)) > irr_run$r.txt"
	run rad_run$r.txt mc "$(pad $k views.pts) | rtrace $RT_OPTS $WORK/clear.oct | tail -n +$((k + 1)) > rad_run$r.txt"
	run dc_run$r.mtx mc "$(pad $k sensors.pts) | rcontrib $DC_OPTS -faa -y $((NSENS + k)) -e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow $WORK/glow.oct > $WORK/raw$r.mtx && python3 $WORK/tool.py drop $WORK/raw$r.mtx $k dc_run$r.mtx"
done

# ---------------------------------------------------------------- spread + manifest
{
	printf 'file\tkind\tcpu_s\tspread_median\tspread_max\tcommand\n'
	while IFS=$'\t' read -r out kind cpu cmd; do
		sp=$'\t'
		case $out in
			irr_run*) sp=$(python3 $WORK/tool.py spread $NCS rt irr_run{1,2,3}.txt) ;;
			rad_run*) sp=$(python3 $WORK/tool.py spread $NCS rt rad_run{1,2,3}.txt) ;;
			dc_run*) sp=$(python3 $WORK/tool.py spread $NCS dc dc_run{1,2,3}.mtx) ;;
		esac
		[[ $kind == scratch ]] || printf '%s\t%s\t%s\t%s\t%s\n' "$out" "$kind" "$cpu" "$sp" "$cmd"
	done <"$LOG"
} >manifest.tsv
echo "# $VERSION" >>manifest.tsv
rm -rf "$WORK"
echo "make_spectral_fixtures.sh: done ($VERSION)" >&2
