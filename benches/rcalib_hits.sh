#!/usr/bin/env bash
# Hit-rate table of `rcalib explain` on hidden-effect cases: 3 rooms x 2 climates x
# (7 single effects, 2 combined, 1 control), 30 measured steps, 9-12 sensors.
# Prints a Markdown table (ranked first / selected, RMSE_rel before, after apply,
# noise-only) and the totals. RCALIB_ONLY=obstruction limits the effects; RCALIB_STEPS and
# RCALIB_ROOM and RCALIB_CLIMATE (comma-separated name parts) pick a subset; RCALIB_MF change the steps and the sky subdivision. Takes about an hour on 2 cores from an empty cache (the truth readings are simulated at
# converged settings), about 12 minutes with it.
# RCALIB_WORST=1 adds each case's worst readings, RCALIB_ORACLE=1 the error of the hidden
# effect itself applied (parameter x 1.01): the Monte Carlo floor of the after-apply error.
# The 'fit vs applied' column is RMSE_rel of the fitted prediction against the applied
# model's re-simulation; 'simulation error' is the truth re-simulated at the model's
# settings against the converged (noise-free) truth values: the floor of any fit.
# Readings come from converged settings (Settings::truth); noise-only = the readings
# against those noise-free values. `cargo test --release --test all rcalib_hits::fidelity_table -- --ignored`
# and `... explain_timing_20_sensors_50_steps -- --ignored` are the other diagnostics.
set -euo pipefail
cd "$(dirname "$0")/.."
time cargo test --release --test all rcalib_hits::hit_rate_table -- --ignored --nocapture 2>&1 \
    | grep -E '^\||^hits|panicked|^test result'
