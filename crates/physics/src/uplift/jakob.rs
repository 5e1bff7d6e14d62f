//! Jakob & Hanika (2019) sigmoid-of-quadratic reflectance model.
//!
//! W. Jakob, J. Hanika, "A Low-Dimensional Function Space for Efficient Spectral Upsampling",
//! Computer Graphics Forum 38(2), 2019:
//!
//! ```text
//! s(l) = S(x(l)),   S(x) = 1/2 + x / (2 sqrt(1 + x^2)),   x(l) = c0 t^2 + c1 t + c2
//! ```
//!
//! with `t = (l - 380 nm) / 400 nm` (the paper fits on a normalised wavelength too; the
//! coefficients here are in `t`, see [`Jakob::coefficients_nm`] for nm). `S` maps the real
//! line onto (0, 1), so every spectrum is smooth and bounded. The three coefficients are fitted
//! by damped Gauss-Newton on the CIELAB difference to the target (as the paper does:
//! "we minimise the CIE76 Delta E"). Gauss-Newton from the grey start `c = 0` can stall for
//! saturated targets; the paper then continues from neighbouring table entries. Here the same
//! idea runs along a path: the target is approached from the flat spectrum of equal
//! lightness in [`STEPS`] steps, each warm-started from the previous solution.
//!
//! Out of gamut (no reflectance in 0..1 has the target colour, e.g. negative RGB or RGB > 1
//! in a channel), the fit returns the closest model spectrum in CIELAB; the residual Delta
//! E*ab is reported with it.

use super::solve::levenberg_marquardt;
use crate::colour::cie::{Observer, Spectrum, WL_MIN, delta_e, wavelengths};

/// Continuation steps used when the direct fit does not converge.
pub const STEPS: usize = 16;

/// Convergence tolerance on Delta E*ab.
pub const TOL: f64 = 1e-6;

/// The model: three coefficients in normalised wavelength `t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jakob {
    pub c: [f64; 3],
}

/// The sigmoid `S(x)`.
pub fn sigmoid(x: f64) -> f64 {
    if x.is_infinite() {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + x / (2.0 * (1.0 + x * x).sqrt())
}

impl Jakob {
    /// The spectrum on the grid.
    pub fn spectrum(&self) -> Spectrum {
        let wl = wavelengths();
        std::array::from_fn(|i| {
            let t = (wl[i] - WL_MIN) / 400.0;
            sigmoid((self.c[0] * t + self.c[1]) * t + self.c[2])
        })
    }

    /// Coefficients for `x(l) = a l^2 + b l + c` with `l` in nm.
    pub fn coefficients_nm(&self) -> [f64; 3] {
        let [c0, c1, c2] = self.c;
        let k = 1.0 / 400.0;
        let o = -WL_MIN / 400.0;
        // t = k l + o
        [
            c0 * k * k,
            2.0 * c0 * k * o + c1 * k,
            c0 * o * o + c1 * o + c2,
        ]
    }

    /// Fit the model to a target XYZ under the observer's illuminant; returns the model and
    /// the residual Delta E*ab.
    pub fn fit(obs: &Observer, xyz: [f64; 3]) -> (Jakob, f64) {
        let target = obs.lab(xyz);
        let resid = |target: [f64; 3]| {
            move |c: &[f64]| {
                let s = Jakob {
                    c: [c[0], c[1], c[2]],
                }
                .spectrum();
                let l = obs.lab(obs.spectrum_xyz(&s));
                vec![l[0] - target[0], l[1] - target[1], l[2] - target[2]]
            }
        };
        let direct = levenberg_marquardt(&resid(target), &[0.0, 0.0, 0.0], TOL, 100);
        if direct.cost < TOL {
            return Self::done(obs, &direct.x, xyz);
        }
        // Continuation from the flat grey of the target's lightness (clamped into the
        // model's range), warm-starting each step.
        let lstar = target[0].clamp(0.5, 99.5);
        let mut c = {
            // S(c2) = grey reflectance with lightness L*: Y from L*.
            let fy = (lstar + 16.0) / 116.0;
            let y = if fy > 6.0 / 29.0 {
                fy.powi(3)
            } else {
                3.0 * (6.0f64 / 29.0).powi(2) * (fy - 4.0 / 29.0)
            };
            let y = y.clamp(1e-4, 1.0 - 1e-4);
            // Inverse of S: x = (2y - 1) / (2 sqrt(y (1 - y))).
            vec![0.0, 0.0, (2.0 * y - 1.0) / (2.0 * (y * (1.0 - y)).sqrt())]
        };
        let start = [lstar, 0.0, 0.0];
        for k in 1..=STEPS {
            let f = k as f64 / STEPS as f64;
            let t: [f64; 3] = std::array::from_fn(|i| start[i] + f * (target[i] - start[i]));
            let tol = if k == STEPS { TOL } else { 1e-3 };
            c = levenberg_marquardt(&resid(t), &c, tol, 100).x;
        }
        let best = if levenberg_marquardt(&resid(target), &c, TOL, 0).cost < direct.cost {
            c
        } else {
            direct.x
        };
        Self::done(obs, &best, xyz)
    }

    fn done(obs: &Observer, c: &[f64], xyz: [f64; 3]) -> (Jakob, f64) {
        let m = Jakob {
            c: [c[0], c[1], c[2]],
        };
        let de = delta_e(obs.lab(obs.spectrum_xyz(&m.spectrum())), obs.lab(xyz));
        (m, de)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::cie::{N, RgbSpace};

    #[test]
    fn sigmoid_bounds_and_nm_form() {
        assert_eq!(sigmoid(0.0), 0.5);
        assert!(sigmoid(1e6) <= 1.0 && sigmoid(-1e6) >= 0.0);
        let m = Jakob {
            c: [3.0, -2.0, 0.5],
        };
        let [a, b, c] = m.coefficients_nm();
        let s = m.spectrum();
        for (i, l) in wavelengths().iter().enumerate() {
            assert!((sigmoid(a * l * l + b * l + c) - s[i]).abs() < 1e-9);
        }
        assert_eq!(s.len(), N);
    }

    #[test]
    fn fits_in_gamut_colours() {
        let obs = Observer::new(RgbSpace::Radiance);
        for rgb in [
            [0.5, 0.5, 0.5],
            [0.8, 0.2, 0.1],
            [0.05, 0.3, 0.6],
            [0.9, 0.9, 0.2],
        ] {
            let (m, de) = Jakob::fit(&obs, obs.rgb_to_xyz(rgb));
            assert!(de < 1e-3, "{rgb:?}: dE {de}");
            assert!(m.spectrum().iter().all(|&v| (0.0..=1.0).contains(&v)));
        }
    }
}
