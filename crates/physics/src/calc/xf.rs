//! The transform arguments (`xf`) of function-file patterns, as the pattern sees the ray.
//!
//! Radiance (`src/rt/func.c: getfunc, setfunc, chanvalue`; `src/common/xf.c`): the options
//! `-t x y z`, `-rx a`, `-ry a`, `-rz a` (degrees), `-s f`, `-mx`, `-my`, `-mz` describe how
//! the pattern was moved into the scene (applied in order, points as row vectors,
//! `p' = p M1 M2 ...`). The pattern evaluates in its own coordinates, so rays are taken
//! back with the inverse: `D = d M^-1 / s`, `N` likewise, `P = p M^-1`, `T` times `1/s`,
//! `S = 1/s`, `Tx Ty Tz` the inverse's translation and `I J K` its unit vectors, `s` the
//! product of the scale factors. (`-i` arrays make no sense for a pattern and are refused.)

use crate::error::{Error, Location, Result};

/// An inverse transform: 4x4 matrix for row vectors and its scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Xf {
    pub m: [[f64; 4]; 4],
    pub sca: f64,
}

impl Default for Xf {
    fn default() -> Self {
        let mut m = [[0.0; 4]; 4];
        for (i, row) in m.iter_mut().enumerate() {
            row[i] = 1.0;
        }
        Xf { m, sca: 1.0 }
    }
}

fn mul(a: &[[f64; 4]; 4], b: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..4).map(|k| a[i][k] * b[k][j]).sum()))
}

/// Whether `s` starts a transform (`isxfopt` in Radiance).
pub fn is_xf_option(s: &str) -> bool {
    matches!(
        s,
        "-t" | "-rx" | "-ry" | "-rz" | "-s" | "-mx" | "-my" | "-mz" | "-i"
    )
}

/// One transform option as a forward matrix, its inverse and its scale factor.
struct Op {
    fwd: [[f64; 4]; 4],
    inv: [[f64; 4]; 4],
    sca: f64,
}

/// The options of `args` in order (`xf()` in `src/common/xf.c`); `loc` and `what` label
/// errors.
fn ops(args: &[String], loc: &Location, what: &str) -> Result<Vec<Op>> {
    let bad = |msg: String| Error::parse(loc.clone(), format!("{what}: {msg}"));
    let num = |k: usize| -> Result<f64> {
        let w = args
            .get(k)
            .ok_or_else(|| bad(format!("transform option '{}' needs a number", args[k - 1])))?;
        w.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| bad(format!("expected a number in the transform, found '{w}'")))
    };
    let mut out = Vec::new();
    let mut k = 0;
    while k < args.len() {
        let (mut fwd, mut inv) = (Xf::default().m, Xf::default().m);
        let mut sca = 1.0;
        match args[k].as_str() {
            "-t" => {
                for j in 0..3 {
                    let v = num(k + 1 + j)?;
                    fwd[3][j] = v;
                    inv[3][j] = -v;
                }
                k += 4;
            }
            o @ ("-rx" | "-ry" | "-rz") => {
                let a = num(k + 1)?.to_radians();
                let (i, j) = match o {
                    "-rx" => (1, 2),
                    "-ry" => (2, 0),
                    _ => (0, 1),
                };
                for (m, a) in [(&mut fwd, a), (&mut inv, -a)] {
                    let (s, c) = a.sin_cos();
                    m[i][i] = c;
                    m[i][j] = s;
                    m[j][i] = -s;
                    m[j][j] = c;
                }
                k += 2;
            }
            "-s" => {
                let f = num(k + 1)?;
                if f == 0.0 {
                    return Err(bad("transform scale 0".into()));
                }
                for i in 0..3 {
                    fwd[i][i] = f;
                    inv[i][i] = 1.0 / f;
                }
                sca = f.abs();
                k += 2;
            }
            o @ ("-mx" | "-my" | "-mz") => {
                let i = match o {
                    "-mx" => 0,
                    "-my" => 1,
                    _ => 2,
                };
                fwd[i][i] = -1.0;
                inv[i][i] = -1.0;
                k += 1;
            }
            o => {
                return Err(Error::unsupported(
                    loc.clone(),
                    format!(
                        "transform option '{o}' on {what}; expected -t -rx -ry -rz -s -mx -my -mz"
                    ),
                ));
            }
        }
        out.push(Op { fwd, inv, sca });
    }
    Ok(out)
}

impl Xf {
    /// The inverse of the transform `args` describe; `loc` and `what` label errors.
    pub fn inverse_of(args: &[String], loc: &Location, what: &str) -> Result<Xf> {
        // Inverse of each option, multiplied in reverse order: (M1 M2 ..)^-1 = .. M2^-1 M1^-1.
        let ops = ops(args, loc, what)?;
        let m = ops
            .iter()
            .rev()
            .fold(Xf::default().m, |acc, op| mul(&acc, &op.inv));
        let sca = ops.iter().fold(1.0, |s, op| s / op.sca);
        Ok(Xf { m, sca })
    }

    /// The transform `args` describe itself (points as row vectors: `p' = p M`), as `xform`
    /// and the `mesh`/`instance` primitives apply it; `sca` is the product of the scales.
    pub fn forward_of(args: &[String], loc: &Location, what: &str) -> Result<Xf> {
        let ops = ops(args, loc, what)?;
        let m = ops
            .iter()
            .fold(Xf::default().m, |acc, op| mul(&acc, &op.fwd));
        let sca = ops.iter().fold(1.0, |s, op| s * op.sca);
        Ok(Xf { m, sca })
    }

    /// This transform followed by `outer` (an object placed by `self` inside an octree that
    /// `outer` places in the scene).
    pub fn then(&self, outer: &Xf) -> Xf {
        Xf {
            m: mul(&self.m, &outer.m),
            sca: self.sca * outer.sca,
        }
    }

    /// The inverse of a similarity transform (rotations, mirrors, one uniform scale, a
    /// translation: all that `xf` options make): the 3x3 part transposed over `sca²`, the
    /// translation taken back through it.
    pub fn inverse(&self) -> Xf {
        let s2 = self.sca * self.sca;
        let mut m = Xf::default().m;
        for (i, row) in m.iter_mut().take(3).enumerate() {
            for (j, v) in row.iter_mut().take(3).enumerate() {
                *v = self.m[j][i] / s2;
            }
        }
        let t = [self.m[3][0], self.m[3][1], self.m[3][2]];
        let back: [f64; 3] = std::array::from_fn(|n| -(0..3).map(|i| t[i] * m[i][n]).sum::<f64>());
        m[3][..3].copy_from_slice(&back);
        Xf {
            m,
            sca: 1.0 / self.sca,
        }
    }

    /// A point moved by this matrix (`multp3`).
    pub fn point(&self, p: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|n| (0..3).map(|i| p[i] * self.m[i][n]).sum::<f64>() + self.m[3][n])
    }

    /// A direction moved by this matrix, without translation (`multv3`).
    pub fn vector(&self, v: [f64; 3]) -> [f64; 3] {
        std::array::from_fn(|n| (0..3).map(|i| v[i] * self.m[i][n]).sum::<f64>())
    }

    /// True when the transform mirrors (its 3x3 part has a negative determinant): a mirrored
    /// polygon's vertex order must be reversed to keep its front side (`xform` does so).
    pub fn mirrors(&self) -> bool {
        let m = &self.m;
        let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        det < 0.0
    }

    /// `$1..$27` for a ray seen through this (inverse) transform; `chan` holds the world
    /// values in the layout of [`super::pattern::RayVars::channels`].
    pub fn apply(&self, chan: &mut [f64; 27]) {
        let m = &self.m;
        let vec = |v: [f64; 3], n: usize| (0..3).map(|i| v[i] * m[i][n]).sum::<f64>();
        let d = [chan[0], chan[1], chan[2]];
        let nrm = [chan[3], chan[4], chan[5]];
        let p = [chan[6], chan[7], chan[8]];
        for n in 0..3 {
            chan[n] = vec(d, n) / self.sca;
            chan[3 + n] = vec(nrm, n) / self.sca;
            chan[6 + n] = vec(p, n) + m[3][n];
            chan[12 + n] = m[3][n];
            chan[15 + n] = m[0][n] / self.sca;
            chan[18 + n] = m[1][n] / self.sca;
            chan[21 + n] = m[2][n] / self.sca;
        }
        chan[9] *= self.sca;
        chan[11] = self.sca;
        chan[24] *= self.sca;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn xf(a: &str) -> Xf {
        let args: Vec<String> = a.split_whitespace().map(String::from).collect();
        Xf::inverse_of(&args, &Location::default(), "t").unwrap()
    }

    #[test]
    fn inverse_takes_moved_points_back() {
        // Forward: rotate 90 about z, scale 2, translate (1, 0, 0): (1,0,0) -> (0,1,0) ->
        // (0,2,0) -> (1,2,0). The inverse maps (1,2,0) back to (1,0,0).
        let x = xf("-rz 90 -s 2 -t 1 0 0");
        let mut c = [0.0; 27];
        c[6..9].copy_from_slice(&[1.0, 2.0, 0.0]);
        c[0..3].copy_from_slice(&[0.0, 1.0, 0.0]); // world +y is pattern +x
        x.apply(&mut c);
        for (a, b) in c[6..9].iter().zip([1.0, 0.0, 0.0]) {
            assert!((a - b).abs() < 1e-12, "{:?}", &c[6..9]);
        }
        for (a, b) in c[0..3].iter().zip([1.0, 0.0, 0.0]) {
            assert!((a - b).abs() < 1e-12, "{:?}", &c[0..3]);
        }
        assert!((c[11] - 0.5).abs() < 1e-12);
    }

    #[test]
    fn forward_and_inverse_undo_each_other() {
        let args: Vec<String> = "-rx 30 -my -s 2.5 -rz 90 -t 1 2 3"
            .split_whitespace()
            .map(String::from)
            .collect();
        let f = Xf::forward_of(&args, &Location::default(), "t").unwrap();
        let i = Xf::inverse_of(&args, &Location::default(), "t").unwrap();
        let p = [0.3, -0.7, 1.1];
        let q = i.point(f.point(p));
        for k in 0..3 {
            assert!((p[k] - q[k]).abs() < 1e-12, "{q:?}");
        }
        assert!((f.sca - 2.5).abs() < 1e-15 && (i.sca - 0.4).abs() < 1e-15);
        assert!(f.mirrors());
        let back = f.inverse();
        let q = back.point(f.point(p));
        for k in 0..3 {
            assert!((p[k] - q[k]).abs() < 1e-12, "{q:?}");
        }
        for r in 0..4 {
            for c in 0..4 {
                assert!((back.m[r][c] - i.m[r][c]).abs() < 1e-12);
            }
        }
        // -rz 90 then -t: (1,0,0) -> (0,1,0) -> (1,3,3).
        let g = xf_fwd("-rz 90 -t 1 2 3");
        let r = g.point([1.0, 0.0, 0.0]);
        assert!(
            (r[0] - 1.0).abs() < 1e-12 && (r[1] - 3.0).abs() < 1e-12 && (r[2] - 3.0).abs() < 1e-12,
            "{r:?}"
        );
    }

    fn xf_fwd(a: &str) -> Xf {
        let args: Vec<String> = a.split_whitespace().map(String::from).collect();
        Xf::forward_of(&args, &Location::default(), "t").unwrap()
    }

    #[test]
    fn bad_transforms_are_errors() {
        let args = |a: &str| a.split_whitespace().map(String::from).collect::<Vec<_>>();
        let e = Xf::inverse_of(&args("-rz"), &Location::line("s.rad", 3), "brightfunc 'b'")
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "s.rad:3: brightfunc 'b': transform option '-rz' needs a number"
        );
        let e = Xf::inverse_of(&args("-i 2"), &Location::line("s.rad", 3), "brightfunc 'b'")
            .unwrap_err();
        assert!(
            e.to_string().contains("unsupported transform option '-i'"),
            "{e}"
        );
    }
}
