//! # Sensor faults: per-sensor calibration factors
//!
//! A photometer out of calibration (or shaded, tilted, dirty) reads a fixed multiple of the
//! true illuminance. Signature: a constant ratio at one sensor, whatever the sky. The
//! random-intercept score already allows a few percent per sensor (the normal calibration
//! spread), so sensors are flagged one at a time, largest mean log residual first, while
//! each flag lowers the BIC; a flagged sensor's factor is exp(mean log residual).
//!
//! Only sensors whose residual is a *constant* ratio qualify: the spread of their log
//! residuals over time must be within [`MAX_SPREAD_RATIO`] times the median spread of all
//! sensors. A physical effect the model lacks (an obstruction, a shade) changes a sensor's
//! ratio with the sky and the sun; a miscalibrated photometer does not. And it must be an
//! outlier: its mean log residual at least [`OUTLIER_SIGMAS`] per-sensor spreads away from
//! the median sensor's (when every sensor reads 25 % low, the glazing is the suspect).

use super::Effect;
use crate::fit::{Fitter, without};

/// How much more a faulty sensor's residual may vary in time than the typical sensor's.
pub const MAX_SPREAD_RATIO: f64 = 1.5;
/// How far (in per-sensor spreads) from the median sensor a faulty one must be.
pub const OUTLIER_SIGMAS: f64 = 3.0;

/// Flag faulty sensors given the other effects in `base`.
pub fn fit(f: &Fitter, base: &[Effect]) -> Option<Effect> {
    let base = without(base, "sensor-fault");
    let sim = f.predict(&base);
    let ns = f.m.nsens();
    let mut factors: Vec<(usize, f64)> = Vec::new();
    let mut best = f.score_sim(&sim).bic(0.0);
    loop {
        // Mean log residual (measured / simulated) per sensor under the current flags.
        let mut sum = vec![0.0; ns];
        let mut sq = vec![0.0; ns];
        let mut cnt = vec![0usize; ns];
        for ((o, y), m) in f.m.obs.iter().zip(&sim).zip(&f.meas) {
            if *m >= crate::stats::MIN_MEASURED && *y > 0.0 {
                let r = (m / y).ln();
                sum[o.sensor] += r;
                sq[o.sensor] += r * r;
                cnt[o.sensor] += 1;
            }
        }
        let spread: Vec<f64> = (0..ns)
            .map(|s| {
                let n = cnt[s].max(1) as f64;
                (sq[s] / n - (sum[s] / n).powi(2)).max(0.0).sqrt()
            })
            .collect();
        let mut sorted: Vec<f64> = (0..ns).filter(|s| cnt[*s] > 1).map(|s| spread[s]).collect();
        sorted.sort_by(f64::total_cmp);
        let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
        let mut means: Vec<f64> = (0..ns)
            .filter(|s| cnt[*s] > 0)
            .map(|s| sum[s] / cnt[s] as f64)
            .collect();
        means.sort_by(f64::total_cmp);
        let mid = means.get(means.len() / 2).copied().unwrap_or(0.0);
        let outlier = |s: usize| {
            (sum[s] / cnt[s].max(1) as f64 - mid).abs() > OUTLIER_SIGMAS * f.sigma_sensor
        };
        let Some(next) = (0..ns)
            .filter(|s| cnt[*s] > 1 && spread[*s] <= MAX_SPREAD_RATIO * median && outlier(*s))
            .filter(|s| !factors.iter().any(|f| f.0 == *s))
            .max_by(|a, b| {
                let ma = (sum[*a] / cnt[*a] as f64).abs();
                let mb = (sum[*b] / cnt[*b] as f64).abs();
                ma.total_cmp(&mb)
            })
        else {
            break;
        };
        let mut trial = factors.clone();
        trial.push((next, (sum[next] / cnt[next] as f64).exp()));
        let e = Effect::SensorFault {
            factors: trial.clone(),
        };
        let w = f.m.weights(std::slice::from_ref(&e));
        let sim2: Vec<f64> = sim
            .iter()
            .zip(&f.m.obs)
            .map(|(y, o)| y * w.cal[o.sensor])
            .collect();
        let bic = f.score_sim(&sim2).bic(e.n_params());
        if bic >= best - 2.0 || trial.len() > ns / 2 {
            break;
        }
        best = bic;
        factors = trial;
    }
    (!factors.is_empty()).then_some(Effect::SensorFault { factors })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::score;
    use rand::{Rng, SeedableRng};

    fn normal(rng: &mut rand_pcg::Pcg64) -> f64 {
        let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-12), rng.random());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }

    /// The BIC of a fault on one sensor, with and without it, for 12 sensors x 18 readings
    /// (the independent cases' size) with 3 % calibration spread and 2 % reading noise,
    /// sensor 0 offset by `offset` (log ratio).
    fn bic_with_and_without(offset: f64, seed: u64) -> (f64, f64) {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let (ns, nt) = (12, 18);
        let (mut meas, mut sens) = (Vec::new(), Vec::new());
        for s in 0..ns {
            let off = if s == 0 {
                offset
            } else {
                0.03 * normal(&mut rng)
            };
            for _ in 0..nt {
                meas.push(1000.0 * (off + 0.02 * normal(&mut rng)).exp());
                sens.push(s);
            }
        }
        let sim = vec![1000.0; ns * nt];
        let mean0 = meas[..nt].iter().map(|m| (m / 1000.0).ln()).sum::<f64>() / nt as f64;
        let fixed: Vec<f64> = sim
            .iter()
            .zip(&sens)
            .map(|(y, s)| if *s == 0 { y * mean0.exp() } else { *y })
            .collect();
        let fault = Effect::SensorFault {
            factors: vec![(0, mean0.exp())],
        };
        let sigma = crate::score::DEFAULT_SENSOR_SIGMA;
        (
            score(&fixed, &meas, &sens, ns, sigma).bic(fault.n_params()),
            score(&sim, &meas, &sens, ns, sigma).bic(0.0),
        )
    }

    #[test]
    fn a_fault_at_the_noise_level_costs_more_than_it_gains() {
        // A sensor within twice the calibration spread: flagging it never pays, over many
        // draws of the noise.
        for seed in 0..20 {
            let (with, without) = bic_with_and_without(0.06, seed);
            assert!(with > without, "seed {seed}: {with} vs {without}");
        }
        // A real fault (reads x0.8, as in the fault-corner case) pays by far.
        for seed in 0..20 {
            let (with, without) = bic_with_and_without(0.8f64.ln(), seed);
            assert!(with < without - crate::score::SIGNIFICANT, "seed {seed}");
        }
    }
}
