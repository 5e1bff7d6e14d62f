//! Channel layouts: how many numbers a radiometric value carries and what they mean.
//!
//! Radiance 6 carries either 3 channels (RGB, the default primaries) or N equal-width
//! spectral bands (`-cs N -cw min max`), ordered from the **longest** wavelength down
//! (`src/common/color.c: setscolor`, `scolor2color`). A file says which with `NCOMP=` and,
//! for N > 3, `WAVELENGTH_SPLITS= lmax lRG lGB lmin` (default `780 588 480 380`, Radiance's
//! `WLPART`). Nothing in the core assumes 3: every buffer is `ncomp` wide.

use crate::error::{Error, Result};

/// Radiance's default wavelength splits `WLPART` (nm): max, red/green, green/blue, min.
pub const DEFAULT_SPLITS: [f64; 4] = [780.0, 588.0, 480.0, 380.0];

/// Luminous efficacy of equal-energy white over 380-780 nm, Radiance `WHTEFFICACY` (lm/W).
pub const WHITE_EFFICACY: f64 = 179.0;

/// Photopic weights of Radiance's standard RGB primaries: what its `luminance()`/`bright()`
/// macros compute (`src/common/color.h`: `CIE_rf` etc. are derived from the standard
/// primaries and equal-energy white, i.e. row Y of [`rgb_to_xyz`] of [`STD_PRIMARIES`]).
/// `179 * (w . rgb)` is luminance or illuminance. (color.h's comment quotes the older
/// 0.265074126/0.670114631/0.064811243; the compiled values, which evalglare and rmtxop
/// `-c Y` use, are these; they differ by up to 1.2e-4 relative on coloured values.)
/// Exactly 10021/37800, 2533/3780, 2449/37800.
pub const RGB_PHOTOPIC: [f64; 3] = [10021.0 / 37800.0, 2533.0 / 3780.0, 2449.0 / 37800.0];

/// Radiance's standard primaries `STDPRIMS` (`src/common/color.h`): x,y of R, G, B, white
/// (equal-energy white, not D65).
pub const STD_PRIMARIES: [f64; 8] = [
    0.640,
    0.330,
    0.290,
    0.600,
    0.150,
    0.060,
    1.0 / 3.0,
    1.0 / 3.0,
];

/// RGB to CIE XYZ for the given primaries (`x y` of R, G, B, white), scaled so that white
/// RGB (1,1,1) has Y = 1: the standard construction (e.g. Hunt, *The Reproduction of Colour*,
/// or Radiance's `compxyz2rgbmat`). Row 1 (Y) for Radiance's standard primaries is
/// (0.265106, 0.670106, 0.064788): what `rmtxop -c Y` (x 179) and Radiance's `luminance()`
/// use ([`RGB_PHOTOPIC`]).
pub fn rgb_to_xyz(p: &[f64; 8]) -> [[f64; 3]; 3] {
    let col = |x: f64, y: f64| [x / y, 1.0, (1.0 - x - y) / y];
    let m = [col(p[0], p[1]), col(p[2], p[3]), col(p[4], p[5])];
    let w = col(p[6], p[7]);
    // Solve M s = w for the primaries' scale factors (Cramer's rule on the 3x3 system whose
    // columns are the primaries' XYZ).
    let det3 = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
        a[0] * (b[1] * c[2] - b[2] * c[1]) - b[0] * (a[1] * c[2] - a[2] * c[1])
            + c[0] * (a[1] * b[2] - a[2] * b[1])
    };
    let d = det3(m[0], m[1], m[2]);
    let s = [
        det3(w, m[1], m[2]) / d,
        det3(m[0], w, m[2]) / d,
        det3(m[0], m[1], w) / d,
    ];
    let mut out = [[0.0; 3]; 3];
    for (row, out_row) in out.iter_mut().enumerate() {
        for (j, v) in out_row.iter_mut().enumerate() {
            *v = m[j][row] * s[j];
        }
    }
    out
}

/// Photopic part of an RGB value with [`RGB_PHOTOPIC`] (Radiance's `bright()`): `w . rgb`.
pub fn photopic(rgb: [f64; 3]) -> f64 {
    RGB_PHOTOPIC[0] * rgb[0] + RGB_PHOTOPIC[1] * rgb[1] + RGB_PHOTOPIC[2] * rgb[2]
}

/// Luminance (cd/m2) of RGB radiance, or illuminance (lx) of RGB irradiance:
/// `179 (w . rgb)` with Radiance's compiled weights (`luminance()`, `rmtxop -c Y`).
pub fn luminance(rgb: [f64; 3]) -> f64 {
    WHITE_EFFICACY * photopic(rgb)
}

/// [`luminance`] with the rounded weights [`RGB_PHOTOPIC_ROUNDED`] (`rmtxop -c 47.4 119.9
/// 11.6`, the `rcalc` line of Radiance tutorials, `rdc -oi`).
pub fn luminance_rounded(rgb: [f64; 3]) -> f64 {
    let w = RGB_PHOTOPIC_ROUNDED;
    WHITE_EFFICACY * (w[0] * rgb[0] + w[1] * rgb[1] + w[2] * rgb[2])
}

/// The rounded weights most pipelines use (`rmtxop -c 47.4 119.9 11.6` = 179 x .265/.670/.065).
pub const RGB_PHOTOPIC_ROUNDED: [f64; 3] = [0.265, 0.670, 0.065];

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Channels {
    /// Number of components per value (NCOMP).
    pub ncomp: usize,
    /// Wavelength splits (nm); meaningful for spectral layouts, default for RGB.
    pub splits: [f64; 4],
}

impl Default for Channels {
    fn default() -> Self {
        Channels::rgb()
    }
}

impl Channels {
    pub const fn rgb() -> Self {
        Channels {
            ncomp: 3,
            splits: DEFAULT_SPLITS,
        }
    }

    /// One channel (grey, or an already weighted quantity such as illuminance).
    pub const fn mono() -> Self {
        Channels {
            ncomp: 1,
            splits: DEFAULT_SPLITS,
        }
    }

    /// N spectral bands from `wl_max` down to `wl_min` (Radiance `-cs N -cw min max`).
    /// Radiance accepts 3 <= N <= 24 (`MAXCSAMP`) and a range of at least 50 nm.
    pub fn spectral(n: usize, wl_min: f64, wl_max: f64) -> Result<Self> {
        if !(3..=crate::radiometry::MAX_SAMPLES).contains(&n) {
            return Err(Error::Usage(format!(
                "-cs {n}: the number of spectral samples must be between 3 and {MAX_SAMPLES}"
            )));
        }
        // Written to also reject NaN ranges.
        if wl_max - wl_min < 50.0 || wl_max.is_nan() || wl_min.is_nan() || wl_min <= 0.0 {
            return Err(Error::Usage(format!(
                "-cw {wl_min} {wl_max}: the wavelength range must span at least 50 nm"
            )));
        }
        let mut splits = DEFAULT_SPLITS;
        splits[0] = wl_max;
        splits[3] = wl_min;
        // Keep the R/G and G/B splits inside the range, as Radiance's setspectrsamp does.
        splits[1] = splits[1].clamp(wl_min, wl_max);
        splits[2] = splits[2].clamp(wl_min, wl_max);
        Ok(Channels { ncomp: n, splits })
    }

    pub fn is_spectral(&self) -> bool {
        self.ncomp > 3
    }

    /// Band `i` as `(upper, lower)` wavelengths in nm; band 0 is the longest wavelength.
    pub fn band(&self, i: usize) -> (f64, f64) {
        let step = (self.splits[3] - self.splits[0]) / self.ncomp as f64;
        let hi = self.splits[0] + i as f64 * step;
        (hi, hi + step)
    }
}

/// Radiance's limit on spectral samples (`MAXCSAMP`).
pub const MAX_SAMPLES: usize = 24;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spectral_bands_run_long_to_short() {
        let c = Channels::spectral(20, 380.0, 780.0).unwrap();
        assert_eq!(c.band(0), (780.0, 760.0));
        assert_eq!(c.band(19), (400.0, 380.0));
    }

    #[test]
    fn photopic_weights_are_the_primaries_row_y() {
        let y = rgb_to_xyz(&STD_PRIMARIES)[1];
        for (a, b) in y.iter().zip(RGB_PHOTOPIC) {
            assert!((a - b).abs() < 1e-15, "{a} vs {b}");
        }
    }

    #[test]
    fn std_rgb_to_y_matches_rmtxop() {
        // `rmtxop -c Y` on RGB printed 47.45394 119.94894 11.59712 (radiance-notes.md §0).
        let y = rgb_to_xyz(&STD_PRIMARIES)[1];
        for (got, want) in y.iter().zip([47.45394, 119.94894, 11.59712]) {
            assert!((got * WHITE_EFFICACY - want).abs() < 1e-4, "{got}");
        }
        assert!((y.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn rejects_out_of_range() {
        assert!(Channels::spectral(2, 380.0, 780.0).is_err());
        assert!(Channels::spectral(25, 380.0, 780.0).is_err());
        assert!(Channels::spectral(5, 500.0, 520.0).is_err());
    }
}
