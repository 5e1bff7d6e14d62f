#!/usr/bin/env python3
"""Reference values for rmcop's normality statistics (crates/mcop/src/stats.rs tests).

Independent implementation: SciPy's stats.normaltest (D'Agostino-Pearson K2, with its
skewtest and kurtosistest z-scores) and the Kolmogorov-Smirnov distance of stats.kstest
against the normal fitted to the sample (mean, sd with ddof=1). The samples are formulas,
not random draws, so the Rust test rebuilds them exactly.

    pip install scipy && python3 scripts/normaltest_reference.py
"""
import math
import numpy as np
from scipy import stats

samples = {
    # A lumpy but roughly symmetric sample of 40.
    "lumpy": [((i * 7919) % 101) / 10.0 + (i % 7) ** 2 * 0.3 for i in range(40)],
    # A right-skewed sample of 60: exponential quantiles.
    "skewed": [-math.log(1.0 - (i + 0.5) / 60.0) for i in range(60)],
}
for name, x in samples.items():
    k2 = stats.normaltest(x)
    z1 = stats.skewtest(x).statistic
    z2 = stats.kurtosistest(x).statistic
    ks = stats.kstest(x, "norm", args=(np.mean(x), np.std(x, ddof=1)))
    print(f"{name}: z1 {z1:.12f} z2 {z2:.12f} k2 {k2.statistic:.12f} p {k2.pvalue:.12e} ks_d {ks.statistic:.12f}")
