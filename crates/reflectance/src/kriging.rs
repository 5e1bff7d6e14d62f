//! Ordinary kriging with a fitted variogram, for the illuminance-proxy method ([`super::proxy`]).
//!
//! Data: values `z_i` at points `x_i` (here pixel coordinates). Steps (Cressie 1993,
//! *Statistics for Spatial Data*, sections 2.3-2.6 and 3.2):
//!
//! 1. Empirical semivariogram (Matheron's estimator): pairs binned by distance, per bin
//!    `g_k = 1 / (2 N_k) sum (z_i - z_j)^2` at the bin's mean distance `h_k`.
//! 2. Model `gamma(h) = c0 + c f(h / a)` for `h > 0`, `gamma(0) = 0`, with nugget `c0`, partial
//!    sill `c`, range `a` and
//!    - spherical: `f(t) = 1.5 t - 0.5 t^3` for `t < 1`, else 1;
//!    - exponential: `f(t) = 1 - exp(-3 t)` (practical range `a`).
//! 3. Fit by Cressie's (1985) weighted least squares,
//!    `min sum_k N_k (g_k / gamma(h_k) - 1)^2`, which weights bins by their pair count and
//!    fits short lags (small gamma) more closely. The range and the nugget fraction
//!    `r = c0 / (c0 + c)` are searched on a grid (range: 40 steps, geometric, from the
//!    smallest to twice the largest lag; `r` in 0, 0.05, ..., 0.9); for given `a` and `r`
//!    the total sill `s` has the closed form `1/s = sum N_k u_k / sum N_k u_k^2` with
//!    `u_k = g_k / g(h_k; a, r, s = 1)`.
//! 4. Ordinary kriging: the unbiased linear predictor of least variance,
//!    `[Gamma 1; 1' 0] [lambda; mu] = [gamma_0; 1]`; computed in dual form: solve once
//!    `[Gamma 1; 1' 0] [w; m] = [z; 0]`, then `z*(x) = sum_i w_i gamma(|x - x_i|) + m`
//!    (the same predictor: the system matrix is symmetric), O(n) per pixel.
//!
//! Degenerate data: fewer than [`MIN_POINTS`] points, or values without variance, give the
//! mean everywhere (what kriging tends to with a pure-nugget variogram).

use nalgebra::{DMatrix, DVector};

use crate::error::{Error, Result};

/// Fewest points for which a variogram is fitted.
pub const MIN_POINTS: usize = 4;

/// Variogram model family.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    Spherical,
    Exponential,
}

/// A fitted variogram `gamma(h) = nugget + psill f(h / range)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variogram {
    pub family: Family,
    pub nugget: f64,
    pub psill: f64,
    pub range: f64,
}

impl Variogram {
    /// Semivariance at distance `h` (0 at `h = 0`).
    pub fn gamma(&self, h: f64) -> f64 {
        if h <= 0.0 {
            return 0.0;
        }
        let t = h / self.range;
        let f = match self.family {
            Family::Spherical => {
                if t < 1.0 {
                    1.5 * t - 0.5 * t * t * t
                } else {
                    1.0
                }
            }
            Family::Exponential => 1.0 - (-3.0 * t).exp(),
        };
        self.nugget + self.psill * f
    }
}

/// Empirical semivariogram: `(mean lag, semivariance, pairs)` per non-empty bin.
pub fn empirical(points: &[[f64; 2]], z: &[f64]) -> Vec<(f64, f64, usize)> {
    let n = points.len();
    let mut pairs = Vec::with_capacity(n * n.saturating_sub(1) / 2);
    for i in 0..n {
        for j in i + 1..n {
            let h = dist(points[i], points[j]);
            pairs.push((h, 0.5 * (z[i] - z[j]).powi(2)));
        }
    }
    let hmax = pairs.iter().map(|p| p.0).fold(0.0, f64::max);
    if pairs.is_empty() || hmax <= 0.0 {
        return Vec::new();
    }
    // About six pairs per bin on average, 3 to 15 bins, lags up to the largest distance
    // (sparse data: cutting at half the largest distance, the textbook rule, leaves too few
    // bins).
    let nbins = (pairs.len() / 6).clamp(3, 15);
    let width = hmax / nbins as f64;
    let mut bins = vec![(0.0, 0.0, 0usize); nbins];
    for (h, g) in pairs {
        let k = ((h / width) as usize).min(nbins - 1);
        bins[k].0 += h;
        bins[k].1 += g;
        bins[k].2 += 1;
    }
    bins.into_iter()
        .filter(|b| b.2 > 0)
        .map(|(h, g, n)| (h / n as f64, g / n as f64, n))
        .collect()
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// Fit a variogram of `family` to the empirical one by Cressie's weighted least squares.
/// `None` when there is nothing to fit (fewer than two bins or no variance).
pub fn fit(emp: &[(f64, f64, usize)], family: Family) -> Option<Variogram> {
    if emp.len() < 2 || emp.iter().all(|b| b.1 <= 0.0) {
        return None;
    }
    let hmin = emp
        .iter()
        .map(|b| b.0)
        .fold(f64::INFINITY, f64::min)
        .max(1e-9);
    let hmax = emp.iter().map(|b| b.0).fold(0.0, f64::max);
    let (lo, hi) = (hmin, 2.0 * hmax);
    let mut best: Option<(f64, Variogram)> = None;
    for ia in 0..40 {
        let range = lo * (hi / lo).powf(ia as f64 / 39.0);
        for ir in 0..19 {
            let r = 0.05 * ir as f64;
            let unit = Variogram {
                family,
                nugget: r,
                psill: 1.0 - r,
                range,
            };
            let (mut a, mut b) = (0.0, 0.0);
            for &(h, g, n) in emp {
                let u = g / unit.gamma(h);
                a += n as f64 * u;
                b += n as f64 * u * u;
            }
            if b <= 0.0 {
                continue;
            }
            let s = b / a; // 1/s = a/b
            let v = Variogram {
                family,
                nugget: r * s,
                psill: (1.0 - r) * s,
                range,
            };
            let cost: f64 = emp
                .iter()
                .map(|&(h, g, n)| n as f64 * (g / v.gamma(h) - 1.0).powi(2))
                .sum();
            if cost.is_finite() && best.as_ref().is_none_or(|(c, _)| cost < *c) {
                best = Some((cost, v));
            }
        }
    }
    best.map(|b| b.1)
}

/// An ordinary kriging predictor (dual form) of one variable.
#[derive(Debug, Clone)]
pub struct Kriging {
    points: Vec<[f64; 2]>,
    /// Dual weights `w` and the Lagrange term `m`; `None` = constant `mean`.
    dual: Option<(Vec<f64>, f64)>,
    variogram: Option<Variogram>,
    mean: f64,
}

impl Kriging {
    /// Fit the variogram and solve the kriging system for values `z` at `points`.
    pub fn new(points: &[[f64; 2]], z: &[f64], family: Family) -> Result<Kriging> {
        if points.len() != z.len() || points.is_empty() {
            return Err(Error::Mismatch(format!(
                "kriging needs as many values as points (at least one), got {} and {}",
                z.len(),
                points.len()
            )));
        }
        let n = points.len();
        for i in 0..n {
            for j in i + 1..n {
                if points[i] == points[j] {
                    return Err(Error::Usage(format!(
                        "two known points at the same place ({}, {}): give each point once",
                        points[i][0], points[i][1]
                    )));
                }
            }
        }
        let mean = z.iter().sum::<f64>() / n as f64;
        let constant = Kriging {
            points: points.to_vec(),
            dual: None,
            variogram: None,
            mean,
        };
        if n < MIN_POINTS {
            return Ok(constant);
        }
        let Some(v) = fit(&empirical(points, z), family) else {
            return Ok(constant);
        };
        let mut a = DMatrix::<f64>::zeros(n + 1, n + 1);
        for i in 0..n {
            for j in 0..n {
                a[(i, j)] = v.gamma(dist(points[i], points[j]));
            }
            a[(i, n)] = 1.0;
            a[(n, i)] = 1.0;
        }
        let mut rhs = DVector::<f64>::zeros(n + 1);
        for i in 0..n {
            rhs[i] = z[i];
        }
        let sol = a.lu().solve(&rhs).ok_or_else(|| {
            Error::Usage("the kriging system is singular (points on top of each other?)".into())
        })?;
        Ok(Kriging {
            points: points.to_vec(),
            dual: Some(((0..n).map(|i| sol[i]).collect(), sol[n])),
            variogram: Some(v),
            mean,
        })
    }

    /// The prediction at `x`.
    pub fn predict(&self, x: [f64; 2]) -> f64 {
        match (&self.dual, &self.variogram) {
            (Some((w, m)), Some(v)) => {
                m + self
                    .points
                    .iter()
                    .zip(w)
                    .map(|(p, wi)| wi * v.gamma(dist(*p, x)))
                    .sum::<f64>()
            }
            _ => self.mean,
        }
    }

    /// The fitted variogram (`None`: constant predictor).
    pub fn variogram(&self) -> Option<Variogram> {
        self.variogram
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(p: [f64; 2]) -> f64 {
        // A smooth illuminance-like field: 1000 lx with a gradient and a bump.
        1000.0 + 4.0 * p[0] - 2.5 * p[1] + 200.0 * (-((p[0] - 40.0).powi(2) / 800.0)).exp()
    }

    fn grid() -> Vec<[f64; 2]> {
        let mut v = Vec::new();
        for i in 0..6 {
            for j in 0..6 {
                v.push([
                    5.0 + 18.0 * i as f64 + (j % 2) as f64 * 3.0,
                    4.0 + 19.0 * j as f64,
                ]);
            }
        }
        v
    }

    #[test]
    fn variogram_shapes() {
        let s = Variogram {
            family: Family::Spherical,
            nugget: 1.0,
            psill: 2.0,
            range: 10.0,
        };
        assert_eq!(s.gamma(0.0), 0.0);
        assert!((s.gamma(5.0) - (1.0 + 2.0 * (0.75 - 0.0625))).abs() < 1e-12);
        assert_eq!(s.gamma(10.0), 3.0);
        assert_eq!(s.gamma(50.0), 3.0);
        let e = Variogram {
            family: Family::Exponential,
            ..s
        };
        assert!((e.gamma(10.0) - (1.0 + 2.0 * (1.0 - (-3.0f64).exp()))).abs() < 1e-12);
    }

    #[test]
    fn fit_recovers_a_known_variogram() {
        // Bins sampled exactly from a model: the fit finds it (grid resolution).
        let truth = Variogram {
            family: Family::Spherical,
            nugget: 0.0,
            psill: 5.0,
            range: 30.0,
        };
        let emp: Vec<(f64, f64, usize)> = (1..12)
            .map(|k| (4.0 * k as f64, truth.gamma(4.0 * k as f64), 10))
            .collect();
        let v = fit(&emp, Family::Spherical).unwrap();
        assert!(
            v.nugget < 0.3 && (v.nugget + v.psill - 5.0).abs() < 0.3,
            "{v:?}"
        );
        assert!((v.range - 30.0).abs() < 3.0, "{v:?}");
    }

    #[test]
    fn kriging_interpolates_exactly_and_predicts_smooth_fields() {
        let pts = grid();
        let z: Vec<f64> = pts.iter().map(|p| field(*p)).collect();
        for family in [Family::Spherical, Family::Exponential] {
            let k = Kriging::new(&pts, &z, family).unwrap();
            assert!(k.variogram().is_some());
            // Exact at the data (ordinary kriging is an exact interpolator).
            for (p, zi) in pts.iter().zip(&z) {
                assert!((k.predict(*p) - zi).abs() < 1e-6 * zi, "{family:?}");
            }
            // Between the data: within 2 % of the smooth field.
            let mut worst: f64 = 0.0;
            for x in (10..95).step_by(7) {
                for y in (10..95).step_by(7) {
                    let p = [x as f64, y as f64];
                    worst = worst.max((k.predict(p) / field(p) - 1.0).abs());
                }
            }
            assert!(worst < 0.02, "{family:?}: worst relative error {worst}");
        }
    }

    #[test]
    fn degenerate_inputs() {
        let k = Kriging::new(&[[0.0, 0.0], [1.0, 1.0]], &[2.0, 4.0], Family::Spherical).unwrap();
        assert_eq!(k.predict([5.0, 5.0]), 3.0);
        let pts = grid();
        let k = Kriging::new(&pts, &vec![7.0; pts.len()], Family::Spherical).unwrap();
        assert!(k.variogram().is_none());
        assert_eq!(k.predict([1.0, 2.0]), 7.0);
        assert!(Kriging::new(&pts, &[1.0], Family::Spherical).is_err());
        let mut dup = pts.clone();
        dup.push(pts[0]);
        let mut z: Vec<f64> = pts.iter().map(|p| field(*p)).collect();
        z.push(z[0] + 1.0);
        assert!(Kriging::new(&dup, &z, Family::Spherical).is_err());
    }
}
