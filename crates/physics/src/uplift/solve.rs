//! Damped Gauss-Newton (Levenberg-Marquardt) for the small fits of uplifting.
//!
//! Minimises `|r(x)|^2` for a few unknowns (3 for Jakob & Hanika, up to ~10 for the basis):
//! step `(J^T J + mu diag(J^T J)) dx = -J^T r` with a forward-difference Jacobian, `mu`
//! shrunk after a successful step and grown after a failed one (Marquardt 1963; Nocedal &
//! Wright, *Numerical Optimization*, 2nd ed., sec. 10.3).

use nalgebra::{DMatrix, DVector};

/// Result of a fit: parameters and final residual norm.
pub struct Fit {
    pub x: Vec<f64>,
    pub cost: f64,
}

/// Levenberg-Marquardt from `x0`; stops when the residual norm is below `tol` or after
/// `iters` iterations.
pub fn levenberg_marquardt(
    r: &dyn Fn(&[f64]) -> Vec<f64>,
    x0: &[f64],
    tol: f64,
    iters: usize,
) -> Fit {
    let mut x = x0.to_vec();
    let mut res = r(&x);
    let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
    let mut cost = norm(&res);
    let mut mu = 1e-3;
    let n = x.len();
    for _ in 0..iters {
        if cost < tol || !cost.is_finite() {
            break;
        }
        let m = res.len();
        let mut jac = DMatrix::<f64>::zeros(m, n);
        for k in 0..n {
            let h = 1e-7 * x[k].abs().max(1.0);
            let mut xp = x.clone();
            xp[k] += h;
            let rp = r(&xp);
            for i in 0..m {
                jac[(i, k)] = (rp[i] - res[i]) / h;
            }
        }
        let jt = jac.transpose();
        let jtj = &jt * &jac;
        let g = &jt * DVector::from_column_slice(&res);
        let mut improved = false;
        for _ in 0..12 {
            let mut a = jtj.clone();
            for k in 0..n {
                a[(k, k)] += mu * jtj[(k, k)].max(1e-12);
            }
            let Some(dx) = a.lu().solve(&(-&g)) else {
                mu *= 10.0;
                continue;
            };
            let xn: Vec<f64> = x.iter().zip(dx.iter()).map(|(a, b)| a + b).collect();
            let rn = r(&xn);
            let cn = norm(&rn);
            if cn.is_finite() && cn < cost {
                x = xn;
                res = rn;
                cost = cn;
                mu = (mu * 0.3).max(1e-12);
                improved = true;
                break;
            }
            mu *= 10.0;
        }
        if !improved {
            break;
        }
    }
    Fit { x, cost }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rosenbrock_residuals() {
        let r = |x: &[f64]| vec![10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]];
        let f = levenberg_marquardt(&r, &[-1.2, 1.0], 1e-12, 200);
        assert!(
            (f.x[0] - 1.0).abs() < 1e-6 && (f.x[1] - 1.0).abs() < 1e-6,
            "{:?}",
            f.x
        );
    }
}
