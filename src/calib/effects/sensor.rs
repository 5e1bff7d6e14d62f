//! # Sensor faults: per-sensor calibration factors
//!
//! A photometer out of calibration (or shaded, tilted, dirty) reads a fixed multiple of the
//! true illuminance. Signature: a constant ratio at one sensor, whatever the sky. The
//! random-intercept score already allows a few percent per sensor (the normal calibration
//! spread), so sensors are flagged one at a time, largest mean log residual first, while
//! each flag lowers the BIC; a flagged sensor's factor is exp(mean log residual).

use super::Effect;
use crate::calib::fit::{Fitter, without};

/// Flag faulty sensors given the other effects in `base`.
pub fn fit(f: &Fitter, base: &[Effect]) -> Option<Effect> {
    let base = without(base, "sensor-fault");
    let sim = f.m.predict(&base);
    let ns = f.m.nsens();
    let mut factors: Vec<(usize, f64)> = Vec::new();
    let mut best = f.score_sim(&sim).bic(0);
    loop {
        // Mean log residual (measured / simulated) per sensor under the current flags.
        let mut sum = vec![0.0; ns];
        let mut cnt = vec![0usize; ns];
        for ((o, y), m) in f.m.obs.iter().zip(&sim).zip(&f.meas) {
            if *m >= crate::calib::stats::MIN_MEASURED && *y > 0.0 {
                sum[o.sensor] += (m / y).ln();
                cnt[o.sensor] += 1;
            }
        }
        let Some(next) = (0..ns)
            .filter(|s| cnt[*s] > 0 && !factors.iter().any(|f| f.0 == *s))
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
        let bic = f.score_sim(&sim2).bic(trial.len());
        if bic >= best - 2.0 || trial.len() > ns / 2 {
            break;
        }
        best = bic;
        factors = trial;
    }
    (!factors.is_empty()).then_some(Effect::SensorFault { factors })
}
