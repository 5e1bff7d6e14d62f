//! # The seed's chapter-6 calibration: scan window transmittance options
//!
//! Options are the base transmittance multiplied or divided by `1 + step x 0.125`,
//! `step = 1..7` (seven up, seven down, plus the base), values kept within 0..1 (seed
//! sec. 6.3.4: "multiplying or dividing the transmittance values by 1 + step x 0.125, while
//! ensuring values remain between 0 and 1"). Each option is simulated at every measured
//! step (through the coefficients, as the transmittance effect) and scored by the mean
//! absolute error over sensors and steps (Eq. 6.1); the lowest MAE is selected.

use super::effects::Effect;
use super::model::Model;
use super::stats::Stats;
use serde::Serialize;

/// One option.
#[derive(Debug, Clone, Serialize)]
pub struct TmOption {
    /// `window_base`, `window_pos_3`, `window_neg_2`, ...
    pub name: String,
    /// Multiplier of the base transmissivity after keeping it within 0..1.
    pub factor: f64,
    pub transmissivity: f64,
    /// Eq. 6.1 (lux).
    pub mae: f64,
    pub stats: Stats,
}

/// All fifteen options, in step order, and the index of the best (lowest MAE).
pub fn scan(m: &Model) -> (Vec<TmOption>, usize) {
    let tn = m.room.glass_tn;
    let mut out = Vec::new();
    for step in -7i32..=7 {
        let f = 1.0 + step.unsigned_abs() as f64 * 0.125;
        let raw = if step >= 0 { tn * f } else { tn / f };
        let t = raw.clamp(0.0, 1.0);
        let factor = if tn > 0.0 { t / tn } else { 1.0 };
        let sim = m.predict(&[Effect::Transmittance { scale: factor }]);
        let pairs: Vec<(f64, f64)> = sim.iter().zip(&m.obs).map(|(y, o)| (*y, o.value)).collect();
        let stats = Stats::of(&pairs);
        let name = match step {
            0 => "window_base".to_string(),
            s if s > 0 => format!("window_pos_{s}"),
            s => format!("window_neg_{}", -s),
        };
        out.push(TmOption {
            name,
            factor,
            transmissivity: t,
            mae: stats.mae,
            stats,
        });
    }
    let best = (0..out.len())
        .min_by(|a, b| out[*a].mae.total_cmp(&out[*b].mae))
        .unwrap_or(7);
    (out, best)
}
