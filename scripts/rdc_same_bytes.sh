#!/usr/bin/env bash
# Compare two rdc builds byte for byte on the example room (sky, direct-only, sun and
# spectral coefficients, point-in-time values, a fisheye picture), e.g. before and after a
# refactoring that must not change any output for the same seed:
#   git worktree add /tmp/old <commit> && (cd /tmp/old && cargo build --release --bin rdc)
#   scripts/rdc_same_bytes.sh /tmp/old/target/release/rdc target/release/rdc
set -euo pipefail
old=$1 new=$2
cd "$(dirname "$0")/.."
room=examples/room/room.rad dome=examples/room/skydome.rad sky=radiance-fixtures/scenes/sky_glow360.rad
sensors=$(mktemp); trap 'rm -f "$sensors"' EXIT
head -20 examples/room/sensors.pts > "$sensors"
status=0
check() { # label, then rdc arguments
    local label=$1; shift
    if cmp -s <("$old" "$@" < "$sensors") <("$new" "$@" < "$sensors"); then
        echo "same bytes: $label"
    else
        echo "DIFFERENT:  $label"; status=1
    fi
}
check "sky coefficients"    -I -ab 3 -ad 256 -lw 1e-4 -s 3 -m 1 -faf "$room" "$dome"
check "direct-only"         -I -ab 2 -ad 64 -m 1 --direct -fad "$room" "$dome"
check "sun coefficients"    -I --suns 6 -ad 1 -faf "$room" "$dome"
check "18 bands"            -I -ab 2 -ad 128 -cs 18 -m 1 -faa -s 1 "$room" "$dome"
check "point-in-time"       -I -ab 2 -ad 128 -s 2 "$room" "$sky"
check "fisheye picture"     -vta -vp 3 4 1.2 -vd 0 -1 0 -vh 180 -vv 180 -x 32 -y 32 -ab 1 -ad 8 "$room" "$sky"
exit $status
