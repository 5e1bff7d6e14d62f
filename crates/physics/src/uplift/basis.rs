//! Uplifting with a low-dimensional basis learned from measured reflectances.
//!
//! Model (a logit-space principal-component model, in the spirit of the linear models of
//! Maloney 1986 and the statistical uplifting of e.g. Otsu et al. 2018):
//!
//! ```text
//! s(l) = sigma(mu(l) + sum_k c_k b_k(l)),   sigma(z) = 1 / (1 + e^-z)
//! ```
//!
//! `mu` and `b_k` are the mean and the first K principal components (eigenvalues `lambda_k`)
//! of `logit(s)` over a training set of measured spectra (Munsell chips, see
//! [`Basis::munsell_training`]). Working in logit space keeps every spectrum inside (0, 1)
//! by construction. Given a target colour XYZ, the coefficients solve
//!
//! ```text
//! minimise  sum_k c_k^2 / lambda_k     subject to   W s(c) = XYZ
//! ```
//!
//! (the most probable spectrum under a Gaussian model of the training set that reproduces
//! the colour exactly; `W` is the 3 x N reflectance->XYZ matrix). Solved by sequential
//! linearisation: at `c`, with `J = W diag(sigma'(z)) B`, the minimum-norm solution of the
//! linearised constraint is `c' = L J^T (J L J^T)^-1 (r + J c)` (`L = diag(lambda)`,
//! `r` = XYZ residual), with step halving on the CIELAB error. For K = 3 this is Newton's
//! method on the 3 x 3 system.
//!
//! Out of gamut or if the iteration stalls, the fit falls back to Levenberg-Marquardt on the
//! CIELAB difference plus a weak prior term, i.e. the closest in-model colour; the residual
//! Delta E*ab is reported.

use std::sync::OnceLock;

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use super::solve::levenberg_marquardt;
use crate::colour::cie::{N, Observer, Spectrum, Table, delta_e};

/// Reflectances are clamped to this margin before the logit (measured values of 0 or 1).
const EPS: f64 = 1e-3;

/// Default number of components (chosen on an inner split of the training set, see
/// `docs/uplift-validation.md`).
pub const DEFAULT_K: usize = 5;

/// A learned basis.
#[derive(Debug, Clone)]
pub struct Basis {
    pub mean: Spectrum,
    /// Components (unit length), largest variance first.
    pub components: Vec<Spectrum>,
    /// Variances along the components.
    pub variances: Vec<f64>,
}

fn logit(s: f64) -> f64 {
    let s = s.clamp(EPS, 1.0 - EPS);
    (s / (1.0 - s)).ln()
}

fn logistic(z: f64) -> f64 {
    1.0 / (1.0 + (-z).exp())
}

/// Is Munsell chip `i` (0-based) in the held-out split? Every 5th chip is held out.
pub fn munsell_held_out(i: usize) -> bool {
    i % 5 == 4
}

/// The compiled-in Munsell set (1269 chips, 5 nm).
pub fn munsell() -> &'static [(String, Spectrum)] {
    static M: OnceLock<Vec<(String, Spectrum)>> = OnceLock::new();
    M.get_or_init(|| {
        let name = "munsell1269_5nm.csv";
        Table::parse(
            include_str!("../../../../data/spectra/munsell1269_5nm.csv"),
            name,
        )
        .and_then(|t| t.all_on_grid(name))
        .unwrap_or_else(|e| panic!("embedded table {name}: {e}"))
    })
}

/// The compiled-in ColorChecker set (24 patches).
pub fn colorchecker() -> &'static [(String, Spectrum)] {
    static M: OnceLock<Vec<(String, Spectrum)>> = OnceLock::new();
    M.get_or_init(|| {
        let name = "macbeth_colorchecker24.csv";
        Table::parse(
            include_str!("../../../../data/spectra/macbeth_colorchecker24.csv"),
            name,
        )
        .and_then(|t| t.all_on_grid(name))
        .unwrap_or_else(|e| panic!("embedded table {name}: {e}"))
    })
}

impl Basis {
    /// Learn mean and the first `k` components of logit reflectance.
    pub fn learn(training: &[&Spectrum], k: usize) -> Basis {
        let k = k.clamp(1, N);
        let m = training.len().max(1);
        let z: Vec<Spectrum> = training.iter().map(|s| s.map(logit)).collect();
        let mut mean = [0.0; N];
        for s in &z {
            for i in 0..N {
                mean[i] += s[i] / m as f64;
            }
        }
        let mut cov = DMatrix::<f64>::zeros(N, N);
        for s in &z {
            let d = DVector::from_iterator(N, (0..N).map(|i| s[i] - mean[i]));
            cov += &d * d.transpose();
        }
        cov /= (m.max(2) - 1) as f64;
        let eig = SymmetricEigen::new(cov);
        let mut order: Vec<usize> = (0..N).collect();
        order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
        let components = order[..k]
            .iter()
            .map(|&j| std::array::from_fn(|i| eig.eigenvectors[(i, j)]))
            .collect();
        let variances = order[..k]
            .iter()
            .map(|&j| eig.eigenvalues[j].max(1e-12))
            .collect();
        Basis {
            mean,
            components,
            variances,
        }
    }

    /// The basis learned on the training split of the Munsell set (every chip not held out
    /// by [`munsell_held_out`]), cached for the default K.
    pub fn munsell_training(k: usize) -> Basis {
        static B: OnceLock<Basis> = OnceLock::new();
        let learn = || {
            let train: Vec<&Spectrum> = munsell()
                .iter()
                .enumerate()
                .filter(|(i, _)| !munsell_held_out(*i))
                .map(|(_, (_, s))| s)
                .collect();
            Basis::learn(&train, k)
        };
        if k == DEFAULT_K {
            B.get_or_init(learn).clone()
        } else {
            learn()
        }
    }

    fn logits(&self, c: &[f64]) -> Spectrum {
        let mut z = self.mean;
        for (b, &ck) in self.components.iter().zip(c) {
            for i in 0..N {
                z[i] += ck * b[i];
            }
        }
        z
    }

    /// The spectrum for coefficients `c`.
    pub fn spectrum(&self, c: &[f64]) -> Spectrum {
        self.logits(c).map(logistic)
    }

    /// Fit to a target XYZ; returns the spectrum and the residual Delta E*ab.
    pub fn fit(&self, obs: &Observer, xyz: [f64; 3]) -> (Spectrum, f64) {
        let k = self.components.len();
        let target = obs.lab(xyz);
        let de_of = |c: &[f64]| delta_e(obs.lab(obs.spectrum_xyz(&self.spectrum(c))), target);
        let mut c = vec![0.0; k];
        let mut de = de_of(&c);
        for _ in 0..60 {
            let z = self.logits(&c);
            let s = z.map(logistic);
            let cur = obs.spectrum_xyz(&s);
            // J = W diag(sigma') B  (3 x k)
            let mut jac = DMatrix::<f64>::zeros(3, k);
            for row in 0..3 {
                for (col, b) in self.components.iter().enumerate() {
                    jac[(row, col)] = (0..N)
                        .map(|i| obs.xyz_w[row][i] * s[i] * (1.0 - s[i]) * b[i])
                        .sum();
                }
            }
            let lam = DMatrix::from_diagonal(&DVector::from_column_slice(&self.variances));
            let cv = DVector::from_column_slice(&c);
            let r = DVector::from_iterator(3, (0..3).map(|i| xyz[i] - cur[i]));
            let a = &jac * &lam * jac.transpose();
            let Some(y) = a.lu().solve(&(r + &jac * &cv)) else {
                break;
            };
            let cn = &lam * jac.transpose() * y;
            let step: Vec<f64> = (0..k).map(|i| cn[i] - c[i]).collect();
            let mut alpha = 1.0;
            let mut accepted = false;
            for _ in 0..20 {
                let trial: Vec<f64> = (0..k).map(|i| c[i] + alpha * step[i]).collect();
                let dt = de_of(&trial);
                // Once on the constraint surface (dE ~ 0), steps that slide along it toward
                // the minimum-norm point are accepted even if dE does not decrease.
                if dt.is_finite() && (dt < de || dt < 1e-7) {
                    c = trial;
                    de = dt;
                    accepted = true;
                    break;
                }
                alpha *= 0.5;
            }
            let size = step.iter().map(|v| v * v).sum::<f64>().sqrt();
            if !accepted || (size * alpha < 1e-10 && de < 1e-7) {
                break;
            }
        }
        if de > 1e-4 {
            // Out of gamut or stalled: closest colour with a weak pull toward the mean.
            let w = 1e-3;
            let resid = |c: &[f64]| {
                let l = obs.lab(obs.spectrum_xyz(&self.spectrum(c)));
                let mut v = vec![l[0] - target[0], l[1] - target[1], l[2] - target[2]];
                v.extend(
                    c.iter()
                        .zip(&self.variances)
                        .map(|(ci, li)| w * ci / li.sqrt()),
                );
                v
            };
            let f = levenberg_marquardt(&resid, &c, 1e-9, 200);
            let d = de_of(&f.x);
            if d < de {
                c = f.x;
                de = d;
            }
        }
        (self.spectrum(&c), de)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::colour::cie::RgbSpace;

    #[test]
    fn basis_reproduces_colours_exactly() {
        let b = Basis::munsell_training(DEFAULT_K);
        assert_eq!(b.components.len(), DEFAULT_K);
        assert!(b.variances.windows(2).all(|w| w[0] >= w[1]));
        let obs = Observer::new(RgbSpace::Radiance);
        for rgb in [
            [0.5, 0.5, 0.5],
            [0.8, 0.2, 0.1],
            [0.05, 0.3, 0.6],
            [0.9, 0.9, 0.2],
        ] {
            let (s, de) = b.fit(&obs, obs.rgb_to_xyz(rgb));
            assert!(de < 1e-3, "{rgb:?}: dE {de}");
            assert!(s.iter().all(|&v| v > 0.0 && v < 1.0));
        }
    }
}
