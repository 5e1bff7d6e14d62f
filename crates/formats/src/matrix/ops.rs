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
//! On spectral input (NCOMP > 3) the symbolic words weight the bands by Radiance's own
//! cumulative observer tables, laid out by the matrix header's `WAVELENGTH_SPLITS`
//! ([`ChannelTransform::symbolic_for`]); they agree with rmtxop 6.0a to float precision.

use super::Operand;
use crate::error::{Error, Result};
use crate::radiometry::{Channels, STD_PRIMARIES, WHITE_EFFICACY, rgb_to_xyz};
use std::fmt;

/// The letters `-c` accepts (rmtxop's `checksymbolic`).
pub const SYMBOLS: &str = "R G B X Y Z S M A (lower case: without the 179/412 factor)";

/// Scotopic efficacy of equal-energy white over 380-780 nm, Radiance `WHTSCOTOPIC` (lm/W,
/// `src/common/color.h`).
pub const WHITE_SCOTOPIC: f64 = 412.0;

/// Radiance's melanopic factor for equal-energy white, `WHTMELANOPIC` (`color.h`): 179, so
/// that `M` equals `Y` for equal-energy light.
pub const WHITE_MELANOPIC: f64 = 179.0;

/// RGB for 3 components, otherwise spectral bands with Radiance's default splits.
fn layout(nin: usize) -> Channels {
    Channels {
        ncomp: nin,
        ..Channels::rgb()
    }
}

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

/// A component transform `out[o] = sum_i coefs[o * nin + i] * in[i]`.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelTransform {
    pub nin: usize,
    pub nout: usize,
    pub coefs: Vec<f64>,
}

impl ChannelTransform {
    /// From rmtxop's `-c` arguments: numbers (a multiple of `nin` of them), or one symbolic
    /// word (see [`ChannelTransform::symbolic_for`]); RGB or default spectral splits.
    /// `what` names the input in errors.
    pub fn parse(args: &[String], nin: usize, what: &str) -> Result<Self> {
        Self::parse_for(args, &layout(nin), what)
    }

    /// As [`ChannelTransform::parse`] for values laid out as `ch` (NCOMP and
    /// WAVELENGTH_SPLITS of the matrix header), which symbolic words need.
    pub fn parse_for(args: &[String], ch: &Channels, what: &str) -> Result<Self> {
        if args.is_empty() {
            return Err(Error::Usage("-c: missing coefficients".into()));
        }
        let nums: Option<Vec<f64>> = args.iter().map(|a| a.parse::<f64>().ok()).collect();
        match nums {
            Some(coefs) => Self::new(coefs, ch.ncomp, what),
            None if args.len() == 1 => Self::symbolic_for(&args[0], ch, what),
            None => Err(Error::Usage(format!(
                "-c {}: expected numbers or one symbolic word of {SYMBOLS}",
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

    /// Symbolic transforms for `nin` components (RGB, or spectral with default splits).
    pub fn symbolic(sym: &str, nin: usize, what: &str) -> Result<Self> {
        Self::symbolic_for(sym, &layout(nin), what)
    }

    /// Symbolic transforms of `rmtxop.c: checksymbolic`, one output component per letter:
    ///
    /// | letter | RGB input (NCOMP=3) | spectral input (NCOMP>3) |
    /// |---|---|---|
    /// | `R G B` (`r g b`) | that channel | band-wise `spec_rgb`: CIE XYZ of the band to standard RGB |
    /// | `X Y Z` (`x y z`) | row of `rgb2xyzmat` | `Y`: `spec_dot` with ȳ; `X`, `Z`: `spec_cie` of the band |
    /// | `S` (`s`) | `spec_dot` with V'(λ) on the 3 split bands | `spec_dot` with V'(λ) |
    /// | `M` (`m`) | `spec_dot` with s_mel on the 3 split bands | `spec_dot` with s_mel |
    /// | `A` (`a`) | mean | mean |
    ///
    /// Upper case multiplies X, Y, Z by 179 lm/W (`WHTEFFICACY`), S by 412
    /// (`WHTSCOTOPIC`) and M by 179 (`WHTMELANOPIC`); upper-case R G B are *not* scaled
    /// (rmtxop's 1/179 for them only applies to XYZE input). The curves are Radiance's own
    /// cumulative tables ([`crate::colour::bands::Curve`]), so an equal-energy white
    /// of 1 in every band gives exactly 179 for `Y` and `M` and 412 for `S`.
    ///
    /// `M` is therefore Radiance's equal-energy-normalised melanopic quantity, not CIE S 026
    /// m-EDI: m-EDI = `M` x `rdaylight_metrics::melanopic::radiance_m_to_medi` (about
    /// 0.9233; `rmetrics` reports both).
    ///
    /// Differences from rmtxop: R G B X Z use whole-nm band edges computed as rmtxop's
    /// `rgbrow`/`xyzrow` write them, but the 6.0a binaries land one nm low on some edges
    /// that are whole numbers (for 6, 7, 9, 12, 14, 15, 18 and 24 bands over 380-780 nm,
    /// e.g. 379 for the last of 18 bands; measured, cause not found in the source), which
    /// moves up to 1.2e-4 of a row's weight (the last band's); Y S M match exactly. Each
    /// letter takes its own scale (rmtxop carries the last
    /// upper-case factor over to following lower-case letters, e.g. `Ry` gives y/179), and
    /// `A` is also accepted for NCOMP < 3, where rmtxop refuses every symbol.
    pub fn symbolic_for(sym: &str, ch: &Channels, what: &str) -> Result<Self> {
        use crate::colour::bands::{Curve, band_edges_nm, spec_cie, spec_dot, xyz_to_std_rgb};
        let nin = ch.ncomp;
        let mut coefs = Vec::new();
        let one_hot = |i: usize| {
            let mut v = vec![0.0; nin];
            v[i] = 1.0;
            v
        };
        // `spec_dot` of each unit band: rmtxop's `sensrow`.
        let sens = |curve: Curve| -> Vec<f64> {
            (0..nin).map(|i| spec_dot(&one_hot(i), ch, curve)).collect()
        };
        for c in sym.chars() {
            let upper = c.is_ascii_uppercase();
            let row: Vec<f64> = match c.to_ascii_uppercase() {
                'A' => vec![1.0 / nin as f64; nin],
                _ if nin < 3 => {
                    return Err(Error::Usage(format!(
                        "{what}: -c '{sym}' requires at least 3 components (NCOMP={nin}); \
                         only A works on fewer"
                    )));
                }
                l @ ('R' | 'G' | 'B') => {
                    let comp = "RGB".find(l).unwrap_or(0);
                    if nin == 3 {
                        one_hot(comp)
                    } else {
                        let m = xyz_to_std_rgb();
                        (0..nin)
                            .map(|i| {
                                let (s, e) = band_edges_nm(ch, i);
                                let xyz = spec_cie(s, e);
                                (0..3).map(|k| m[comp][k] * xyz[k]).sum()
                            })
                            .collect()
                    }
                }
                l @ ('X' | 'Y' | 'Z') => {
                    let comp = "XYZ".find(l).unwrap_or(0);
                    let cf = if upper { WHITE_EFFICACY } else { 1.0 };
                    let row: Vec<f64> = if nin == 3 {
                        rgb_to_xyz(&STD_PRIMARIES)[comp].to_vec()
                    } else if comp == 1 {
                        sens(Curve::Y)
                    } else {
                        (0..nin)
                            .map(|i| {
                                let (s, e) = band_edges_nm(ch, i);
                                spec_cie(s, e)[comp]
                            })
                            .collect()
                    };
                    row.into_iter().map(|w| cf * w).collect()
                }
                'S' => {
                    let cf = if upper { WHITE_SCOTOPIC } else { 1.0 };
                    sens(Curve::Scotopic).into_iter().map(|w| cf * w).collect()
                }
                'M' => {
                    let cf = if upper { WHITE_MELANOPIC } else { 1.0 };
                    sens(Curve::Melanopic).into_iter().map(|w| cf * w).collect()
                }
                _ => {
                    return Err(Error::Usage(format!(
                        "{what}: -c '{c}' unsupported; expected a word of {SYMBOLS}"
                    )));
                }
            };
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
/// Memory: the right operands ([`Operand`]: rows dense or sparse) plus two row buffers.
#[derive(Debug, Clone)]
pub struct RowOps {
    chain: Vec<Operand>,
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
        chain: Vec<Operand>,
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
            m.multiply_row(a, b);
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
        let b = super::super::Matrix {
            nrows: 3,
            ncols: 2,
            channels: Channels {
                ncomp: 2,
                ..Channels::rgb()
            },
            data: (0..12).map(|i| (i * i) as f64 * 0.25).collect(),
        };
        let op = Operand::from_matrix(&b);
        for i in 0..2 {
            let mut out = vec![0.0; 4];
            op.multiply_row(&a[i * 6..(i + 1) * 6], &mut out);
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
        assert!(ChannelTransform::symbolic("Y", 2, "m").is_err());
        assert!(ChannelTransform::symbolic("Q", 20, "m").is_err());
        let e = ChannelTransform::new(vec![1.0, 2.0], 3, "m").unwrap_err();
        assert_eq!(e.to_string(), "m: -c must have N x 3 coefficients, got 2");
    }

    /// `rmtxop -fa -c W` on the 18 unit spectra (an 18x1x18 identity, default splits), real
    /// Radiance 6.0a: the weight of each band, longest wavelength first.
    const RMTXOP_18: [(&str, [f64; 18]); 4] = [
        (
            "Y",
            [
                2.7313649e-03,
                5.4627298e-03,
                2.7313650e-02,
                1.3110551e-01,
                6.5825897e-01,
                2.5893340e+00,
                7.6860609e+00,
                1.6527489e+01,
                2.6696362e+01,
                3.6343540e+01,
                3.6130497e+01,
                2.9050797e+01,
                1.4446189e+01,
                5.7549858e+00,
                2.1304646e+00,
                7.1015489e-01,
                1.0106050e-01,
                8.1940945e-03,
            ],
        ),
        (
            "M",
            [
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                5.4627298e-03,
                1.3656825e-02,
                8.1940949e-02,
                5.3534752e-01,
                3.2694438e+00,
                1.1977036e+01,
                2.7758862e+01,
                4.1890945e+01,
                4.4554024e+01,
                3.0053207e+01,
                1.4995193e+01,
                3.6299839e+00,
                2.3489739e-01,
            ],
        ),
        (
            "R",
            [
                6.0483348e-05,
                1.9925502e-04,
                9.5713098e-04,
                4.3123905e-03,
                2.1622436e-02,
                8.2586199e-02,
                2.2374937e-01,
                3.8318384e-01,
                3.6842105e-01,
                1.8203588e-01,
                -2.5435217e-02,
                -1.2997614e-01,
                -1.0873479e-01,
                -5.3418078e-02,
                4.6396703e-03,
                3.3273458e-02,
                1.1462037e-02,
                9.8166964e-04,
            ],
        ),
        (
            "Z",
            [
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                1.0925460e-02,
                4.0970474e-02,
                9.2866406e-02,
                4.5613796e-01,
                2.2260625e+00,
                8.7758760e+00,
                3.0848034e+01,
                6.0696392e+01,
                5.8481255e+01,
                1.5973022e+01,
                1.3110552e+00,
            ],
        ),
    ];

    #[test]
    fn spectral_symbolic_weights_match_rmtxop() {
        let ch = Channels::spectral(18, 380.0, 780.0).unwrap();
        for (sym, want) in RMTXOP_18 {
            let t = ChannelTransform::symbolic_for(sym, &ch, "m").unwrap();
            assert_eq!((t.nin, t.nout), (18, 1));
            let scale: f64 = want.iter().map(|w| w.abs()).sum();
            // rmtxop prints 8 digits of float results. For R G B X Z it truncates band
            // edges to whole nm from float arithmetic and, for some band counts (6, 7, 9,
            // 12, 14, 15, 18, 24 over 380-780 nm), lands one nm low on an edge that is a
            // whole number (18 bands: 379 instead of 380): a few units of 65535 on that
            // band, which we do not reproduce (ChannelTransform::symbolic_for).
            let tol = if "RGBXZ".contains(sym) { 1e-4 } else { 1e-7 };
            for (i, (got, w)) in t.coefs.iter().zip(want).enumerate() {
                assert!(
                    (got - w).abs() <= 1e-7 * w.abs() + tol * scale,
                    "-c {sym} band {i}: {got} vs rmtxop {w}"
                );
            }
        }
    }

    #[test]
    fn equal_energy_white_is_179_412_179() {
        let ch = Channels::spectral(9, 380.0, 780.0).unwrap();
        let t = ChannelTransform::symbolic_for("YSMA", &ch, "m").unwrap();
        let mut out = [0.0; 4];
        t.apply_row(&[1.0; 9], &mut out);
        for (o, w) in out.iter().zip([179.0, 412.0, 179.0, 1.0]) {
            assert!((o - w).abs() < 1e-9 * w, "{out:?}");
        }
        // RGB of equal-energy white is (1, 1, 1): each of XYZ integrates to 1.
        let t = ChannelTransform::symbolic_for("RGB", &ch, "m").unwrap();
        let mut out = [0.0; 3];
        t.apply_row(&[1.0; 9], &mut out);
        for o in out {
            // Not exactly 1: the bands start at 380 nm, x̄ and z̄ tables at 362 and 359.
            assert!((o - 1.0).abs() < 1e-3, "{out:?}");
        }
    }

    #[test]
    fn melanopic_of_rgb_uses_the_split_bands() {
        // radiance-notes.md 10.3: rmtxop -c M on RGB is 0.3278 R + 107.45 G + 71.22 B.
        let t = ChannelTransform::symbolic("M", 3, "m").unwrap();
        for (got, want) in t.coefs.iter().zip([0.3278, 107.45, 71.22]) {
            assert!((got - want).abs() < 1e-2, "{:?}", t.coefs);
        }
    }
}
