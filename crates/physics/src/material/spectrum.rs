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
use crate::colour::bands::{Curve, band_integrals, rebin, spec_dot, xyz_to_rgb_clipped};
use crate::radiometry::{Channels, DEFAULT_SPLITS, MAX_SAMPLES};

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

/// Band means of the reflectance `ruplift` gives an RGB colour (linear Radiance RGB,
/// equal-energy white; [`crate::uplift::Uplifter`] with `method`): what `rdc --uplift`
/// puts in place of Radiance's step spectrum. Each band is the mean of the 5 nm spectrum's
/// piecewise-linear interpolant over the band (zero outside 380-780 nm). `None` when the
/// colour is not a reflectance (a channel outside [0, 1] or not finite).
///
/// The spectrum reproduces the colour under illuminant E exactly (CIE 1931, 5 nm; out of
/// gamut: the closest the model reaches), so photopic values agree with Radiance's step
/// spectrum under light close to equal-energy; under daylight they differ by the
/// metamerism of the two spectra (measured in `tests/all/spectral_misc.rs`). Fits are cached
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
}
