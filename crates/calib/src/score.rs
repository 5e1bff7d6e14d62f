//! # How well a model variant explains the readings: a noise-aware BIC
//!
//! Residuals are log ratios `r = ln(simulated / measured)` (sensor errors are
//! multiplicative). Real readings carry two kinds of noise the effects must not be fitted
//! to: a fixed calibration error per sensor (a few percent for class-B/L photometers,
//! CIE 69) and a per-reading error. So residuals are scored under a random-intercept model
//! (Laird & Ware 1982): `r_st = b_s + e_st`, `b_s ~ N(0, σ_c²)`, `e_st ~ N(0, σ_n²)`, whose
//! marginal log-likelihood per sensor with `T` readings, mean `r̄` and within-sensor sum of
//! squares `W` is
//!
//! ```text
//! -2 ln L_s = (T-1) ln σ_n² + ln(σ_n² + T σ_c²) + W/σ_n² + T r̄²/(σ_n² + T σ_c²)  (+ const)
//! ```
//!
//! with σ_n² estimated by maximum likelihood for every variant and σ_c given
//! ([`DEFAULT_SENSOR_SIGMA`], `--sensor-sigma`: the photometers' calibration class plus the
//! model's own Monte Carlo error per sensor). σ_c is not estimated because the estimate
//! would absorb exactly what the effects are for: twelve sensors all 30 % low look like a
//! large calibration spread to a maximum-likelihood fit. A missing physical effect shows up
//! as structure the random intercepts cannot absorb (a common bias, a pattern in time or
//! across sensors); a few percent of calibration spread does not. The
//! score is Schwarz's BIC: `-2 ln L + k ln n`; effects are kept when they lower it by more
//! than [`SIGNIFICANT`] (Kass & Raftery 1995: "very strong" evidence).

use super::stats::MIN_MEASURED;
use serde::Serialize;

/// Per-sensor spread assumed when none is given: class-B photometers (about 3 %, CIE 69)
/// plus a few percent of Monte Carlo error in the model's coefficients.
pub const DEFAULT_SENSOR_SIGMA: f64 = 0.05;

/// A BIC decrease larger than this counts as a significant effect.
pub const SIGNIFICANT: f64 = 10.0;

/// Fit quality of one model variant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Default)]
pub struct Score {
    /// -2 ln L (without the constant).
    pub m2ll: f64,
    /// Number of log residuals used.
    pub n: usize,
    /// Per-reading noise (relative, ~ln ratio).
    pub sigma_reading: f64,
    /// Spread of per-sensor offsets (relative).
    pub sigma_sensor: f64,
}

impl Score {
    /// BIC with `k` effect parameters (effective ones for a penalised profile).
    pub fn bic(&self, k: f64) -> f64 {
        self.m2ll + k * (self.n.max(1) as f64).ln()
    }
}

/// Score simulated against measured readings, grouped by `sensor` index, with per-sensor
/// spread `sigma_sensor`.
pub fn score(
    sim: &[f64],
    meas: &[f64],
    sensor: &[usize],
    nsens: usize,
    sigma_sensor: f64,
) -> Score {
    let mut sum = vec![0.0; nsens];
    let mut sq = vec![0.0; nsens];
    let mut cnt = vec![0usize; nsens];
    for ((&y, &m), &s) in sim.iter().zip(meas).zip(sensor) {
        if m < MIN_MEASURED || s >= nsens {
            continue;
        }
        let r = (y.max(0.01 * MIN_MEASURED) / m).ln();
        sum[s] += r;
        sq[s] += r * r;
        cnt[s] += 1;
    }
    let n: usize = cnt.iter().sum();
    let groups: Vec<(f64, f64, f64)> = (0..nsens)
        .filter(|&s| cnt[s] > 0)
        .map(|s| {
            let t = cnt[s] as f64;
            let mean = sum[s] / t;
            (t, mean, (sq[s] - t * mean * mean).max(0.0))
        })
        .collect();
    if n == 0 {
        return Score::default();
    }
    let dof = (n - groups.len()).max(1) as f64;
    let within: f64 = groups.iter().map(|g| g.2).sum();
    // Floor: readings are never more precise than 0.1 % (keeps ln finite for exact fits).
    let sn2 = (within / dof).max(1e-6);
    let m2ll = |sc2: f64| -> f64 {
        groups
            .iter()
            .map(|&(t, mean, w)| {
                let v = sn2 + t * sc2;
                (t - 1.0) * sn2.ln() + v.ln() + w / sn2 + t * mean * mean / v
            })
            .sum()
    };
    let sc2 = sigma_sensor * sigma_sensor;
    let best = m2ll(sc2);
    Score {
        m2ll: best,
        n,
        sigma_reading: sn2.sqrt(),
        sigma_sensor: sc2.sqrt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn normal(rng: &mut rand_pcg::Pcg64) -> f64 {
        let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-12), rng.random());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }

    #[test]
    fn recovers_reading_noise_and_penalises_bias() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        let (ns, nt) = (20, 50);
        let mut meas = Vec::new();
        let mut sens = Vec::new();
        let offsets: Vec<f64> = (0..ns).map(|_| 0.03 * normal(&mut rng)).collect();
        for (s, off) in offsets.iter().enumerate() {
            for _ in 0..nt {
                meas.push(1000.0 * (off + 0.02 * normal(&mut rng)).exp());
                sens.push(s);
            }
        }
        let sim = vec![1000.0; ns * nt];
        let sc = score(&sim, &meas, &sens, ns, 0.03);
        assert!((sc.sigma_reading - 0.02).abs() < 0.003, "{sc:?}");
        // A 20 % common bias costs far more than the significance threshold.
        let biased: Vec<f64> = sim.iter().map(|v| v * 1.2).collect();
        let sb = score(&biased, &meas, &sens, ns, 0.03);
        assert!(
            sb.m2ll - sc.m2ll > 10.0 * SIGNIFICANT,
            "{} {}",
            sb.m2ll,
            sc.m2ll
        );
        // A 1 % bias is within the calibration spread.
        let small: Vec<f64> = sim.iter().map(|v| v * 1.01).collect();
        let ss = score(&small, &meas, &sens, ns, 0.03);
        assert!(
            (ss.m2ll - sc.m2ll).abs() < SIGNIFICANT,
            "{} {}",
            ss.m2ll,
            sc.m2ll
        );
    }
}
