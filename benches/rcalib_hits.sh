#!/usr/bin/env bash
# Hit-rate table of `rcalib explain` on hidden-effect cases: 3 rooms x 2 climates x
# (7 single effects, 2 combined, 1 control), 30 measured steps, 9-12 sensors.
# Prints a Markdown table (ranked first / selected, RMSE_rel before, after apply,
# noise-only) and the totals. RCALIB_ONLY=obstruction limits the effects; RCALIB_STEPS and
# RCALIB_ROOM and RCALIB_CLIMATE (comma-separated name parts) pick a subset; RCALIB_MF change the steps and the sky subdivision. Takes about 10 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
time cargo test --release --test rcalib_hits -- --ignored --nocapture 2>&1 \
    | grep -E '^\||^hits'
