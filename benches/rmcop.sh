#!/usr/bin/env bash
# benches/rmcop.sh: rmcop's cost per material draw against re-simulating each draw with rdc
# at the same settings (the brute-force loop a Radiance user runs: edit the materials, trace,
# multiply by the sky), on the bundled furnished room (165 sensors, the main job's
# -ab 5 -ad 10000 -lw 1e-5, London year). Prints median wall times of 3 runs:
#   A  rdc -I -m 1 (one trace: what re-simulating ONE draw costs, before its sky product)
#   B  rmcop study, GLoD4 only, 4 sigmas x 500 draws (one trace + 2,000 TAI draws)
#   C  rmcop study, all five GLoDs x 4 sigmas x 500 draws (five traces + 10,000 draws)
#   D  rmcop study, GLoD4, 1 sigma x 200 draws with --hourly (one trace + 200 hourly products)
# and the ratios: per-draw speed-up = A / ((B - A) / 2000) is bounded below by 2000 A / B.
# Usage: benches/rmcop.sh   (builds the release binaries)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q --bin rdc --bin rmcop
T=$(mktemp -d)
EPW=examples/weather/GBR_London.Gatwick.037760_IWEC.epw
F=examples/furnished
median() { sort -g | sed -n 2p; }
timeit() { local s e; s=$(date +%s.%N); "$@" > /dev/null 2>&1; e=$(date +%s.%N); echo "$e - $s" | bc; }
A=$(for i in 1 2 3; do timeit sh -c "target/release/rdc -I -ab 5 -ad 10000 -lw 1e-5 -m 1 $F/room.rad < $F/sensors.pts"; done | median)
B=$(for i in 1 2 3; do timeit target/release/rmcop study -w $EPW --pts $F/sensors.pts --levels 4 -o $T/b $F/room.rad; done | median)
C=$(for i in 1 2 3; do timeit target/release/rmcop study -w $EPW --pts $F/sensors.pts -o $T/c $F/room.rad; done | median)
D=$(for i in 1 2 3; do timeit target/release/rmcop study -w $EPW --pts $F/sensors.pts --levels 4 --sigmas 0.2 --draws 200 --hourly -o $T/d $F/room.rad; done | median)
echo "A rdc one trace (= one re-simulated draw):      ${A} s"
echo "B rmcop GLoD4, 2,000 draws (trace included):    ${B} s"
echo "C rmcop GLoD0-4, 10,000 draws (traces included): ${C} s"
echo "D rmcop GLoD4, 200 hourly draws (trace incl.):  ${D} s"
echo "per-draw speed-up (TAI), lower bound 2000 A / B: $(echo "2000 * $A / $B" | bc)"
echo "hourly cost per draw, (D - B/1 trace) ~ (D - A) / 200: $(echo "scale=4; ($D - $A) / 200 * 1000" | bc) ms"
rm -rf "$T"
