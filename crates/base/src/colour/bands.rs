//! Colour science over bands: spectra rebinned to a run's channels, band integrals of the
//! CIE tables, and Radiance 6's cumulative observer tables.
//!
//! How band values become scalar quantities (`src/common/spec_rgb.c`, `src/common/color.c`):
//! - [`rebin`] is Radiance's `convertscolor`: the source intervals' overlap-weighted mean
//!   per band, zero where the source does not reach (no extrapolation, no normalisation);
//! - [`band_integrals`] integrate the piecewise-linear interpolant of a 5 nm CIE table
//!   ([`super::cie::tables`]) exactly over each band; they turn band values into photopic,
//!   melanopic or CIE XYZ quantities ([`band_xyz`]);
//! - Radiance's own way, integer cumulative tables over whole-nm band edges (`spec_dot`,
//!   `spec_cie`), is [`spec_dot`] / [`spec_cie`] with the tables of [`Curve`] rebuilt from
//!   the CIE data: what `rmtxop -c` and `rmtx -c` use on spectral matrices. The two differ
//!   by up to a few 1e-3 of a band's weight.
//! - [`xyz_to_rgb_clipped`] is `cie_rgb` followed by `clipgamut` with the lower bound only.

use super::cie::{WL_MIN, WL_STEP, inv3, tables};
use crate::radiometry::{Channels, STD_PRIMARIES, rgb_to_xyz};

/// Radiance's `convertscolor`: `src` (intervals evenly covering `a`..`b` nm, either order)
/// to the bands of `ch`, each the overlap-weighted mean, zero where `src` does not reach.
pub fn rebin(src: &[f64], a: f64, b: f64, ch: &Channels) -> Vec<f64> {
    let n = src.len();
    let (lo, hi, rev) = if a <= b { (a, b, false) } else { (b, a, true) };
    let w = (hi - lo) / n.max(1) as f64;
    (0..ch.ncomp)
        .map(|i| {
            let (bhi, blo) = ch.band(i);
            let width = bhi - blo;
            if width <= 0.0 || w <= 0.0 {
                return 0.0;
            }
            let mut acc = 0.0;
            // Only the source intervals overlapping this band.
            let k0 = (((blo - lo) / w).floor().max(0.0)) as usize;
            let k1 = ((((bhi - lo) / w).ceil()).max(0.0) as usize).min(n);
            for k in k0..k1 {
                let s_lo = lo + k as f64 * w;
                let overlap = (s_lo + w).min(bhi) - s_lo.max(blo);
                if overlap > 0.0 {
                    let v = if rev { src[n - 1 - k] } else { src[k] };
                    acc += v * overlap;
                }
            }
            acc / width
        })
        .collect()
}

/// Integral (nm units) of the piecewise-linear curve `table` (5 nm grid from 380 nm, zero
/// outside) over `[lo, hi]`.
fn integral(table: &[f64], lo: f64, hi: f64) -> f64 {
    if hi <= lo {
        return 0.0;
    }
    let f = |x: f64| -> f64 {
        let t = (x - WL_MIN) / WL_STEP;
        if t < 0.0 || t > (table.len() - 1) as f64 {
            return 0.0;
        }
        let i = (t.floor() as usize).min(table.len() - 2);
        let u = t - i as f64;
        table[i] * (1.0 - u) + table[i + 1] * u
    };
    // Exact for a piecewise-linear curve: trapezoids between the knots inside [lo, hi].
    let mut xs = vec![lo];
    let mut k = ((lo - WL_MIN) / WL_STEP).floor() + 1.0;
    loop {
        let x = WL_MIN + k * WL_STEP;
        if x >= hi {
            break;
        }
        xs.push(x);
        k += 1.0;
    }
    xs.push(hi);
    xs.windows(2)
        .map(|p| 0.5 * (f(p[0]) + f(p[1])) * (p[1] - p[0]))
        .sum()
}

/// Integral of `table` (5 nm grid from 380 nm, e.g. a column of
/// [`crate::colour::cie::tables`]) over each band of `ch`, in nm.
pub fn band_integrals(table: &[f64], ch: &Channels) -> Vec<f64> {
    (0..ch.ncomp)
        .map(|i| {
            let (hi, lo) = ch.band(i);
            integral(table, lo, hi)
        })
        .collect()
}

/// CIE XYZ of band values with unit-area colour-matching functions (Radiance's
/// `scolor2cie`: equal-energy white, all bands 1, gives X = Y = Z = 1 over 380-780 nm).
pub fn band_xyz(v: &[f64], ch: &Channels) -> [f64; 3] {
    let t = tables();
    std::array::from_fn(|c| {
        let w = band_integrals(&t.cmf[c], ch);
        let total = integral(&t.cmf[c], WL_MIN, 780.0);
        v.iter().zip(&w).map(|(a, b)| a * b).sum::<f64>() / total
    })
}

/// CIE XYZ to Radiance RGB (standard primaries), negative channels clipped towards the grey
/// of equal luminance as `clipgamut(.., CGAMUT_LOWER, black, white)` does.
pub fn xyz_to_rgb_clipped(xyz: [f64; 3]) -> [f64; 3] {
    let inv = xyz_to_std_rgb();
    let mut rgb: [f64; 3] =
        std::array::from_fn(|r| (0..3).map(|c| inv[r][c] * xyz[c]).sum::<f64>());
    let y = xyz[1];
    if y <= 0.0 {
        return [0.0; 3];
    }
    // Mix toward grey (y, y, y) just enough that no channel is negative.
    let mut keep: f64 = 1.0;
    for v in rgb {
        if v < 0.0 {
            keep = keep.min(y / (y - v));
        }
    }
    for v in &mut rgb {
        *v = y + keep * (*v - y);
    }
    rgb
}

/// Radiance 6's observer curves as the integer cumulative tables of `src/common/spec_rgb.c`
/// (`cie_x_cumul` ... `melanopic_cumul`), which `spec_dot`/`spec_cie` and therefore
/// `rmtxop -c`, `rcomb -c` and the renderers' `-pY`/`-pS`/`-pM` integrate band values with.
///
/// We do not copy those tables: they are rebuilt from the 1 nm CIE data in `data/spectra/`
/// by the rule they follow (found by comparing with Radiance's tables; cumulative sums
/// normalised to 65535 over the whole 360-830 nm table):
/// - CIE 1931 x̄, ȳ, z̄: `C(w) = round(65535 S(w + 2) / S_total)`, `S(u)` the sum of the
///   1 nm samples below `u` nm: every entry of the three Radiance tables is reproduced;
/// - melanopic (CIE S 026 s_mel): `floor(65535 S(w + 1) / S_total)`: every entry but the
///   last, which Radiance pins at 65535 (so do we);
/// - scotopic (CIE 1951 V'(λ), S 026's rhodopic column): `floor(65535 S(w) / S_total)`:
///   within one unit (1.5e-5 of the curve's area) of Radiance's table, which was built from
///   slightly different V'(λ) values (47 of 303 entries differ by one).
///
/// The ranges (first and last tabulated nm) are Radiance's `CIE_X_WLMIN` ... constants.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Curve {
    X,
    Y,
    Z,
    Scotopic,
    Melanopic,
}

/// One cumulative table: `values[w - wlmin]` for `wlmin <= w <= wlmax`, 0 below, 65535 above.
#[derive(Debug, Clone)]
pub struct Cumulative {
    pub wlmin: i32,
    pub wlmax: i32,
    pub values: Vec<f64>,
}

impl Cumulative {
    /// The table value at integer wavelength `w` (nm), clamped to the table's ends.
    pub fn at(&self, w: i32) -> f64 {
        if w <= self.wlmin {
            self.values.first().copied().unwrap_or(0.0)
        } else if w >= self.wlmax {
            CUMUL_FULL
        } else {
            self.values[(w - self.wlmin) as usize]
        }
    }
}

/// Radiance's full scale of a cumulative table.
pub const CUMUL_FULL: f64 = 65535.0;

impl Curve {
    /// The rebuilt table (built once per curve).
    pub fn cumulative(self) -> &'static Cumulative {
        use std::sync::OnceLock;
        static T: OnceLock<[Cumulative; 5]> = OnceLock::new();
        let all = T.get_or_init(|| {
            let cmf = one_nm_table(
                include_str!("../../../../data/spectra/cie1931_2deg_cmf.csv"),
                "cie1931_2deg_cmf.csv",
            );
            let s026 = one_nm_table(
                include_str!("../../../../data/spectra/cie_s026_alpha_opic_action_spectra.csv"),
                "cie_s026_alpha_opic_action_spectra.csv",
            );
            let col = |t: &crate::colour::cie::Table, name: &str| {
                let c = t.columns.iter().position(|c| c == name).unwrap_or(1);
                t.rows
                    .iter()
                    .map(|r| (r[0], r.get(c).copied().unwrap_or(0.0)))
                    .collect::<Vec<_>>()
            };
            let round = |x: f64| x.round();
            let floor = |x: f64| x.floor();
            [
                build_cumulative(&col(&cmf, "xbar"), 362, 774, 2, round),
                build_cumulative(&col(&cmf, "ybar"), 386, 760, 2, round),
                build_cumulative(&col(&cmf, "zbar"), 359, 624, 2, round),
                build_cumulative(&col(&s026, "rhodopic"), 382, 684, 0, floor),
                build_cumulative(&col(&s026, "melanopic"), 380, 651, 1, floor),
            ]
        });
        &all[self as usize]
    }
}

fn one_nm_table(text: &str, name: &str) -> crate::colour::cie::Table {
    // Compiled-in data: a failure is a build defect (and the tests parse every table).
    crate::colour::cie::Table::parse(text, name)
        .unwrap_or_else(|e| panic!("embedded table {name}: {e}"))
}

/// Cumulative sums of 1 nm samples `(nm, value)`, shifted by `offset` nm, normalised to
/// 65535 over the whole table and rounded by `rnd`; the last entry is full scale.
fn build_cumulative(
    samples: &[(f64, f64)],
    wlmin: i32,
    wlmax: i32,
    offset: i32,
    rnd: impl Fn(f64) -> f64,
) -> Cumulative {
    let total: f64 = samples.iter().map(|s| s.1).sum();
    let mut values: Vec<f64> = (wlmin..=wlmax)
        .map(|w| {
            let upto = (w + offset) as f64;
            let s: f64 = samples.iter().filter(|p| p.0 < upto).map(|p| p.1).sum();
            rnd(CUMUL_FULL * s / total)
        })
        .collect();
    if let Some(last) = values.last_mut() {
        *last = CUMUL_FULL;
    }
    Cumulative {
        wlmin,
        wlmax,
        values,
    }
}

/// Radiance's `spec_dot`: the dot product of band values `v` (layout `ch`, longest
/// wavelength first) with a curve, as a fraction of the curve's area (equal-energy white,
/// all bands 1, gives 1). Band edges are truncated to whole nm the way Radiance computes
/// them (from its `float` splits, in double); a 3-band value uses the splits themselves
/// (blue 380-480, green 480-588, red 588-780 by default).
pub fn spec_dot(v: &[f64], ch: &Channels, curve: Curve) -> f64 {
    let t = curve.cumulative();
    let ncs = v.len();
    if ncs == 0 {
        return 0.0;
    }
    // Radiance keeps WAVELENGTH_SPLITS as float.
    let wl: [f64; 4] = ch.splits.map(|x| x as f32 as f64);
    let step = (wl[0] - wl[3]) / ncs as f64;
    let mut wl1 = wl[3] as i32;
    let mut n = 0usize;
    if wl1 < t.wlmin {
        n += ((t.wlmin - wl1) as f64 / step) as usize;
        wl1 = t.wlmin;
    } else if wl1 >= t.wlmax {
        return 0.0;
    }
    let mut sum = 0.0;
    while n < ncs {
        let wl0 = wl1;
        wl1 = if ncs == 3 {
            wl[2 - n] as i32
        } else {
            (wl[3] + (n + 1) as f64 * step) as i32
        };
        let value = v[ncs - 1 - n];
        if wl1 >= t.wlmax {
            sum += (CUMUL_FULL - t.at(wl0)) * value;
            break;
        }
        sum += (t.at(wl1) - t.at(wl0)) * value;
        n += 1;
    }
    sum / CUMUL_FULL
}

/// Radiance's `spec_cie`: CIE XYZ (unit-area curves) of equal-energy light between `s` and
/// `e` nm (whole nm, either order).
pub fn spec_cie(s: i32, e: i32) -> [f64; 3] {
    let (s, e) = if s > e { (e, s) } else { (s, e) };
    [Curve::X, Curve::Y, Curve::Z].map(|c| {
        let t = c.cumulative();
        if s >= t.wlmax || e <= t.wlmin {
            0.0
        } else {
            (t.at(e) - t.at(s)) / CUMUL_FULL
        }
    })
}

/// Band edges of band `i` of `ch` as whole nm `(start, end)`, computed the way `rmtxop`
/// does for its RGB and XYZ rows (`rgbrow`, `xyzrow`: float arithmetic, truncated).
pub fn band_edges_nm(ch: &Channels, i: usize) -> (i32, i32) {
    let w0 = ch.splits[0] as f32;
    let w3 = ch.splits[3] as f32;
    let nc = ch.ncomp as f32;
    let end = w0 + (w3 - w0) * i as f32 / nc;
    let start = w0 + (w3 - w0) * (i + 1) as f32 / nc;
    (start as i32, end as i32)
}

/// Radiance's `xyz2rgbmat`: CIE XYZ to its standard RGB primaries (no white balance).
pub fn xyz_to_std_rgb() -> [[f64; 3]; 3] {
    inv3(rgb_to_xyz(&STD_PRIMARIES))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ch(n: usize) -> Channels {
        Channels::spectral(n, 380.0, 780.0).unwrap()
    }

    #[test]
    fn band_integrals_sum_to_the_curve_area() {
        let t = tables();
        let total: f64 = band_integrals(&t.cmf[1], &ch(18)).iter().sum();
        let area = integral(&t.cmf[1], 380.0, 780.0);
        assert!((total - area).abs() < 1e-9 * area);
        // ybar's area is 106.86 nm (CIE 1931, 5 nm table).
        assert!((area - 106.86).abs() < 0.1, "{area}");
        let xyz = band_xyz(&[1.0; 18], &ch(18));
        for v in xyz {
            assert!((v - 1.0).abs() < 1e-9, "{xyz:?}");
        }
    }

    #[test]
    fn radiance_cumulative_tables() {
        // Entries of Radiance's tables (spec_rgb.c), rebuilt from the 1 nm CIE data.
        let x = Curve::X.cumulative();
        assert_eq!(
            (x.at(379), x.at(380), x.at(402), x.at(480)),
            (7.0, 8.0, 108.0, 10566.0)
        );
        for c in [
            Curve::X,
            Curve::Y,
            Curve::Z,
            Curve::Scotopic,
            Curve::Melanopic,
        ] {
            let t = c.cumulative();
            assert_eq!(t.at(t.wlmin), 0.0, "{c:?}");
            assert_eq!(t.at(t.wlmax), CUMUL_FULL, "{c:?}");
            assert!(t.values.windows(2).all(|w| w[0] <= w[1]), "{c:?}");
            // Equal-energy white: the whole curve.
            for n in [3, 9, 18, 24] {
                let d = spec_dot(&vec![1.0; n], &ch(n.max(4)), c);
                let d = if n == 3 {
                    spec_dot(&[1.0; 3], &Channels::rgb(), c)
                } else {
                    d
                };
                // x̄ and z̄ start below 380 nm, where the bands do not reach.
                let want = 1.0 - t.at(380) / CUMUL_FULL;
                assert!((d - want).abs() < 1e-12, "{c:?} {n}: {d}");
            }
        }
    }
}
