//! Constant spectral patterns (Radiance 6 `spectrum` and `specfile`) and band integrals.
//!
//! A spectral pattern multiplies the colour of whatever it modifies (`src/rt/p_data.c`:
//! `p_spectrum`, `p_specfile` end in `smultscolor(r->pcol, scval)`); the materials then
//! multiply their own colour by that pattern colour (`normal.c`: diffuse colour; `glass.c`:
//! the transmission coefficient only; `source.c`: emitted radiance).
//!
//! How a sampled spectrum becomes the run's channels (`src/common/spec_rgb.c:
//! convertscolorcol`, `src/common/color.c: convertscolor`):
//! - the `n` samples, evenly spaced from `a` to `b` nm, stand for `n` adjacent intervals of
//!   width `(b - a)/(n - 1)` centred on them (so the spectrum covers `a - h` to `b + h`,
//!   `h` half a step);
//! - spectral runs (`-cs N`, N > 3): each band takes the overlap-weighted mean of those
//!   intervals, **zero** where the spectrum does not reach (no extrapolation, no
//!   normalisation);
//! - RGB runs: the spectrum is first rebinned to bands over the default range (as many as
//!   its own sampling density gives, at most 24), then taken to CIE XYZ with Radiance's
//!   cumulative observer tables ([`spec_dot`], as `scolor2cie` does) and to
//!   Radiance RGB with the standard primaries, clipping negative channels towards grey
//!   (`cie_rgb`, `clipgamut` with the lower bound only).
//!
//! A `specfile`'s data file is regular (`begin end n`) or irregular (`0 0 n w1..wn`);
//! Radiance resamples an irregular axis at `2 n` even steps with linear interpolation
//! (`p_specfile`) before the conversion above, and so do we.
//!
//! Band integrals of tabulated curves ([`band_integrals`]) integrate the piecewise-linear
//! interpolant of a 5 nm table exactly over each band; they turn band values into photopic,
//! melanopic or CIE XYZ quantities. Radiance's own way, integer cumulative tables over
//! whole-nm band edges (`spec_dot`, `spec_cie` in `spec_rgb.c`), is [`spec_dot`] /
//! [`spec_cie`] with the tables of [`Curve`] rebuilt from the CIE data: what `rmtx -c`
//! uses on spectral matrices to match `rmtxop` to float precision. The two differ by up
//! to a few 1e-3 of a band's weight.
//!
//! [`uplifted_bands`] replaces Radiance's RGB step spectrum by `ruplift`'s reflectance
//! (`rdc --uplift`).

use super::Color;
use crate::radiometry::{Channels, DEFAULT_SPLITS, MAX_SAMPLES, STD_PRIMARIES, rgb_to_xyz};
use crate::uplift::colorimetry::{WL_MIN, WL_STEP, tables};

/// A sampled spectrum: `values` evenly spaced from `first` to `last` nm (either order).
#[derive(Debug, Clone, PartialEq)]
pub struct Sampled {
    pub first: f64,
    pub last: f64,
    pub values: Vec<f64>,
}

impl Sampled {
    /// The spectrum of a `spectrum` primitive.
    pub fn new(first: f64, last: f64, values: Vec<f64>) -> Sampled {
        Sampled {
            first,
            last,
            values,
        }
    }

    /// A `specfile` data file: regular axes as they are, irregular ones resampled at twice
    /// their count by linear interpolation (Radiance's `p_specfile`).
    pub fn from_data(d: &crate::scene::SpecData) -> Sampled {
        let w = &d.wavelengths;
        let n = w.len();
        let (Some(&first), Some(&last)) = (w.first(), w.last()) else {
            return Sampled::new(380.0, 780.0, vec![]);
        };
        let step = (last - first) / (n as f64 - 1.0);
        let regular = w
            .iter()
            .enumerate()
            .all(|(i, &x)| (x - (first + i as f64 * step)).abs() <= 1e-6 * step.abs().max(1.0));
        if regular {
            return Sampled::new(first, last, d.values.clone());
        }
        let m = 2 * n;
        let step = (last - first) / (m as f64 - 1.0);
        let values = (0..m)
            .map(|k| interpolate(w, &d.values, first + k as f64 * step))
            .collect();
        Sampled::new(first, last, values)
    }

    /// The spectrum in the run's channels (see the module documentation).
    pub fn to_channels(&self, ch: &Channels) -> Color {
        let n = self.values.len();
        if n == 0 {
            return Color::black(ch.ncomp);
        }
        // The interval the samples cover, from the sample spacing.
        let h = if n > 1 {
            0.5 * (self.last - self.first) / (n as f64 - 1.0)
        } else {
            0.0
        };
        let (a, b) = (self.first - h, self.last + h);
        match ch.ncomp {
            n if n > 3 => {
                let v: Vec<f32> = rebin(&self.values, a, b, ch)
                    .iter()
                    .map(|&x| x as f32)
                    .collect();
                Color::from_slice(&v)
            }
            3 => {
                let rgb = self.rgb(a, b);
                Color::from_slice(&[rgb[0] as f32, rgb[1] as f32, rgb[2] as f32])
            }
            _ => {
                let rgb = self.rgb(a, b);
                super::to_channels(rgb, ch)
            }
        }
    }

    /// Radiance RGB (standard primaries, equal-energy white) of the spectrum.
    fn rgb(&self, a: f64, b: f64) -> [f64; 3] {
        let span = DEFAULT_SPLITS[0] - DEFAULT_SPLITS[3];
        let dnc = ((self.values.len() as f64 * span / (b - a).abs() + 0.99) as usize)
            .clamp(3, MAX_SAMPLES);
        let Ok(bands) = Channels::spectral(dnc.max(4), DEFAULT_SPLITS[3], DEFAULT_SPLITS[0]) else {
            return [0.0; 3];
        };
        let v = rebin(&self.values, a, b, &bands);
        // scolor2rgb: XYZ from Radiance's cumulative observer tables (`spec_dot`), not the
        // 5 nm CIE table, so coarse or steep spectra give rtrace's RGB (up to 3.5 % apart
        // on blue otherwise).
        let xyz = [Curve::X, Curve::Y, Curve::Z].map(|c| spec_dot(&v, &bands, c));
        xyz_to_rgb_clipped(xyz)
    }
}

/// Linear interpolation in a monotonic table (clamped at the ends).
fn interpolate(x: &[f64], y: &[f64], at: f64) -> f64 {
    let n = x.len().min(y.len());
    if n == 0 {
        return 0.0;
    }
    let inc = x[n - 1] >= x[0];
    for i in 1..n {
        let (x0, x1) = (x[i - 1], x[i]);
        let inside = if inc {
            at <= x1 || i == n - 1
        } else {
            at >= x1 || i == n - 1
        };
        if inside {
            if x1 == x0 {
                return y[i];
            }
            let t = ((at - x0) / (x1 - x0)).clamp(0.0, 1.0);
            return y[i - 1] + t * (y[i] - y[i - 1]);
        }
    }
    y[n - 1]
}

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
/// [`crate::uplift::colorimetry::tables`]) over each band of `ch`, in nm.
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
fn xyz_to_rgb_clipped(xyz: [f64; 3]) -> [f64; 3] {
    let m = rgb_to_xyz(&STD_PRIMARIES);
    let inv = invert3(&m);
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

fn invert3(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    let c =
        |r0: usize, c0: usize, r1: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    [
        [
            c(1, 1, 2, 2) / det,
            -c(0, 1, 2, 2) / det,
            c(0, 1, 1, 2) / det,
        ],
        [
            -c(1, 0, 2, 2) / det,
            c(0, 0, 2, 2) / det,
            -c(0, 0, 1, 2) / det,
        ],
        [
            c(1, 0, 2, 1) / det,
            -c(0, 0, 2, 1) / det,
            c(0, 0, 1, 1) / det,
        ],
    ]
}

/// Band means of the reflectance `ruplift` gives an RGB colour (linear Radiance RGB,
/// equal-energy white; [`crate::uplift::Uplifter`] with `method`): what `rdc --uplift`
/// puts in place of Radiance's step spectrum. Each band is the mean of the 5 nm spectrum's
/// piecewise-linear interpolant over the band (zero outside 380-780 nm). `None` when the
/// colour is not a reflectance (a channel outside [0, 1] or not finite).
///
/// The spectrum reproduces the colour under illuminant E exactly (CIE 1931, 5 nm; out of
/// gamut: the closest the model reaches), so photopic values agree with Radiance's step
/// spectrum under light close to equal-energy; under daylight they differ by the
/// metamerism of the two spectra (measured in `tests/spectral_misc.rs`). Fits are cached
/// per colour and method: a scene's surfaces share few colours.
pub fn uplifted_bands(
    rgb: [f64; 3],
    ch: &Channels,
    method: crate::uplift::Method,
) -> Option<Vec<f64>> {
    use crate::uplift::{Method, RgbSpace, Uplifter};
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};
    if !rgb.iter().all(|v| (0.0..=1.0).contains(v)) {
        return None;
    }
    if rgb == [0.0; 3] {
        return Some(vec![0.0; ch.ncomp]);
    }
    type Key = ([u64; 3], bool);
    static CACHE: OnceLock<Mutex<HashMap<Key, crate::uplift::Spectrum>>> = OnceLock::new();
    static BASIS: OnceLock<Uplifter> = OnceLock::new();
    static JAKOB: OnceLock<Uplifter> = OnceLock::new();
    let key = (rgb.map(f64::to_bits), method == Method::Basis);
    let cache = CACHE.get_or_init(|| Mutex::new(HashMap::new()));
    let cached = cache.lock().ok().and_then(|c| c.get(&key).copied());
    let spectrum = match cached {
        Some(s) => s,
        None => {
            let u = match method {
                Method::Basis => {
                    BASIS.get_or_init(|| Uplifter::new(RgbSpace::Radiance, Method::Basis))
                }
                Method::Jakob => {
                    JAKOB.get_or_init(|| Uplifter::new(RgbSpace::Radiance, Method::Jakob))
                }
            };
            let s = u.uplift_rgb(rgb).spectrum;
            if let Ok(mut c) = cache.lock() {
                c.insert(key, s);
            }
            s
        }
    };
    Some(
        band_integrals(&spectrum, ch)
            .iter()
            .enumerate()
            .map(|(i, a)| {
                let (hi, lo) = ch.band(i);
                if hi > lo { a / (hi - lo) } else { 0.0 }
            })
            .collect(),
    )
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
                include_str!("../../data/spectra/cie1931_2deg_cmf.csv"),
                "cie1931_2deg_cmf.csv",
            );
            let s026 = one_nm_table(
                include_str!("../../data/spectra/cie_s026_alpha_opic_action_spectra.csv"),
                "cie_s026_alpha_opic_action_spectra.csv",
            );
            let col = |t: &crate::uplift::colorimetry::Table, name: &str| {
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

fn one_nm_table(text: &str, name: &str) -> crate::uplift::colorimetry::Table {
    // Compiled-in data: a failure is a build defect (and the tests parse every table).
    crate::uplift::colorimetry::Table::parse(text, name)
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
    invert3(&rgb_to_xyz(&STD_PRIMARIES))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ch(n: usize) -> Channels {
        Channels::spectral(n, 380.0, 780.0).unwrap()
    }

    #[test]
    fn rebin_is_the_overlap_mean_and_zero_outside() {
        // 5 samples at 400, 450, ..., 600 cover 375-625 nm.
        let s = Sampled::new(400.0, 600.0, vec![1.0, 2.0, 3.0, 4.0, 5.0]);
        let c = s.to_channels(&ch(8)); // bands of 50 nm from 780 down
        let v = c.as_slice();
        // 780-730, 730-680, 680-630: nothing.
        assert_eq!(&v[..3], &[0.0, 0.0, 0.0]);
        // 630-580: 5 over 580-625 (45 nm) -> 4.5; 4 over 575..580 not in band.
        assert!((v[3] - 4.5).abs() < 1e-6, "{v:?}");
        // 580-530: 4 on 575-580? no: 525-575 is '4', 575-625 is '5' -> (5*5 + 4*45)/50.
        assert!(
            (v[4] - (5.0 * 5.0 + 4.0 * 45.0) / 50.0).abs() < 1e-5,
            "{v:?}"
        );
        // 430-380: 1 over 380-425, 2 over 425-430 -> (45 + 10)/50.
        assert!((v[7] - 55.0 / 50.0).abs() < 1e-6, "{v:?}");
        // Descending wavelengths give the same result.
        let r = Sampled::new(600.0, 400.0, vec![5.0, 4.0, 3.0, 2.0, 1.0]).to_channels(&ch(8));
        assert_eq!(r, c);
    }

    #[test]
    fn flat_spectrum_is_white_in_every_layout() {
        let s = Sampled::new(380.0, 780.0, vec![0.5; 41]);
        let v = s.to_channels(&ch(18));
        // The 41 samples cover 375-785 nm, so every band is inside: 0.5 everywhere.
        assert!(
            v.as_slice().iter().all(|&x| (x - 0.5).abs() < 1e-6),
            "{v:?}"
        );
        let rgb = s.to_channels(&Channels::rgb());
        for x in rgb.as_slice() {
            assert!((x - 0.5).abs() < 2e-3, "{rgb:?}");
        }
    }

    #[test]
    fn irregular_files_are_resampled_at_twice_their_count() {
        let d = crate::scene::SpecData {
            wavelengths: vec![400.0, 500.0, 700.0],
            values: vec![0.0, 1.0, 3.0],
        };
        let s = Sampled::from_data(&d);
        assert_eq!(s.values.len(), 6);
        assert_eq!(s.values[0], 0.0);
        assert_eq!(s.values[5], 3.0);
        // 460 nm: 0.6 of the way from 400 to 500.
        assert!((s.values[1] - 0.6).abs() < 1e-12, "{:?}", s.values);
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
