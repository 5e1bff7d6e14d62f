#!/usr/bin/env bash
# benches/rrecon.sh: the whole rrecon pipeline (read, down-sample, outliers, normals, RANSAC,
# shell, windows, .rad) on a simulated scan of the rectangular test room, down-sampled to
# 100,000 and to 1,000,000 points, on 2 threads. Prints wall time and the stage timings of the
# JSON summary. The scan (~1.3 M points, 2 stations at 0.25 degrees) goes to a temporary
# folder (not committed).
# Usage: benches/rrecon.sh   (builds rrecon --release)
set -euo pipefail
cd "$(dirname "$0")/.."
T=${BENCH_DIR:-$(mktemp -d)}; mkdir -p "$T"
cargo build --release --bin rrecon -q
B=target/release/rrecon
export RAYON_NUM_THREADS=2
$B room rect > "$T/room.rad"
s=$(date +%s.%N)
$B simulate "$T/room.rad" --resolution 0.25 > "$T/scan.ply"
echo "simulate: $(echo "$(date +%s.%N) - $s" | bc) s, $(grep -a -m1 '^element vertex' "$T/scan.ply" | cut -d' ' -f3) points"
for n in 100000 1000000; do
	s=$(date +%s.%N)
	$B --auto --target-points $n --json "$T/s$n.json" "$T/scan.ply" > "$T/recon$n.rad"
	e=$(echo "$(date +%s.%N) - $s" | bc)
	python3 - "$T/s$n.json" "$n" "$e" <<'PY'
import json, sys
j = json.load(open(sys.argv[1])); t = j["timings"]
print(f"target {int(sys.argv[2]):>8}: wall {float(sys.argv[3]):.2f} s (pipeline {t['total']:.2f} s: preprocess {t['preprocess']:.2f}, "
      f"planes {t['planes']:.2f}, shell {t['shell']:.3f}, windows {t['windows']:.2f}); used {j['used_points']} points, "
      f"{len(j['faces'])} faces, {len(j['windows'])} windows, watertight {j['watertight']}")
PY
	$B eval "$T/room.rad" "$T/recon$n.rad" --samples 80000 | python3 -c "import json,sys; j=json.load(sys.stdin); print(f\"  chamfer {j['chamfer']*1000:.2f} mm, hausdorff {j['hausdorff']*100:.1f} cm, window area error {j['window_area_error']*100:+.1f} %\")"
done
