#!/bin/bash
# Streaming at scale (issue 17): the annual study of `make` (TAI, UDI, DA, sDA and ASE) for
# 10,000 sensors x 8760 hours, the two annual results produced by rmtx and reduced by
# rmetrics in one pipe, never written to disk, with each process's peak resident memory
# and CPU time from GNU time (`/usr/bin/time -v`):
#
#   1. 10,000 work-plane sensors: a 100 x 100 grid over the example room's 6 x 8 m floor at
#      0.8 m (6 cm x 8 cm spacing);
#   2. their daylight coefficients with rdc on the example room at the main job's settings
#      (RDC_OPTS, default -ab 5 -ad 10000 -lw 1e-5: ~124 of the 146 patches non-zero per
#      sensor, so the product does the real work; cheap sampling such as -ab 2 -ad 64
#      leaves ~4 and rmtx skips the zero rows): 10,000 x 146 x RGB float, Radiance's own
#      matrix format; about 140 CPU-s;
#   3. their sun coefficients (rdc --suns 6 -ad 1, direct only: 10,000 x 5186 x RGB float,
#      622 MB on disk, deleted at the end);
#   4. the annual Perez sky matrix of the bundled London weather file (rspecsky -m 1:
#      146 x 8760) and its sun-only matrix (rspecsky -m 6 -5 0.533 -d: 5186 x 8760, 545 MB,
#      99.99 % zeros, deleted at the end);
#   5. rmtx -ff -c 47.4 119.9 11.6 sun.mtx sky_sun.smx > a FIFO, and at the same time
#      rmtx -ff -c 47.4 119.9 11.6 dc.mtx sky.smx | rmetrics --direct-sun FIFO --pts ... -
#      (2 x 87.6 million illuminances, 2 x 350 MB of float, through the pipes).
#
# The pipe's three processes run at the same time, so its peak is at most the sum of their
# peaks; the script fails (status 1) when that sum reaches LIMIT_KB (default 976562 KiB =
# 1e9 bytes). Settings from the environment: BIN (target/release), OUT (out/stream-10k),
# RDC_OPTS, LIMIT_KB. `make stream-10k` runs it after building. Figures: docs/scaling.md.
set -euo pipefail
BIN=${BIN:-target/release}
OUT=${OUT:-out/stream-10k}
ROOM=${ROOM:-examples/room}
EPW=${EPW:-examples/weather/GBR_London.Gatwick.037760_IWEC.epw}
RDC_OPTS=${RDC_OPTS:--ab 5 -ad 10000 -lw 1e-5 -s 1}
LIMIT_KB=${LIMIT_KB:-976562}
TIME=/usr/bin/time

if ! [ -x "$TIME" ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
        apt-get install -y -q time >/dev/null
    else
        echo "stream-10k: GNU time ($TIME) is missing: install the Debian package 'time'" >&2
        exit 1
    fi
fi
mkdir -p "$OUT"

# Peak RSS (KiB) and CPU seconds (user + system) of one GNU time report.
rss() { awk -F': ' '/Maximum resident set size/ {print $2}' "$1"; }
cpu() { awk -F': ' '/User time/ {u=$2} /System time/ {s=$2} END {printf "%.1f", u+s}' "$1"; }
wall() { awk -F': ' '/Elapsed \(wall clock\)/ {print $2}' "$1"; }

awk 'BEGIN { for (j = 0; j < 100; j++) for (i = 0; i < 100; i++)
    printf "%.2f %.2f 0.8 0 0 1\n", 0.03 + 0.06 * i, 0.04 + 0.08 * j }' > "$OUT/sensors.pts"
# shellcheck disable=SC2086 # RDC_OPTS is a list of options
"$TIME" -v -o "$OUT/rdc.time" "$BIN/rdc" -I $RDC_OPTS -m 1 -faf "$ROOM/room.rad" \
    "$ROOM/skydome.rad" < "$OUT/sensors.pts" > "$OUT/dc.mtx"
"$TIME" -v -o "$OUT/rdc-suns.time" "$BIN/rdc" -I --suns 6 -ad 1 -faf "$ROOM/room.rad" \
    "$ROOM/skydome.rad" < "$OUT/sensors.pts" > "$OUT/sun.mtx"
"$TIME" -v -o "$OUT/rspecsky.time" "$BIN/rspecsky" -m 1 -of "$EPW" > "$OUT/sky.smx"
"$BIN/rspecsky" -m 6 -5 0.533 -d -of "$EPW" > "$OUT/sky_sun.smx"
fifo=$OUT/direct_sun.fifo
rm -f "$fifo"
mkfifo "$fifo"
"$TIME" -v -o "$OUT/rmtx-sun.time" "$BIN/rmtx" -ff -c 47.4 119.9 11.6 "$OUT/sun.mtx" \
    "$OUT/sky_sun.smx" > "$fifo" &
sun_pid=$!
# Should the reducing pipe fail before opening the FIFO, the sun product would wait on it
# for ever: read it out so that it ends by itself.
drain() { if kill -0 "$sun_pid" 2>/dev/null; then cat "$fifo" > /dev/null; fi; }
trap drain EXIT
"$TIME" -v -o "$OUT/rmtx.time" "$BIN/rmtx" -ff -c 47.4 119.9 11.6 "$OUT/dc.mtx" "$OUT/sky.smx" \
    | "$TIME" -v -o "$OUT/rmetrics.time" "$BIN/rmetrics" -w "$EPW" --pts "$OUT/sensors.pts" \
        --direct-sun "$fifo" -o "$OUT/metrics.tsv" -
wait "$sun_pid"
rm -f "$fifo" "$OUT/sun.mtx" "$OUT/sky_sun.smx"

rows=$(grep -c '^[0-9]' "$OUT/metrics.tsv")
if [ "$rows" != 10000 ]; then
    echo "stream-10k: metrics.tsv has $rows sensor rows, expected 10000" >&2
    exit 1
fi
for p in rdc rdc-suns rspecsky rmtx rmtx-sun rmetrics; do
    printf 'stream-10k: %-9s peak RSS %7d KiB  CPU %6s s  wall %s\n' "$p" \
        "$(rss "$OUT/$p.time")" "$(cpu "$OUT/$p.time")" "$(wall "$OUT/$p.time")"
done
pipe=$(($(rss "$OUT/rmtx.time") + $(rss "$OUT/rmtx-sun.time") + $(rss "$OUT/rmetrics.time")))
echo "stream-10k: 10000 sensors x 8760 hours (sky and direct sun), rmtx + rmtx | rmetrics" \
    "peak RSS at most $pipe KiB ($((pipe / 1024)) MiB; limit $LIMIT_KB KiB)"
grep '^room' "$OUT/metrics.tsv"
if [ "$pipe" -ge "$LIMIT_KB" ]; then
    echo "stream-10k: over the limit" >&2
    exit 1
fi
