//! Matrix operations of `rmtxop`/`dctimestep`: shape checks, per-channel multiplication,
//! channel transforms (`-c`) and scaling (`-s`).
//!
//! Multiplication (`rmatrix.c: rmx_multiply`; `dctimestep` likewise) is per channel: for
//! NCOMP = 3 the red result is the product of the red matrices, and so on:
//! `C[i][j][k] = sum_h A[i][h][k] * B[h][j][k]`, which needs `ncols(A) == nrows(B)` and equal
//! NCOMP. Radiance stores float and sums in double; we store and sum in f64, so results agree
//! to float precision (relative 1e-7).
//!
//! Channel transform (`rmatrix.c: rmx_transform`, man `rmtxop.1`): `-c w...` with
//! `n_out * NCOMP` coefficients maps each element `out[o] = sum_i w[o*NCOMP + i] * in[i]`.
//! Symbolic `-c Y` on RGB is photopic luminance/illuminance `179 * (0.265106, 0.670106,
//! 0.064788)` (row Y of the standard primaries' RGB-to-XYZ matrix times `WHTEFFICACY`, as
//! rmtxop computes it); lower case `y` omits 179.
//! Note: real rmtxop 6.0a uses its float-computed `rgb2xyzmat` row, 47.45394 119.94894
//! 11.59712 (notes §2.4), which differs from these by up to 1.2e-4 relative.

use super::Matrix;
use crate::error::{Error, Result};
use crate::radiometry::{STD_PRIMARIES, WHITE_EFFICACY, rgb_to_xyz};
use std::fmt;

/// Matrix dimensions; `nrows` is unknown for streams without `NROWS=`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shape {
    pub nrows: Option<usize>,
    pub ncols: usize,
    pub ncomp: usize,
}

impl fmt::Display for Shape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.nrows {
            Some(n) => write!(f, "{n}x{}x{}", self.ncols, self.ncomp),
            None => write!(f, "?x{}x{}", self.ncols, self.ncomp),
        }
    }
}

/// Check that `left · right` is defined; the error is one line naming both files and shapes:
/// `dc.mtx (165x146x3) cannot multiply sky.mtx (145x8760x3): 146 columns vs 145 rows`.
pub fn check_multiply(left_name: &str, left: Shape, right_name: &str, right: Shape) -> Result<()> {
    let head = format!("{left_name} ({left}) cannot multiply {right_name} ({right})");
    if left.ncomp != right.ncomp {
        return Err(Error::Mismatch(format!(
            "{head}: {} components vs {}",
            left.ncomp, right.ncomp
        )));
    }
    match right.nrows {
        Some(r) if r == left.ncols => Ok(()),
        Some(r) => Err(Error::Mismatch(format!(
            "{head}: {} columns vs {r} rows",
            left.ncols
        ))),
        None => Err(Error::Mismatch(format!(
            "{head}: the right matrix has no NROWS"
        ))),
    }
}

/// Check that row blocks can be stacked (`rmtx --cat`): same NCOLS and NCOMP.
pub fn check_stack(first_name: &str, first: Shape, name: &str, shape: Shape) -> Result<()> {
    if first.ncols != shape.ncols || first.ncomp != shape.ncomp {
        return Err(Error::Mismatch(format!(
            "{name} ({shape}) cannot be stacked under {first_name} ({first}): \
             NCOLS and NCOMP must agree"
        )));
    }
    Ok(())
}

/// `out = a · b` for one row `a` (`b.nrows * ncomp` numbers), per channel.
pub fn multiply_row(a: &[f64], b: &Matrix, out: &mut [f64]) {
    let nc = b.channels.ncomp;
    out.iter_mut().for_each(|v| *v = 0.0);
    for (h, ah) in a.chunks_exact(nc).enumerate().take(b.nrows) {
        // Zero coefficients (e.g. ground or unseen patches) are common: skip their rows.
        if ah.iter().all(|&v| v == 0.0) {
            continue;
        }
        let brow = b.row(h);
        for (o, bv) in out.chunks_exact_mut(nc).zip(brow.chunks_exact(nc)) {
            for k in 0..nc {
                o[k] += ah[k] * bv[k];
            }
        }
    }
}

/// A component transform `out[o] = sum_i coefs[o * nin + i] * in[i]`.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelTransform {
    pub nin: usize,
    pub nout: usize,
    pub coefs: Vec<f64>,
}

impl ChannelTransform {
    /// From rmtxop's `-c` arguments: numbers (a multiple of `nin` of them), or one symbolic
    /// word of letters `R G B Y A` (`y`: without 179). `what` names the input in errors.
    pub fn parse(args: &[String], nin: usize, what: &str) -> Result<Self> {
        if args.is_empty() {
            return Err(Error::Usage("-c: missing coefficients".into()));
        }
        let nums: Option<Vec<f64>> = args.iter().map(|a| a.parse::<f64>().ok()).collect();
        match nums {
            Some(coefs) => Self::new(coefs, nin, what),
            None if args.len() == 1 => Self::symbolic(&args[0], nin, what),
            None => Err(Error::Usage(format!(
                "-c {}: expected numbers or one symbolic word (R G B Y y A)",
                args.join(" ")
            ))),
        }
    }

    pub fn new(coefs: Vec<f64>, nin: usize, what: &str) -> Result<Self> {
        if nin == 0 || coefs.is_empty() || coefs.len() % nin != 0 {
            return Err(Error::Usage(format!(
                "{what}: -c must have N x {nin} coefficients, got {}",
                coefs.len()
            )));
        }
        Ok(ChannelTransform {
            nin,
            nout: coefs.len() / nin,
            coefs,
        })
    }

    /// Symbolic transforms (subset of `rmtxop.c: checksymbolic`).
    pub fn symbolic(sym: &str, nin: usize, what: &str) -> Result<Self> {
        let mut coefs = Vec::new();
        for c in sym.chars() {
            let mut row = vec![0.0; nin];
            match c {
                'R' | 'r' | 'G' | 'g' | 'B' | 'b' if nin == 3 => {
                    row["RGB".find(c.to_ascii_uppercase()).unwrap_or(0)] = 1.0;
                }
                'Y' | 'y' if nin == 3 => {
                    // rmtxop's `-c Y` is row Y of rgb2xyzmat for the standard primaries
                    // (x 179 for upper case).
                    let cf = if c == 'Y' { WHITE_EFFICACY } else { 1.0 };
                    for (r, w) in row.iter_mut().zip(rgb_to_xyz(&STD_PRIMARIES)[1]) {
                        *r = cf * w;
                    }
                }
                'A' | 'a' => row.iter_mut().for_each(|r| *r = 1.0 / nin as f64),
                _ => {
                    return Err(Error::Usage(format!(
                        "{what}: -c '{c}' unsupported for NCOMP={nin} (R G B Y y on RGB, \
                         A on any)"
                    )));
                }
            }
            coefs.extend(row);
        }
        Self::new(coefs, nin, what)
    }

    /// Apply to a row of elements with `nin` components, writing `nout` per element.
    pub fn apply_row(&self, row: &[f64], out: &mut [f64]) {
        for (src, dst) in row
            .chunks_exact(self.nin)
            .zip(out.chunks_exact_mut(self.nout))
        {
            for (o, d) in dst.iter_mut().enumerate() {
                let w = &self.coefs[o * self.nin..(o + 1) * self.nin];
                *d = w.iter().zip(src).map(|(a, b)| a * b).sum();
            }
        }
    }
}

/// Per-component factors for `-s`: one factor for all, or one per component (rmtxop).
pub fn scale_factors(sf: &[f64], ncomp: usize) -> Result<Vec<f64>> {
    match sf.len() {
        1 => Ok(vec![sf[0]; ncomp]),
        n if n == ncomp => Ok(sf.to_vec()),
        n => Err(Error::Usage(format!(
            "-s must have one or {ncomp} factors, got {n}"
        ))),
    }
}

/// Multiply each element's components by `factors` (length NCOMP).
pub fn scale_row(row: &mut [f64], factors: &[f64]) {
    for elem in row.chunks_exact_mut(factors.len()) {
        for (v, f) in elem.iter_mut().zip(factors) {
            *v *= f;
        }
    }
}

/// What happens to each row of a streamed left operand: multiplication by the in-memory
/// right operands in turn (left to right), then the channel transform, then the scale.
/// Memory: the right operands plus two row buffers.
#[derive(Debug, Clone)]
pub struct RowOps {
    chain: Vec<Matrix>,
    transform: Option<ChannelTransform>,
    scale: Option<Vec<f64>>,
    ncomp_in: usize,
    bufs: [Vec<f64>; 2],
}

impl RowOps {
    /// `ncomp` of the streamed rows; `chain` must already be shape-checked (see
    /// [`check_multiply`]); `transform.nin` must equal `ncomp`; `scale` has one factor per
    /// output component.
    pub fn new(
        ncomp: usize,
        chain: Vec<Matrix>,
        transform: Option<ChannelTransform>,
        scale: Option<Vec<f64>>,
    ) -> Self {
        RowOps {
            chain,
            transform,
            scale,
            ncomp_in: ncomp,
            bufs: [Vec::new(), Vec::new()],
        }
    }

    /// Columns of the result.
    pub fn out_ncols(&self, in_ncols: usize) -> usize {
        self.chain.last().map_or(in_ncols, |m| m.ncols)
    }

    /// Components of the result.
    pub fn out_ncomp(&self) -> usize {
        self.transform.as_ref().map_or(self.ncomp_in, |t| t.nout)
    }

    /// Apply everything to one row; the result lives until the next call.
    pub fn apply(&mut self, row: &[f64]) -> &[f64] {
        let [a, b] = &mut self.bufs;
        a.clear();
        a.extend_from_slice(row);
        for m in &self.chain {
            b.clear();
            b.resize(m.row_len(), 0.0);
            multiply_row(a, m, b);
            std::mem::swap(a, b);
        }
        if let Some(t) = &self.transform {
            let nelem = a.len() / t.nin;
            b.clear();
            b.resize(nelem * t.nout, 0.0);
            t.apply_row(a, b);
            std::mem::swap(a, b);
        }
        if let Some(f) = &self.scale {
            scale_row(a, f);
        }
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::radiometry::Channels;

    #[test]
    fn shape_message() {
        let a = Shape {
            nrows: Some(165),
            ncols: 146,
            ncomp: 3,
        };
        let b = Shape {
            nrows: Some(145),
            ncols: 8760,
            ncomp: 3,
        };
        let e = check_multiply("dc.mtx", a, "sky.mtx", b).unwrap_err();
        assert_eq!(
            e.to_string(),
            "dc.mtx (165x146x3) cannot multiply sky.mtx (145x8760x3): 146 columns vs 145 rows"
        );
        let c = Shape { ncomp: 1, ..b };
        let e = check_multiply("dc.mtx", a, "sky.mtx", c).unwrap_err();
        assert!(e.to_string().ends_with(": 3 components vs 1"), "{e}");
    }

    #[test]
    fn multiply_matches_brute_force() {
        // 2x3x2 times 3x2x2, against a direct triple loop.
        let a: Vec<f64> = (0..12).map(|i| i as f64 * 0.5 - 1.0).collect();
        let b = Matrix {
            nrows: 3,
            ncols: 2,
            channels: Channels {
                ncomp: 2,
                ..Channels::rgb()
            },
            data: (0..12).map(|i| (i * i) as f64 * 0.25).collect(),
        };
        for i in 0..2 {
            let mut out = vec![0.0; 4];
            multiply_row(&a[i * 6..(i + 1) * 6], &b, &mut out);
            for j in 0..2 {
                for k in 0..2 {
                    let want: f64 = (0..3).map(|h| a[i * 6 + h * 2 + k] * b.get(h, j)[k]).sum();
                    assert_eq!(out[j * 2 + k], want);
                }
            }
        }
    }

    #[test]
    fn symbolic_y_is_179_times_photopic() {
        let t = ChannelTransform::symbolic("Y", 3, "m").unwrap();
        let mut out = [0.0];
        t.apply_row(&[1.0, 1.0, 1.0], &mut out);
        assert!((out[0] - 179.0).abs() < 1e-6, "{out:?}");
        assert!(ChannelTransform::symbolic("Y", 20, "m").is_err());
        let e = ChannelTransform::new(vec![1.0, 2.0], 3, "m").unwrap_err();
        assert_eq!(e.to_string(), "m: -c must have N x 3 coefficients, got 2");
    }
}
