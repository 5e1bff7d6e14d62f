#!/usr/bin/env bash
# make_fixtures.sh: regenerate every scene, sensor grid, sky and reference output in
# radiance-fixtures/ with REAL Radiance (the binaries shipped in the pip package
# `pyradiance`, or the ones in $RADIANCE_BIN), and write manifest.json recording, for every
# output file, the exact command that made it, Radiance's version, the CPU time, and for
# Monte Carlo outputs the measured run-to-run spread.
#
# Usage:  radiance-fixtures/make_fixtures.sh        (from anywhere; works in its own folder)
#   RADIANCE_BIN=/path/to/radiance/bin  optional; RAYPATH defaults to ../lib beside it.
#   NPROC=2                             optional; rcontrib/rtrace -n (default 1: shared box).
# Needs: bash, awk, python3 (standard library only), and the London EPW at
# ../examples/weather/GBR_London.Gatwick.037760_IWEC.epw.
#
# Everything is deterministic except Monte Carlo noise (and the dates Radiance writes in
# headers). Independent Monte Carlo runs: Radiance has no seed option, so run r prepends
# K_r copies of the first sensor ray and the script drops those leading rows afterwards
# (docs/benchmarking.md rule 2). Paths are relative to this folder only.
set -euo pipefail
cd "$(dirname "$0")"

# ---------------------------------------------------------------- find Radiance
source find_radiance.sh rtrace make_fixtures.sh
NPROC=${NPROC:-1}
VERSION=$(rtrace -version)
EPW=../examples/weather/GBR_London.Gatwick.037760_IWEC.epw
[[ -f $EPW ]] || { echo "make_fixtures.sh: missing $EPW" >&2; exit 1; }

# Settings shared by the references (see README.md for why).
DC_OPTS="-I+ -ab 5 -ad 10000 -lw 1e-5"
RT_OPTS="-h -I -ab 5 -ad 4096 -aa 0 -as 0 -lw 1e-5"
PIC_OPTS="-ab 3 -ad 1024 -aa 0.1 -ar 64 -as 256"
if [[ -n "${FIXTURES_QUICK:-}" ]]; then   # only for debugging this script: cheap settings
	DC_OPTS="-I+ -ab 2 -ad 256 -lw 1e-3"
	RT_OPTS="-h -I -ab 2 -ad 256 -aa 0 -as 0 -lw 1e-3"
	PIC_OPTS="-ab 1 -ad 64 -aa 0.2 -ar 16 -as 0"
fi
PADS=(0 17 41)   # dummy rays prepended in the independent runs 1, 2, 3
SITE="-a 51.15 -o 0.18 -m 0"   # Gatwick: 51.15 N, 0.18 W, GMT (gensky/gendaylit: west +)

WORK=oct   # scratch (octrees, raw outputs); removed at the end
rm -rf "$WORK" scenes sensors skies weather dc sky points pictures oracles manifest.json
mkdir -p "$WORK" scenes sensors skies weather dc sky points pictures oracles
LOG=$WORK/log.tsv
: > "$LOG"

# run OUT KIND CMD: run CMD with bash, record OUT, KIND, CPU seconds and CMD in the log.
# KIND: input (generated input), exact (deterministic output), mc (Monte Carlo output),
# derived (computed by this script from other outputs), scratch (not committed).
run() {
	local out=$1 kind=$2 cmd=$3 t
	t=$( { TIMEFORMAT='%3U %3S'; time bash -c "set -o pipefail; $cmd" >/dev/null 2>>"$WORK/stderr.txt"; } 2>&1 ) || {
		echo "make_fixtures.sh: failed: $cmd" >&2
		tail -n 20 "$WORK/stderr.txt" >&2
		exit 1
	}
	printf '%s\t%s\t%s\t%s\n' "$out" "$kind" "$(awk '{print $1+$2}' <<<"$t")" "$cmd" >>"$LOG"
}

# pad K FILE: command text printing K copies of FILE's first line, then FILE.
pad() { echo "awk -v k=$1 'NR==1{for(i=0;i<k;i++)print}1' $2"; }

# ---------------------------------------------------------------- python helpers
# One inline tool (standard library only) for what Radiance itself cannot do:
# drop leading rows of a matrix, average runs, measure spreads, write the manifest.
cat >"$WORK/tool.py" <<'PY'
import json, math, os, struct, sys

def read_header(path):
    """Radiance information header -> (lines, dict, data offset)."""
    with open(path, 'rb') as f:
        data = f.read()
    if not data.startswith(b'#?RADIANCE'):
        return None, {}, 0, data
    end = data.index(b'\n\n') + 2
    lines = data[:end].decode().split('\n')[:-2]
    kv = {}
    for l in lines:
        if '=' in l and not l.startswith('\t'):
            k, v = l.split('=', 1)
            kv[k.strip()] = v.strip()
    return lines, kv, end, data

def read_matrix(path):
    lines, kv, off, data = read_header(path)
    nc = int(kv.get('NCOMP', '3'))
    fmt = kv.get('FORMAT', 'ascii')
    if fmt == 'float':
        n = (len(data) - off) // 4
        vals = list(struct.unpack('<%df' % n, data[off:off + 4 * n]))
    elif fmt == 'double':
        n = (len(data) - off) // 8
        vals = list(struct.unpack('<%dd' % n, data[off:off + 8 * n]))
    else:
        vals = [float(x) for x in data[off:].split()]
    ncols = int(kv['NCOLS'])
    nrows = len(vals) // (ncols * nc)
    return lines, kv, vals, nrows, ncols, nc

def write_float_matrix(path, lines, nrows, ncols, nc, vals):
    keep = [l for l in lines if not l.split('=')[0] in
            ('NROWS', 'NCOLS', 'NCOMP', 'FORMAT', 'BigEndian')]
    hdr = '\n'.join(keep + ['NROWS=%d' % nrows, 'NCOLS=%d' % ncols, 'NCOMP=%d' % nc,
                            'BigEndian=0', 'FORMAT=float']) + '\n\n'
    with open(path, 'wb') as f:
        f.write(hdr.encode())
        f.write(struct.pack('<%df' % len(vals), *vals))

def drop_rows(src, k, dst):
    lines, kv, vals, nrows, ncols, nc = read_matrix(src)
    w = ncols * nc
    lines = lines + ['make_fixtures.sh: dropped %d leading dummy rows (independent run)' % k]
    write_float_matrix(dst, lines, nrows - k, ncols, nc, vals[k * w:])

def mean_matrix(dst, srcs):
    mats = [read_matrix(s) for s in srcs]
    _, kv, _, nrows, ncols, nc = mats[0]
    n = len(mats[0][2])
    acc = [0.0] * n
    for m in mats:
        assert len(m[2]) == n
        for i, v in enumerate(m[2]):
            acc[i] += v
    acc = [a / len(mats) for a in acc]
    lines = ['#?RADIANCE', 'make_fixtures.sh: mean of ' + ' '.join(srcs),
             'SOFTWARE= ' + os.environ['VERSION']]
    write_float_matrix(dst, lines, nrows, ncols, nc, acc)

# Radiance's rmtxop -c Y weights for RGB (179 * rgb2xyz row 1; notes section 0).
YW = (47.45394, 119.94894, 11.59712)

def pct(xs, p):
    xs = sorted(xs)
    if not xs:
        return float('nan')
    i = (len(xs) - 1) * p
    lo = math.floor(i)
    hi = min(lo + 1, len(xs) - 1)
    return xs[lo] + (xs[hi] - xs[lo]) * (i - lo)

def cv_stats(per_run):
    """per_run: list of runs, each a list of per-sensor values -> (median, p95, max) CV."""
    cvs = []
    for vals in zip(*per_run):
        m = sum(vals) / len(vals)
        if m <= 0:
            continue
        var = sum((v - m) ** 2 for v in vals) / (len(vals) - 1)
        cvs.append(math.sqrt(var) / m)
    return {'median_cv': pct(cvs, 0.5), 'p95_cv': pct(cvs, 0.95), 'max_cv': max(cvs),
            'sensors': len(cvs)}

def annual_totals(dc_path, sky_path):
    """Per-sensor annual illuminance sums (lx h): DC x (mean sky x 8760), Y-weighted."""
    _, _, dc, nr, ncol, nc = read_matrix(dc_path)
    _, kv, sky, srows, _, snc = read_matrix(sky_path)
    nav = int(kv.get('NAVERAGED', '1'))
    assert srows == ncol and nc == snc == 3
    tot = []
    for r in range(nr):
        s = 0.0
        for p in range(ncol):
            for c in range(3):
                s += dc[(r * ncol + p) * 3 + c] * sky[p * 3 + c] * YW[c]
        tot.append(s * nav)
    return tot

def rtrace_values(path):
    out = []
    with open(path) as f:
        for l in f:
            t = l.split()
            if t:
                out.append(sum(float(t[c]) * YW[c] for c in range(3)))
    return out

def main():
    cmd = sys.argv[1]
    a = sys.argv[2:]
    if cmd == 'drop':
        drop_rows(a[0], int(a[1]), a[2])
    elif cmd == 'mean':
        mean_matrix(a[0], a[1:])
    elif cmd == 'spread_dc':     # sky file then runs
        print(json.dumps(cv_stats([annual_totals(r, a[0]) for r in a[1:]])))
    elif cmd == 'mean_txt':      # mean of headerless ascii rtrace outputs
        runs = [[[float(x) for x in l.split()] for l in open(r) if l.strip()] for r in a[1:]]
        with open(a[0], 'w') as f:
            for rows in zip(*runs):
                f.write('\t'.join('%.6e' % (sum(v) / len(v)) for v in zip(*rows)) + '\t\n')
    elif cmd == 'spread_rt':
        print(json.dumps(cv_stats([rtrace_values(r) for r in a])))
    elif cmd == 'spread_dc_values':  # per-coefficient spread (Y) for tiny oracles
        runs = [read_matrix(r) for r in a]
        per = []
        for _, _, v, nr, ncol, nc in runs:
            per.append([sum(v[i * 3 + c] * YW[c] for c in range(3)) / 179.0
                        for i in range(nr * ncol)])
        st = cv_stats(per)
        rows = []
        for _, _, v, nr, ncol, nc in runs:
            rows.append([sum(v[(r * ncol + p) * 3] for p in range(ncol)) for r in range(nr)])
        st['row_sum_red'] = [[round(x, 7) for x in rr] for rr in rows]
        print(json.dumps(st))
    elif cmd == 'compare_dc':    # sky, reference, other: relative differences of totals
        ref = annual_totals(a[1], a[0])
        oth = annual_totals(a[2], a[0])
        d = [abs(o / r - 1) for r, o in zip(ref, oth) if r > 0]
        print(json.dumps({'median_rel_diff': pct(d, 0.5), 'p95_rel_diff': pct(d, 0.95)}))
    elif cmd == 'manifest':
        manifest(*a)

def manifest(log, spreads, timing, out):
    entries = []
    extra = {}
    with open(spreads) as f:
        for l in f:
            k, v = l.rstrip('\n').split('\t', 1)
            extra.setdefault(k, {}).update(json.loads(v))
    for l in open(log):
        path, kind, cpu, command = l.rstrip('\n').split('\t', 3)
        if kind == 'scratch':
            continue
        e = {'file': path, 'kind': kind, 'cpu_s': float(cpu), 'command': command}
        lines, kv, off, data = read_header(path)
        e['bytes'] = len(data)
        if lines is not None:
            for k in ('NROWS', 'NCOLS', 'NCOMP', 'FORMAT', 'NAVERAGED'):
                if k in kv:
                    e[k.lower()] = int(kv[k]) if k != 'FORMAT' else kv[k]
            if 'NROWS' not in kv and 'NCOLS' in kv and 'FORMAT' in kv:
                nc = int(kv.get('NCOMP', '3'))
                size = {'float': 4, 'double': 8}.get(kv['FORMAT'])
                if size:
                    e['nrows'] = (len(data) - off) // (size * nc * int(kv['NCOLS']))
        if path in extra:
            e.update(extra[path])
        entries.append(e)
    tm = json.load(open(timing))
    doc = {
        'generator': 'radiance-fixtures/make_fixtures.sh',
        'radiance_version': os.environ['VERSION'],
        'cwd': 'radiance-fixtures (all paths relative to it)',
        'settings': {
            'daylight_coefficients': 'rcontrib ' + os.environ['DC_OPTS'],
            'point_in_time': 'rtrace ' + os.environ['RT_OPTS'],
            'pictures': 'rpict ' + os.environ['PIC_OPTS'],
            'independent_runs': 'run r prepends K_r copies of the first sensor ray, '
                                'K = ' + os.environ["PADS_STR"] + '; those rows are dropped',
            'spread': 'per-sensor coefficient of variation (sample std / mean) over the runs; '
                      'DC: of annual illuminance totals (DC x gendaymtx -m 1 -A of the full '
                      'London year, Y = 47.45394 R + 119.94894 G + 11.59712 B); rtrace: of '
                      'illuminance values; median / p95 / max over sensors with mean > 0',
        },
        'timing': tm,
        'files': entries,
    }
    with open(out, 'w') as f:
        json.dump(doc, f, indent=1)
        f.write('\n')
    # The same list, flat, for readers without a JSON parser (tests/all/fixtures.rs).
    cols = ['file', 'kind', 'bytes', 'nrows', 'ncols', 'ncomp', 'format', 'cpu_s',
            'median_cv', 'p95_cv', 'command']
    with open(out[:-len('.json')] + '.tsv', 'w') as f:
        f.write('# ' + os.environ['VERSION'] + '; columns: ' + ' '.join(cols) +
                '; empty = not applicable; spreads: see manifest.json\n')
        for e in entries:
            sp = e.get('spread') or e.get('coefficient_spread') or {}
            row = [e['file'], e['kind'], e['bytes'], e.get('nrows', ''), e.get('ncols', ''),
                   e.get('ncomp', ''), e.get('format', ''), e['cpu_s'],
                   '%.6g' % sp['median_cv'] if sp else '', '%.6g' % sp['p95_cv'] if sp else '',
                   e['command']]
            f.write('\t'.join(str(x) for x in row) + '\n')

main()
PY
tool() { python3 "$WORK/tool.py" "$@"; }
export VERSION DC_OPTS RT_OPTS PIC_OPTS
export PADS_STR="${PADS[*]}"
SPREADS=$WORK/spreads.tsv
: > "$SPREADS"
spread() { printf '%s\t%s\n' "$1" "$2" >>"$SPREADS"; }

T_START=$(date +%s)

# ---------------------------------------------------------------- scenes
run scenes/office.rad input "cp ../examples/room/room.rad scenes/office.rad"
run sensors/office.pts input "cp ../examples/room/sensors.pts sensors/office.pts"
run scenes/sky_glow360.rad input "printf '%s\n' '# Uniform unit-radiance glow sky on a 360-degree source: every ray that leaves' '# the scene hits it; with reinhart.cal rbin the ground (Dz<0) is bin 0 (gendaymtx order).' 'void glow skyglow 0 0 4 1 1 1 0' 'skyglow source sky 0 0 4 0 0 1 360' > scenes/sky_glow360.rad"

# furnished: the office plus desks, chairs, a shelf and a partition (real genbox, expanded).
FURN="{ cat scenes/office.rad; printf '%s\n' '' '# ---- furniture (genbox boxes moved with xform) ----' \
'void plastic desk_mat 0 0 5 0.55 0.42 0.3 0 0' 'void plastic chair_mat 0 0 5 0.1 0.1 0.1 0 0' \
'void plastic shelf_mat 0 0 5 0.6 0.6 0.6 0 0' 'void plastic partition_mat 0 0 5 0.25 0.3 0.4 0 0';"
i=0
for d in "0.7 1.1" "3.7 1.1" "0.7 4.1" "3.7 4.1"; do
	set -- $d; i=$((i + 1))
	FURN+=" genbox desk_mat desk${i}_top 1.6 0.8 0.03 | xform -t $1 $2 0.69;"
	FURN+=" genbox desk_mat desk${i}_lside 0.03 0.8 0.69 | xform -t $1 $2 0;"
	FURN+=" genbox desk_mat desk${i}_rside 0.03 0.8 0.69 | xform -t $(awk "BEGIN{print $1+1.57}") $2 0;"
	FURN+=" genbox chair_mat chair${i}_seat 0.45 0.45 0.05 | xform -t $(awk "BEGIN{print $1+0.55}") $(awk "BEGIN{print $2+0.88}") 0.42;"
	FURN+=" genbox chair_mat chair${i}_back 0.45 0.04 0.45 | xform -t $(awk "BEGIN{print $1+0.55}") $(awk "BEGIN{print $2+1.29}") 0.47;"
done
FURN+=" genbox shelf_mat shelf 2 0.4 2 | xform -t 2 7.58 0;"
FURN+=" genbox partition_mat partition 0.05 1.6 1.5 | xform -t 3.2 4.2 0; } > scenes/furnished.rad"
run scenes/furnished.rad input "$FURN"

# specular: the office with a polished (mirror-like, roughness 0) plastic floor and a
# brushed-aluminium table (Ward isotropic metal, roughness 0.05).
run scenes/specular.rad input "{ sed 's/^void plastic floor_mat 0 0 5 0.2 0.2 0.2 0 0\$/void plastic floor_mat 0 0 5 0.2 0.2 0.2 0.05 0/' scenes/office.rad; printf '%s\n' '' '# ---- brushed aluminium table top (metal, specularity 0.9, roughness 0.05) ----' 'void metal alu_mat 0 0 5 0.8 0.8 0.8 0.9 0.05'; genbox alu_mat table 3 1.2 0.03 | xform -t 1.5 2 0.69; } > scenes/specular.rad"
grep -q 'floor_mat 0 0 5 0.2 0.2 0.2 0.05 0' scenes/specular.rad

# oracles: open sensors under the uniform glow sky (nothing else in the scene) and closed
# 2 m furnace boxes centred on the origin.
run sensors/open.pts input "printf '%s\n' '0 0 0 0 0 1' '0 0 0 0 -1 0' '0 0 0 0.7071068 0 0.7071068' '0 0 0 0 0 -1' > sensors/open.pts"
run scenes/furnace_glow.rad input "{ echo '# Closed 2 m cube, inner faces glow radiance 1, normals INTO the box (genbox -i).'; echo 'void glow furnace_glow 0 0 4 1 1 1 0'; genbox furnace_glow box 2 2 2 -i | xform -t -1 -1 -1; } > scenes/furnace_glow.rad"
run scenes/furnace_glow_out.rad input "{ echo '# Same cube with normals OUT of the box: glow emits only from its front side,'; echo '# so rtrace sees black walls; rcontrib still counts every ray that hits.'; echo 'void glow furnace_glow 0 0 4 1 1 1 0'; genbox furnace_glow box 2 2 2 | xform -t -1 -1 -1; } > scenes/furnace_glow_out.rad"
run scenes/furnace_grey.rad input "{ echo '# Closed 2 m cube of grey plastic (reflectance 0.5); lit only by rtrace -av.'; echo 'void plastic grey 0 0 5 0.5 0.5 0.5 0 0'; genbox grey box 2 2 2 -i | xform -t -1 -1 -1; } > scenes/furnace_grey.rad"
run sensors/furnace.pts input "printf '%s\n' '0 0 0 0 0 1' '0.9 0.9 -0.9 1 0 0' '0.5 -0.3 0.2 0.6 0.64 0.48' '0.999 0 0 -1 0 0' > sensors/furnace.pts"

# ---------------------------------------------------------------- weather and skies
run weather/london.wea input "epw2wea $EPW weather/london.wea"
run weather/london_4days.wea input "awk 'NR<=6 || (\$2==21 && (\$1==3 || \$1==6 || \$1==9 || \$1==12))' weather/london.wea > weather/london_4days.wea"
run weather/london_6hours.wea input "awk 'NR<=6 || (\$1==3 && \$2==2 && \$3>10 && \$3<14) || (\$1==3 && \$2==21 && \$3==12.5) || (\$1==4 && \$2==21 && \$3==11.5)' weather/london.wea > weather/london_6hours.wea"
# The 3 point-in-time cases, taken from the same EPW hours (DNI DHI in W/m2):
#   clear        2 Mar 12:30  838 79   (sun at 30.8 deg, 4.9 deg west of south: enters the window)
#   intermediate 21 Mar 12:30 297 265
#   overcast     21 Apr 11:30   0 155
CASES=(clear intermediate overcast)
declare -A WHEN=([clear]="3 2 12.5" [intermediate]="3 21 12.5" [overcast]="4 21 11.5")
declare -A WDAT=([clear]="838 79" [intermediate]="297 265" [overcast]="0 155")
declare -A GSKY=([clear]="+s" [intermediate]="+i" [overcast]="-c -B 155")
for c in "${CASES[@]}"; do
	run skies/${c}_gendaylit.rad exact "gendaylit ${WHEN[$c]} $SITE -W ${WDAT[$c]} > skies/${c}_gendaylit.rad"
	run skies/${c}_gensky.rad exact "gensky ${WHEN[$c]} ${GSKY[$c]} $SITE > skies/${c}_gensky.rad"
done
run skies/skyglow.rad input "printf '%s\n' '# Sky and ground glow for a gensky/gendaylit skyfunc (append after the sky file).' 'skyfunc glow skyglow 0 0 4 1 1 1 0' 'skyglow source sky 0 0 4 0 0 1 180' 'skyfunc glow groundglow 0 0 4 1 1 1 0' 'groundglow source ground 0 0 4 0 0 -1 180' > skies/skyglow.rad"

# ---------------------------------------------------------------- sky matrices
run sky/london_4days_m1.smx exact "gendaymtx -m 1 -of weather/london_4days.wea > sky/london_4days_m1.smx"
run sky/london_4days_m4.smx exact "gendaymtx -m 4 -of weather/london_4days.wea > sky/london_4days_m4.smx"
run sky/london_year_m1_A.smx exact "gendaymtx -m 1 -A -of $EPW > sky/london_year_m1_A.smx"
run sky/london_year_m1_A.txt exact "gendaymtx -m 1 -A $EPW > sky/london_year_m1_A.txt"
run sky/london_year_m1_A_d.smx exact "gendaymtx -m 1 -A -d -of $EPW > sky/london_year_m1_A_d.smx"
run sky/london_year_m1_A_s.smx exact "gendaymtx -m 1 -A -s -of $EPW > sky/london_year_m1_A_s.smx"
run sky/london_6hours_m1.smx exact "gendaymtx -m 1 -of weather/london_6hours.wea > sky/london_6hours_m1.smx"
run sky/london_6hours_m1_d.smx exact "gendaymtx -m 1 -d -of weather/london_6hours.wea > sky/london_6hours_m1_d.smx"
run sky/london_6hours_m1_s.smx exact "gendaymtx -m 1 -s -of weather/london_6hours.wea > sky/london_6hours_m1_s.smx"
run sky/london_6hours_m6_5d.smx exact "gendaymtx -5 0.533 -d -m 6 -of weather/london_6hours.wea > sky/london_6hours_m6_5d.smx"
YEARSKY=sky/london_year_m1_A.smx

# ---------------------------------------------------------------- octrees (scratch)
for s in office furnished specular; do
	run $WORK/$s.oct scratch "oconv scenes/$s.rad > $WORK/$s.oct"
	run $WORK/${s}_sky.oct scratch "oconv scenes/$s.rad scenes/sky_glow360.rad > $WORK/${s}_sky.oct"
done
for c in "${CASES[@]}"; do
	run $WORK/office_$c.oct scratch "oconv scenes/office.rad skies/${c}_gendaylit.rad skies/skyglow.rad > $WORK/office_$c.oct"
done
run $WORK/specular_clear.oct scratch "oconv scenes/specular.rad skies/clear_gendaylit.rad skies/skyglow.rad > $WORK/specular_clear.oct"
run $WORK/open.oct scratch "oconv scenes/sky_glow360.rad > $WORK/open.oct"
for f in furnace_glow furnace_glow_out furnace_grey; do
	run $WORK/$f.oct scratch "oconv scenes/$f.rad > $WORK/$f.oct"
done

# ---------------------------------------------------------------- daylight coefficients
# dc_runs SCENE OUTBASE MF: three independent rcontrib runs, their mean and spread.
dc_runs() {
	local s=$1 base=$2 mf=$3 r k files=()
	for r in 1 2 3; do
		k=${PADS[$((r - 1))]}
		local f=${base}_run$r.mtx
		if [[ $k == 0 ]]; then
			run "$f" mc "rcontrib $DC_OPTS -n $NPROC -faf -y 165 -e MF:$mf -f reinhart.cal -b rbin -bn Nrbins -m skyglow $WORK/${s}_sky.oct < sensors/office.pts > $f"
		else
			run "$f" mc "$(pad $k sensors/office.pts) | rcontrib $DC_OPTS -n $NPROC -faf -y $((165 + k)) -e MF:$mf -f reinhart.cal -b rbin -bn Nrbins -m skyglow $WORK/${s}_sky.oct > $WORK/raw.mtx && python3 $WORK/tool.py drop $WORK/raw.mtx $k $f"
		fi
		files+=("$f")
	done
	run "$base.mtx" derived "python3 $WORK/tool.py mean $base.mtx ${files[*]}"
	local st
	st=$(tool spread_dc "$YEARSKY" "${files[@]}")
	spread "$base.mtx" "{\"spread\": $st, \"runs\": \"${files[*]}\"}"
	for f in "${files[@]}"; do spread "$f" "{\"spread\": $st}"; done
}
dc_runs office dc/office_m1 1
dc_runs furnished dc/furnished_m1 1
dc_runs specular dc/specular_m1 1
# the same coefficients through rfluxmtx and the example sky dome (ground + 145 sky bins)
run dc/office_m1_rfluxmtx.mtx mc "rfluxmtx $DC_OPTS -n $NPROC -faf -y 165 - ../examples/room/skydome.rad -i $WORK/office.oct < sensors/office.pts > dc/office_m1_rfluxmtx.mtx"
spread dc/office_m1_rfluxmtx.mtx "{\"agreement_with_rcontrib_mean\": $(tool compare_dc "$YEARSKY" dc/office_m1.mtx dc/office_m1_rfluxmtx.mtx)}"
# MF 4 (2306 columns), one run, same settings
run dc/office_m4.mtx mc "rcontrib $DC_OPTS -n $NPROC -faf -y 165 -e MF:4 -f reinhart.cal -b rbin -bn Nrbins -m skyglow $WORK/office_sky.oct < sensors/office.pts > dc/office_m4.mtx"

# ---------------------------------------------------------------- point-in-time values
rt_runs() {   # rt_runs OCT OUTBASE SENSORS NSENS
	local oct=$1 base=$2 pts=$3 n=$4 r k files=()
	for r in 1 2 3; do
		k=${PADS[$((r - 1))]}
		local f=${base}_run$r.txt
		run "$f" mc "$(pad $k $pts) | rtrace $RT_OPTS -n $NPROC $oct | tail -n +$((k + 1)) > $f"
		[[ $(wc -l <"$f") == "$n" ]] || { echo "bad row count in $f" >&2; exit 1; }
		files+=("$f")
	done
	run "$base.txt" derived "python3 $WORK/tool.py mean_txt $base.txt ${files[*]}"
	local st
	st=$(tool spread_rt "${files[@]}")
	spread "$base.txt" "{\"spread\": $st, \"runs\": \"${files[*]}\"}"
	for f in "${files[@]}"; do spread "$f" "{\"spread\": $st}"; done
}
for c in "${CASES[@]}"; do
	rt_runs $WORK/office_$c.oct points/office_$c sensors/office.pts 165
done
# the specular room under the clear sky (sun reflected by the metal table and glossy floor)
rt_runs $WORK/specular_clear.oct points/specular_clear sensors/office.pts 165

# ---------------------------------------------------------------- pictures and glare
# Seated eye (1.2 m). window: 1.5 m from the window looking south (sun in view in the clear
# case); along: near the west wall looking east along the window (sun out of view).
declare -A VIEWS=([window]="-vta -vp 3 1.5 1.2 -vd 0 -1 0 -vu 0 0 1 -vh 180 -vv 180" \
	[along]="-vta -vp 0.6 2 1.2 -vd 1 0 0 -vu 0 0 1 -vh 180 -vv 180")
for c in "${CASES[@]}"; do
	for v in window along; do
		f=pictures/office_${c}_${v}.hdr
		run "$f" mc "rpict ${VIEWS[$v]} -x 256 -y 256 $PIC_OPTS $WORK/office_$c.oct > $f"
		run "pictures/office_${c}_${v}_evalglare.txt" exact "evalglare -d $f > pictures/office_${c}_${v}_evalglare.txt"
	done
done
run pictures/office_clear_perspective.hdr mc "rpict -vtv -vp 5.5 7.5 1.6 -vd -0.45 -1 -0.25 -vu 0 0 1 -vh 70 -vv 50 -x 256 -y 256 $PIC_OPTS $WORK/office_clear.oct > pictures/office_clear_perspective.hdr"

# ---------------------------------------------------------------- analytic oracles
# Open sensors (up, south, 45 deg, down) under the unit glow sky: each row sums to pi per
# channel; an upward sensor has ground bin 0 = 0, a vertical one pi/2 in bin 0.
for r in 1 2 3; do
	k=${PADS[$((r - 1))]}
	f=oracles/open_sensor_dc_run$r.mtx
	run "$f" mc "$(pad $k sensors/open.pts) | rcontrib $DC_OPTS -n 1 -faf -y $((4 + k)) -e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow $WORK/open.oct > $WORK/raw.mtx && python3 $WORK/tool.py drop $WORK/raw.mtx $k $f"
done
spread oracles/open_sensor_dc_run1.mtx "{\"coefficient_spread\": $(tool spread_dc_values oracles/open_sensor_dc_run{1,2,3}.mtx)}"
run oracles/open_sensor_rtrace.txt mc "rtrace $RT_OPTS $WORK/open.oct < sensors/open.pts > oracles/open_sensor_rtrace.txt"
# Furnaces: glow walls facing in -> pi everywhere (rtrace and rcontrib); facing out ->
# rtrace 0 but rcontrib pi; grey walls with -av 1 1 1 -> pi * 0.5^ab.
for f in furnace_glow furnace_glow_out; do
	run oracles/${f}_rtrace.txt mc "rtrace -h -I -ab 1 -ad 1024 -aa 0 -as 0 -lw 1e-5 $WORK/$f.oct < sensors/furnace.pts > oracles/${f}_rtrace.txt"
	run oracles/${f}_rcontrib.txt mc "rcontrib -I+ -ab 1 -ad 1024 -lw 1e-5 -y 4 -m furnace_glow $WORK/$f.oct < sensors/furnace.pts > oracles/${f}_rcontrib.txt"
done
for ab in 1 2 3; do
	run oracles/furnace_grey_ab$ab.txt mc "rtrace -h -I -ab $ab -ad 1024 -aa 0 -as 0 -lw 1e-5 -av 1 1 1 $WORK/furnace_grey.oct < sensors/furnace.pts > oracles/furnace_grey_ab$ab.txt"
done

# ---------------------------------------------------------------- manifest
T_END=$(date +%s)
times >"$WORK/times.txt"   # in this shell: user/sys of the script, then of its children
read -r CU CS CCU CCS < <(tr '\n' ' ' <"$WORK/times.txt" | sed 's/m/ /g; s/s//g' | awk '{print $1*60+$2, $3*60+$4, $5*60+$6, $7*60+$8}')
cat >"$WORK/timing.json" <<EOF
{"wall_s": $((T_END - T_START)), "cpu_s_total": $(awk "BEGIN{print $CU+$CS+$CCU+$CCS}"),
 "cpu_s_logged_commands": $(awk -F'\t' '{s+=$3} END{print s}' "$LOG"),
 "processes": $NPROC, "cores": $(nproc 2>/dev/null || echo 0),
 "note": "CPU = user+sys; the machine was shared, so wall time is not meaningful"}
EOF
tool manifest "$LOG" "$SPREADS" "$WORK/timing.json" manifest.json
rm -rf "$WORK"
echo "make_fixtures.sh: done; $(du -sh . | cut -f1) in radiance-fixtures"
