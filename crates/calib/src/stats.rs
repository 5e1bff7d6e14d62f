//! # Agreement statistics (seed chapter 6)
//!
//! With `y` simulated and `ŷ` measured (the seed's Eq. 6.2-6.4 notation), over `n`
//! observations:
//!
//! ```text
//! MBE_rel   = 100/n Σ (y - ŷ)/ŷ                                  (6.2)
//! RMSE_rel  = 100 sqrt(1/n Σ ((y - ŷ)/ŷ)^2)                       (6.3)
//! sigma_rel = 100 sqrt(1/n Σ ((y - ŷ)/ŷ - mean((y - ŷ)/ŷ))^2)     (6.4)
//! MAE       = 1/n Σ |y - ŷ|          (Eq. 6.1 averaged over sensors and steps)
//! ```
//!
//! plus Pearson's r between `y` and `ŷ`. Observations with `ŷ` below [`MIN_MEASURED`] lux
//! are left out of the relative measures (a relative error of a reading near zero says
//! nothing about the model) and counted in `excluded`.

use serde::Serialize;

/// Readings below this (lux) are not used in relative errors.
pub const MIN_MEASURED: f64 = 1.0;

/// Summary statistics of simulated against measured values.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Default)]
pub struct Stats {
    pub n: usize,
    pub excluded: usize,
    /// Eq. 6.2, percent.
    pub mbe_rel: f64,
    /// Eq. 6.3, percent.
    pub rmse_rel: f64,
    /// Eq. 6.4, percent.
    pub sigma_rel: f64,
    /// Pearson correlation of simulated and measured values.
    pub r: f64,
    /// Eq. 6.1 (lux).
    pub mae: f64,
}

/// Relative error (y - ŷ)/ŷ, `None` when the reading is too small.
pub fn rel_error(sim: f64, meas: f64) -> Option<f64> {
    (meas >= MIN_MEASURED).then(|| (sim - meas) / meas)
}

impl Stats {
    /// Statistics of pairs (simulated, measured).
    pub fn of(pairs: &[(f64, f64)]) -> Stats {
        let rel: Vec<f64> = pairs.iter().filter_map(|&(y, m)| rel_error(y, m)).collect();
        let n = rel.len();
        let mut st = Stats {
            n,
            excluded: pairs.len() - n,
            ..Stats::default()
        };
        if !pairs.is_empty() {
            st.mae = pairs.iter().map(|(y, m)| (y - m).abs()).sum::<f64>() / pairs.len() as f64;
            st.r = pearson(pairs);
        }
        if n == 0 {
            return st;
        }
        let mean = rel.iter().sum::<f64>() / n as f64;
        st.mbe_rel = 100.0 * mean;
        st.rmse_rel = 100.0 * (rel.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
        st.sigma_rel =
            100.0 * (rel.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
        st
    }
}

/// Pearson's correlation coefficient (0 when either side is constant).
pub fn pearson(pairs: &[(f64, f64)]) -> f64 {
    let n = pairs.len() as f64;
    if pairs.len() < 2 {
        return 0.0;
    }
    let mx = pairs.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pairs.iter().map(|p| p.1).sum::<f64>() / n;
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for &(x, y) in pairs {
        sxy += (x - mx) * (y - my);
        sxx += (x - mx) * (x - mx);
        syy += (y - my) * (y - my);
    }
    if sxx <= 0.0 || syy <= 0.0 {
        0.0
    } else {
        sxy / (sxx * syy).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equations_6_2_to_6_4() {
        // Relative errors +10 % and -10 %: no bias, RMSE 10 %, sigma 10 %.
        let s = Stats::of(&[(110.0, 100.0), (180.0, 200.0)]);
        assert!((s.mbe_rel).abs() < 1e-12);
        assert!((s.rmse_rel - 10.0).abs() < 1e-12);
        assert!((s.sigma_rel - 10.0).abs() < 1e-12);
        // A constant +20 %: bias 20, RMSE 20, sigma 0, r = 1.
        let s = Stats::of(&[(120.0, 100.0), (240.0, 200.0), (60.0, 50.0)]);
        assert!((s.mbe_rel - 20.0).abs() < 1e-12 && (s.rmse_rel - 20.0).abs() < 1e-12);
        assert!(s.sigma_rel.abs() < 1e-9 && (s.r - 1.0).abs() < 1e-12);
        assert!((s.mae - (20.0 + 40.0 + 10.0) / 3.0).abs() < 1e-12);
        // Tiny readings are excluded from relative measures.
        let s = Stats::of(&[(5.0, 0.1), (100.0, 100.0)]);
        assert_eq!((s.n, s.excluded), (1, 1));
        assert_eq!(s.rmse_rel, 0.0);
    }
}
