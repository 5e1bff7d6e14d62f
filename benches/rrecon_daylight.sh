#!/usr/bin/env bash
# benches/rrecon_daylight.sh [ROOM...]: the daylight consequence of reconstruction (seed
# Tables 4.4-4.7). For each built-in test room (default: rect lshape slanted arched cluttered):
# ground truth -> simulated scan -> rrecon --auto -> geometric errors (rrecon eval), then the
# same annual study on the truth and on the reconstruction (rdc daylight and sun coefficients,
# rspecsky Perez skies for London, rmtx, rmetrics) and the comparison (rmetrics compare: TAI
# bias, sDA, ASE). Work-plane sensors: 0.5 m grid at 0.8 m, 0.3 m from the walls, inside the
# room. The truth keeps its furniture out (GLoD0 against GLoD0: the error is the pipeline's).
# Usage: benches/rrecon_daylight.sh [rect ...]   (builds the tools --release; minutes)
set -euo pipefail
cd "$(dirname "$0")/.."
T=${BENCH_DIR:-$(mktemp -d)}; mkdir -p "$T"
cargo build --release --bins -q
B=target/release
EPW=examples/weather/GBR_London.Gatwick.037760_IWEC.epw
SKY=examples/room/skydome.rad
OPTS=${RDC_OPTS:--ab 4 -ad 4096 -lw 1e-4 -s 1}
ROOMS=${*:-rect lshape slanted arched cluttered}
$B/rspecsky -m 1 -of $EPW > "$T/sky.smx"
$B/rspecsky -m 6 -5 0.533 -d -of $EPW > "$T/sky_sun.smx"
for room in $ROOMS; do
	D=$T/$room; mkdir -p "$D"
	$B/rrecon room "$room" > "$D/truth_scan.rad"
	# The daylight truth is the GLoD0 shell (no furniture); the scan sees the furniture.
	$B/rrecon room "$room" --shell > "$D/truth.rad"
	$B/rrecon simulate "$D/truth_scan.rad" > "$D/scan.ply"
	$B/rrecon --auto --json "$D/recon.json" "$D/scan.ply" > "$D/recon.rad"
	$B/rrecon eval "$D/truth.rad" "$D/recon.rad" > "$D/eval.json"
	# Sensors inside the floor polygon of the truth, 0.3 m from its edges.
	python3 - "$D/truth.rad" > "$D/sensors.pts" <<'PY'
import sys
words = open(sys.argv[1]).read().split("\n")
floor = None
for i, l in enumerate(words):
    w = l.split()
    if len(w) == 3 and w[1] == "polygon" and w[2] == "floor":
        vals = " ".join(words[i + 3:i + 3000]).split()
        n = int(vals[0]); v = [float(x) for x in vals[1:n + 1]]
        floor = [(v[k], v[k + 1]) for k in range(0, n, 3)]
        break
def inside(x, y, m=0.3):
    c = False
    for k in range(len(floor)):
        (ax, ay), (bx, by) = floor[k], floor[(k + 1) % len(floor)]
        if (ay > y) != (by > y) and x < ax + (y - ay) * (bx - ax) / (by - ay): c = not c
        # distance to the edge
        dx, dy = bx - ax, by - ay; L = (dx * dx + dy * dy) ** 0.5
        t = max(0, min(1, ((x - ax) * dx + (y - ay) * dy) / (L * L)))
        if ((ax + t * dx - x) ** 2 + (ay + t * dy - y) ** 2) ** 0.5 < m: return False
    return c
xs = [p[0] for p in floor]; ys = [p[1] for p in floor]
y = min(ys) + 0.25
while y < max(ys):
    x = min(xs) + 0.25
    while x < max(xs):
        if inside(x, y): print(f"{x:.2f} {y:.2f} 0.8 0 0 1")
        x += 0.5
    y += 0.5
PY
	for m in truth recon; do
		$B/rdc -I $OPTS -m 1 -faf "$D/$m.rad" $SKY < "$D/sensors.pts" > "$D/$m.dc"
		$B/rdc -I --suns 6 -ad 1 -faf "$D/$m.rad" $SKY < "$D/sensors.pts" > "$D/$m.sun"
		$B/rmtx -ff -c 47.4 119.9 11.6 "$D/$m.dc" "$T/sky.smx" > "$D/$m.ill"
		$B/rmtx -ff -c 47.4 119.9 11.6 "$D/$m.sun" "$T/sky_sun.smx" > "$D/$m.dsun"
		$B/rmetrics -w $EPW --pts "$D/sensors.pts" --direct-sun "$D/$m.dsun" -o "$D/$m.tsv" "$D/$m.ill" > /dev/null
	done
	echo "== $room: $(wc -l < "$D/sensors.pts") sensors"
	python3 -c "import json,sys; j=json.load(open('$D/eval.json')); print(f\"geometry: chamfer {j['chamfer']*1000:.2f} mm (mean sq {j['chamfer_sq']:.2e} m2), hausdorff {j['hausdorff']*100:.1f} cm, windows {j['windows_found']}/{j['windows_true']}, area error {j['window_area_error']*100:+.1f} %, position error {j['window_position_error']*100:.1f} cm, watertight {j['recon_watertight']}\")"
	echo "truth: $(grep '^room' "$D/truth.tsv")"
	echo "recon: $(grep '^room' "$D/recon.tsv")"
	$B/rmetrics compare "$D/truth.tsv" "$D/recon.tsv" || true
done
echo "(files in $T)"
