#!/usr/bin/env bash
# benches/rglare.sh: rglare vs real evalglare on one 1000x1000 angular fisheye (the furnished
# office, clear sky, sun in view), rendered with rpict at low -ab into a temporary folder
# (not committed). Prints the median wall time of 3 runs of each and their DGP lines.
# Usage: benches/rglare.sh   (needs pyradiance or RADIANCE_BIN; builds rglare --release)
set -euo pipefail
cd "$(dirname "$0")/.."
source radiance-fixtures/find_radiance.sh evalglare "$0"
T=${BENCH_DIR:-$(mktemp -d)}
PIC=$T/bench_1000.hdr
if [[ ! -s $PIC ]]; then
	F=radiance-fixtures
	oconv $F/scenes/furnished.rad $F/skies/clear_gendaylit.rad $F/skies/skyglow.rad > $T/b.oct
	rpict -vta -vp 3 1.5 1.2 -vd 0 -1 0 -vu 0 0 1 -vh 180 -vv 180 -x 1000 -y 1000 \
		-ab 1 -ad 128 -aa 0.2 -ar 16 -as 0 -ps 2 $T/b.oct > $PIC
fi
cargo build --release --bin rglare -q
median() { sort -g | sed -n 2p; }
timeit() { local s e; s=$(date +%s.%N); "$@" > $T/out.txt 2>/dev/null; e=$(date +%s.%N); echo "$e - $s" | bc; }
for tool in evalglare target/release/rglare; do
	t=$(for i in 1 2 3; do timeit $tool $PIC; done | median)
	echo "$(basename $tool): median of 3 = ${t}s; $(cat $T/out.txt)"
done
