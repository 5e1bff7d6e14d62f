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

impl Xf {
    /// The inverse of the transform `args` describe; `loc` and `what` label errors.
    pub fn inverse_of(args: &[String], loc: &Location, what: &str) -> Result<Xf> {
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
        // Inverse of each option, multiplied in reverse order: (M1 M2 ..)^-1 = .. M2^-1 M1^-1.
        let mut ops: Vec<[[f64; 4]; 4]> = Vec::new();
        let mut sca = 1.0;
        let mut k = 0;
        while k < args.len() {
            let mut m = Xf::default().m;
            match args[k].as_str() {
                "-t" => {
                    for (j, v) in m[3].iter_mut().take(3).enumerate() {
                        *v = -num(k + 1 + j)?;
                    }
                    k += 4;
                }
                o @ ("-rx" | "-ry" | "-rz") => {
                    let a = -num(k + 1)?.to_radians();
                    let (s, c) = a.sin_cos();
                    let (i, j) = match o {
                        "-rx" => (1, 2),
                        "-ry" => (2, 0),
                        _ => (0, 1),
                    };
                    m[i][i] = c;
                    m[i][j] = s;
                    m[j][i] = -s;
                    m[j][j] = c;
                    k += 2;
                }
                "-s" => {
                    let f = num(k + 1)?;
                    if f == 0.0 {
                        return Err(bad("transform scale 0".into()));
                    }
                    for (i, row) in m.iter_mut().take(3).enumerate() {
                        row[i] = 1.0 / f;
                    }
                    sca /= f.abs();
                    k += 2;
                }
                o @ ("-mx" | "-my" | "-mz") => {
                    let i = match o {
                        "-mx" => 0,
                        "-my" => 1,
                        _ => 2,
                    };
                    m[i][i] = -1.0;
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
            ops.push(m);
        }
        let m = ops
            .iter()
            .rev()
            .fold(Xf::default().m, |acc, op| mul(&acc, op));
        Ok(Xf { m, sca })
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
