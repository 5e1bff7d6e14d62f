//! # Distribution statistics of a cell's draws
//!
//! - [`Summary`]: median, quartiles, 5/95 percentiles (linear interpolation between order
//!   statistics, `rdaylight_base::stats::percentile`), mean and sample standard deviation.
//! - [`dagostino_pearson`]: the omnibus normality test the seed used (section 3.3.3;
//!   D'Agostino & Pearson 1973, Biometrika 60: 613-622), in the form of D'Agostino, Belanger
//!   & D'Agostino (1990, The American Statistician 44: 316-321): skewness `sqrt(b1)` to
//!   `Z1` by D'Agostino's (1970) Johnson SU transformation, kurtosis `b2` to `Z2` by Anscombe
//!   & Glynn (1983, Biometrika 70: 227-234), `K2 = Z1^2 + Z2^2`, chi-squared with 2 degrees
//!   of freedom, so `p = exp(-K2 / 2)`. Valid from 20 values (the kurtosis transformation's
//!   stated range); fewer give `None`.
//! - [`ks_normal`]: the Kolmogorov-Smirnov distance between the sample and the normal fitted
//!   to it (its mean and sample sd), with the asymptotic p-value of Stephens' (1970, JRSS B
//!   32: 115-122) modified statistic `(sqrt n + 0.12 + 0.11 / sqrt n) D`. With the
//!   parameters estimated from the same sample (Lilliefors' case) that p-value is
//!   conservative (too large); the seed plotted this goodness of fit against the number of
//!   draws to decide when to stop (Fig. 3.5): [`ks_curve`].

use rdaylight_base::stats::{normal_cdf, percentile};
use serde::Serialize;

/// Order statistics, mean and spread of a sample (NaN entries ignored by the percentiles).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Summary {
    pub n: usize,
    pub median: f64,
    pub q25: f64,
    pub q75: f64,
    pub p5: f64,
    pub p95: f64,
    pub mean: f64,
    pub sd: f64,
}

impl Summary {
    pub fn of(v: &[f64]) -> Summary {
        let (mean, sd) = mean_sd(v);
        Summary {
            n: v.len(),
            median: percentile(v, 50.0),
            q25: percentile(v, 25.0),
            q75: percentile(v, 75.0),
            p5: percentile(v, 5.0),
            p95: percentile(v, 95.0),
            mean,
            sd,
        }
    }

    /// Inter-quartile range.
    pub fn iqr(&self) -> f64 {
        self.q75 - self.q25
    }
}

/// Mean and sample standard deviation (n - 1); NaN for an empty sample, sd 0 for one value.
pub fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let mean = v.iter().sum::<f64>() / n;
    let ss = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>();
    (
        mean,
        if v.len() > 1 {
            (ss / (n - 1.0)).sqrt()
        } else {
            0.0
        },
    )
}

/// The D'Agostino-Pearson omnibus test.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Normality {
    /// Skewness and kurtosis z-scores.
    pub z_skew: f64,
    pub z_kurt: f64,
    pub k2: f64,
    pub p: f64,
}

/// Central moments m2, m3, m4 (biased, divided by n).
fn moments(v: &[f64]) -> (f64, f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let (mut m2, mut m3, mut m4) = (0.0, 0.0, 0.0);
    for x in v {
        let d = x - mean;
        m2 += d * d;
        m3 += d * d * d;
        m4 += d * d * d * d;
    }
    (m2 / n, m3 / n, m4 / n)
}

/// D'Agostino-Pearson K2 and its p-value (module documentation); `None` below 20 values or
/// for a constant sample.
pub fn dagostino_pearson(v: &[f64]) -> Option<Normality> {
    if v.len() < 20 || v.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let n = v.len() as f64;
    let (m2, m3, m4) = moments(v);
    if m2 <= 0.0 {
        return None;
    }
    // Skewness, D'Agostino (1970).
    let b1 = m3 / m2.powf(1.5);
    let y = b1 * ((n + 1.0) * (n + 3.0) / (6.0 * (n - 2.0))).sqrt();
    let beta2 = 3.0 * (n * n + 27.0 * n - 70.0) * (n + 1.0) * (n + 3.0)
        / ((n - 2.0) * (n + 5.0) * (n + 7.0) * (n + 9.0));
    let w2 = -1.0 + (2.0 * (beta2 - 1.0)).sqrt();
    let delta = 1.0 / (0.5 * w2.ln()).sqrt();
    let alpha = (2.0 / (w2 - 1.0)).sqrt();
    let ya = y / alpha;
    let z1 = delta * (ya + (ya * ya + 1.0).sqrt()).ln();
    // Kurtosis, Anscombe & Glynn (1983).
    let b2 = m4 / (m2 * m2);
    let e = 3.0 * (n - 1.0) / (n + 1.0);
    let var = 24.0 * n * (n - 2.0) * (n - 3.0) / ((n + 1.0).powi(2) * (n + 3.0) * (n + 5.0));
    let x = (b2 - e) / var.sqrt();
    let sqrt_beta1 = 6.0 * (n * n - 5.0 * n + 2.0) / ((n + 7.0) * (n + 9.0))
        * (6.0 * (n + 3.0) * (n + 5.0) / (n * (n - 2.0) * (n - 3.0))).sqrt();
    let a = 6.0
        + 8.0 / sqrt_beta1 * (2.0 / sqrt_beta1 + (1.0 + 4.0 / (sqrt_beta1 * sqrt_beta1)).sqrt());
    let t = (1.0 - 2.0 / a) / (1.0 + x * (2.0 / (a - 4.0)).sqrt());
    let z2 = ((1.0 - 2.0 / (9.0 * a)) - t.cbrt()) / (2.0 / (9.0 * a)).sqrt();
    let k2 = z1 * z1 + z2 * z2;
    Some(Normality {
        z_skew: z1,
        z_kurt: z2,
        k2,
        p: (-k2 / 2.0).exp(),
    })
}

/// Kolmogorov-Smirnov distance to the fitted normal and its (conservative) p-value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct KsFit {
    pub n: usize,
    pub d: f64,
    pub p: f64,
}

/// Kolmogorov's limiting survival function `Q(l) = 2 sum_k (-1)^(k-1) exp(-2 k^2 l^2)`.
fn kolmogorov_q(l: f64) -> f64 {
    if l < 0.2 {
        return 1.0;
    }
    let mut sum = 0.0;
    for k in 1..=100 {
        let k = f64::from(k);
        let term = (-2.0 * k * k * l * l).exp();
        sum += if k as u64 % 2 == 1 { term } else { -term };
        if term < 1e-16 {
            break;
        }
    }
    (2.0 * sum).clamp(0.0, 1.0)
}

/// KS against the normal with the sample's own mean and sd; `None` below 3 values or for a
/// constant sample.
pub fn ks_normal(v: &[f64]) -> Option<KsFit> {
    let (mean, sd) = mean_sd(v);
    if v.len() < 3 || sd.is_nan() || sd <= 0.0 {
        return None;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len() as f64;
    let mut d = 0.0f64;
    for (i, x) in s.iter().enumerate() {
        let f = normal_cdf((x - mean) / sd);
        d = d.max((i as f64 + 1.0) / n - f).max(f - i as f64 / n);
    }
    let r = n.sqrt();
    Some(KsFit {
        n: s.len(),
        d,
        p: kolmogorov_q((r + 0.12 + 0.11 / r) * d),
    })
}

/// The seed's convergence curve (Fig. 3.5): KS of the first `n` values for `n` = 10, 20, ...
/// and the full sample.
pub fn ks_curve(v: &[f64]) -> Vec<KsFit> {
    let mut out = Vec::new();
    let mut n = 10;
    while n < v.len() {
        out.extend(ks_normal(&v[..n]));
        n += 10;
    }
    out.extend(ks_normal(v));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    fn normals(n: usize, seed: u64) -> Vec<f64> {
        let mut r = Pcg64::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let u1: f64 = 1.0 - r.random::<f64>();
                let u2: f64 = r.random();
                (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
            })
            .collect()
    }

    #[test]
    fn matches_scipy_on_fixed_samples() {
        // scripts/normaltest_reference.py (SciPy's normaltest, skewtest, kurtosistest and
        // kstest against the fitted normal): an independent implementation.
        let lumpy: Vec<f64> = (0..40)
            .map(|i| ((i * 7919) % 101) as f64 / 10.0 + ((i % 7) * (i % 7)) as f64 * 0.3)
            .collect();
        let skewed: Vec<f64> = (0..60)
            .map(|i| -(1.0 - (i as f64 + 0.5) / 60.0).ln())
            .collect();
        for (v, z1, z2, k2, p, d) in [
            (
                &lumpy,
                1.129370239764,
                -0.288969696051,
                1.358980623701,
                5.068752748590e-01,
                0.074596977771,
            ),
            (
                &skewed,
                4.421394689426,
                3.070192992544,
                28.974816011155,
                5.107385581387e-07,
                0.156512996891,
            ),
        ] {
            let t = dagostino_pearson(v).unwrap();
            assert!((t.z_skew - z1).abs() < 1e-9, "{t:?}");
            assert!((t.z_kurt - z2).abs() < 1e-9, "{t:?}");
            assert!((t.k2 - k2).abs() < 1e-8, "{t:?}");
            assert!(((t.p - p) / p).abs() < 1e-8, "{t:?}");
            let ks = ks_normal(v).unwrap();
            assert!((ks.d - d).abs() < 1e-9, "{ks:?}");
        }
        // A uniform sample is platykurtic (b2 = 1.8): strongly non-normal, and symmetric.
        let sym: Vec<f64> = (0..500).map(|i| (i as f64 + 0.5) / 500.0 - 0.5).collect();
        let t = dagostino_pearson(&sym).unwrap();
        assert!(
            t.z_skew.abs() < 1e-6 && t.z_kurt < -10.0 && t.p < 1e-20,
            "{t:?}"
        );
    }

    #[test]
    fn normal_samples_pass_and_skewed_ones_fail() {
        // Under the null, p is uniform: with 200 samples of 500 normals, about 5 % fall
        // below 0.05 (binomial sd 1.5 %: 2-9 % is a 3 sd band).
        let rejected = (0..200)
            .filter(|&s| dagostino_pearson(&normals(500, s)).unwrap().p < 0.05)
            .count();
        assert!((4..=18).contains(&rejected), "{rejected} of 200");
        // Exponential (skewness 2, excess kurtosis 6): rejected every time at n = 500.
        let mut r = Pcg64::seed_from_u64(9);
        let expo: Vec<f64> = (0..500).map(|_| -(1.0 - r.random::<f64>()).ln()).collect();
        let t = dagostino_pearson(&expo).unwrap();
        assert!(t.z_skew > 5.0 && t.p < 1e-10, "{t:?}");
        assert!(dagostino_pearson(&expo[..19]).is_none());
    }

    #[test]
    fn ks_distance_shrinks_for_normals_and_not_for_uniforms() {
        let v = normals(2000, 3);
        let curve = ks_curve(&v);
        let last = curve.last().unwrap();
        assert_eq!(last.n, 2000);
        // Lilliefors' 5 % critical value is 0.886 / sqrt n = 0.0198 at n = 2000.
        assert!(last.d < 0.0198, "{last:?}");
        assert!(curve[0].n == 10 && curve.len() == 200);
        let u: Vec<f64> = (0..2000).map(|i| i as f64).collect();
        let ku = ks_normal(&u).unwrap();
        // A uniform against its fitted normal: D tends to 0.0577.
        assert!((ku.d - 0.0577).abs() < 0.003 && ku.p < 0.01, "{ku:?}");
        assert!(ks_normal(&[1.0, 1.0, 1.0]).is_none());
    }

    #[test]
    fn kolmogorov_tail_matches_tabulated_critical_values() {
        // Q(1.358) = 0.05, Q(1.628) = 0.01 (the classical critical values).
        assert!((kolmogorov_q(1.3581) - 0.05).abs() < 1e-4);
        assert!((kolmogorov_q(1.6276) - 0.01).abs() < 1e-4);
    }

    #[test]
    fn summary_quantiles() {
        let v: Vec<f64> = (0..=100).map(f64::from).collect();
        let s = Summary::of(&v);
        assert_eq!(
            (s.median, s.q25, s.q75, s.p5, s.p95),
            (50.0, 25.0, 75.0, 5.0, 95.0)
        );
        assert_eq!(s.iqr(), 50.0);
    }
}
