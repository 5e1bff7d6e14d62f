//! # Spectral sky matrices: the Perez sky with a daylight spectrum per part and time step
//!
//! `rspecsky -cs N` writes the same matrix as the photopic one ([`super::matrix`], the
//! gendaymtx counterpart: same patches, same row order, same time steps, same inputs in
//! W/m2 or lux) with `NCOMP = N` spectral bands instead of RGB. Each column is the Perez
//! (1993) sky of that step ([`super::perez::perez_sky_vector`]) split into its three parts,
//! and each part gets a CIE daylight spectrum (CIE 15:2004 eq. 3.3-3.5, the uplift module's
//! [`crate::colour::cie::daylight`]):
//!
//! | part | correlated colour temperature (modelling choice, see below) |
//! |---|---|
//! | diffuse sky | 6500 K for an overcast sky (Perez clearness `eps = 1`) rising with `ln eps` to 12000 K for the clearest skies (`eps >= 6.2`, Perez category 8) |
//! | sun (direct) | 4000 K at the horizon rising with `sin(altitude)` to 5800 K at 40 deg altitude and above |
//! | ground | the mix of the two above in proportion to the diffuse and direct horizontal illuminance, times a grey reflectance |
//!
//! The CCTs are a simple, documented parametrisation of the well-known trends (overcast
//! skies near D65; clear blue skies 10 000-15 000 K; the direct beam warmer at low sun;
//! e.g. Chain, Dumortier, Fontoynont 1999, *Solar Energy* 65(5)), not a fitted model; the
//! point of this matrix is a photopically exact Perez sky whose spectral *shape* follows
//! the sky condition. gensdaymtx (Radiance 6) instead runs a physically based clear-sky
//! model (Bruneton's precomputed scattering) and scales it by cloud cover: a different
//! sky, so the two agree on photopic totals only as far as Perez and that model agree.
//! Measured (`tests/all/spectral_sky.rs::compare_with_gensdaymtx`, London, 2 days, RADIANCE
//! 6.0a): photopic sums over the sky patches within 1.5 % at the first day's bright hours,
//! -24 % to +11 % on the second day's (where the sun's share and its patch spreading
//! differ most); our skies are 3-15 % bluer (380-480 over 680-780 nm: 1.41-1.45 against
//! 1.20-1.40). For gensdaymtx's own sky use `--model atmosphere`
//! ([`super::atmosphere_matrix`]). Speed: a London year at MF 1 and 18 bands takes 0.3 s CPU here; gensdaymtx
//! needs 0.26 s CPU per day after minutes of atmosphere precomputation per distinct aerosol
//! depth.
//!
//! **Photopic consistency.** Every spectrum is scaled so that its Radiance photopic value
//! (`179 sum_i v_i A_i`, `A_i` the share of the CIE 1931 ybar area inside band `i` from
//! Radiance's own cumulative observer tables, Radiance's `scolor_photopic`) equals that of the RGB matrix entry it replaces
//! (`179 (0.2651 R + 0.6701 G + 0.0648 B)`): weighting the spectral matrix photopically
//! gives rspecsky's photopic matrix (`rmtxop -c Y` of the RGB one), to float rounding
//! (real `rmtxop -c Y` of both: 1.2e-7 to 1.8e-7 worst relative, `tests/all/spectral_sky.rs`).
//! With Radiance's channel convention (a band value is the spectral radiance times the full
//! range, so equal-energy white is 1 in every band) the result feeds `rcontrib -cs N`
//! coefficients and `rmtx`/`rcomb` directly.

use super::matrix::{Colours, MatrixOptions};
use super::patches::SkyPatches;
use super::perez::{SkyVector, TimeStep, perez_sky_vector};
use crate::colour::bands::{Curve, band_integrals, spec_dot};
use crate::colour::cie::daylight;
use crate::formats::weather::Site;
use crate::radiometry::Channels;
use rayon::prelude::*;

/// CCT (K) of the diffuse sky for Perez clearness `epsilon` (see the module table).
pub fn sky_cct(epsilon: f64) -> f64 {
    let t = (epsilon.max(1.0).ln() / 6.2f64.ln()).clamp(0.0, 1.0);
    6500.0 + t * (12000.0 - 6500.0)
}

/// CCT (K) of the direct sun at `altitude` radians (see the module table).
pub fn sun_cct(altitude: f64) -> f64 {
    let t = (altitude.max(0.0).sin() / 40f64.to_radians().sin()).clamp(0.0, 1.0);
    4000.0 + t * (5800.0 - 4000.0)
}

/// The share of the photopic (ybar) area in each band: Radiance's `A_i`, from Radiance's
/// own cumulative observer tables and band-edge truncation
/// ([`crate::colour::bands::spec_dot`] with [`Curve::Y`], what `scolor_photopic` and
/// `rmtxop -c Y` use), so that `rmtx -c Y` of a spectral matrix equals the photopic value
/// of the RGB matrix it was scaled to (a 5 nm integration of the CIE tables differs from
/// Radiance's by up to 0.4 % per band set).
pub fn photopic_shares(ch: &Channels) -> Vec<f64> {
    let mut e = vec![0.0; ch.ncomp];
    (0..ch.ncomp)
        .map(|i| {
            e.iter_mut().for_each(|x| *x = 0.0);
            e[i] = 1.0;
            spec_dot(&e, ch, Curve::Y)
        })
        .collect()
}

/// Band means of CIE daylight of `cct`, scaled to unit Radiance photopic value
/// (`sum v_i A_i = 1`).
pub fn daylight_bands(cct: f64, ch: &Channels, shares: &[f64]) -> Vec<f64> {
    let Ok(d) = daylight(cct.clamp(4000.0, 25000.0)) else {
        return vec![1.0; ch.ncomp];
    };
    let v: Vec<f64> = band_integrals(&d, ch)
        .iter()
        .enumerate()
        .map(|(i, a)| {
            let (hi, lo) = ch.band(i);
            a / (hi - lo)
        })
        .collect();
    let y: f64 = v.iter().zip(shares).map(|(a, b)| a * b).sum();
    if y > 0.0 {
        v.iter().map(|x| x / y).collect()
    } else {
        vec![1.0; ch.ncomp]
    }
}

/// One column: the Perez parts and their spectra (already photopically scaled).
struct Column {
    step: usize,
    sky: Vec<f32>,
    ground: f64,
    sun: Vec<(usize, f64)>,
    s_sky: Vec<f64>,
    s_sun: Vec<f64>,
    s_ground: Vec<f64>,
}

/// A spectral sky matrix, rows built on demand (as [`super::matrix::SkyMatrix`]).
pub struct SpectralSkyMatrix {
    nrows: usize,
    ch: Channels,
    columns: Vec<Column>,
}

fn photopic(rgb: &[f64]) -> f64 {
    crate::radiometry::photopic([rgb[0], rgb[1], rgb[2]])
}

fn column(v: SkyVector, step: usize, ch: &Channels, shares: &[f64], c: &Colours) -> Column {
    let state = v.state;
    let eps = state.map_or(1.0, |s| s.epsilon);
    let alt = v.sun_position.altitude;
    let s_sky = daylight_bands(sky_cct(eps), ch, shares);
    let s_sun = daylight_bands(sun_cct(alt), ch, shares);
    // Ground: global horizontal light, diffuse and direct parts by their illuminance.
    let (dif, dir) = state.map_or((1.0, 0.0), |s| {
        (s.diff_illum, s.dir_illum * alt.sin().max(0.0))
    });
    let w = if dif + dir > 0.0 {
        dir / (dif + dir)
    } else {
        0.0
    };
    let (ks, kg, ku) = (photopic(&c.sky), photopic(&c.ground), photopic(&c.sun));
    let mix: Vec<f64> = s_sky
        .iter()
        .zip(&s_sun)
        .map(|(a, b)| kg * ((1.0 - w) * a + w * b))
        .collect();
    Column {
        step,
        sky: if ks != 0.0 {
            v.sky.iter().map(|&x| x as f32).collect()
        } else {
            Vec::new()
        },
        ground: v.ground,
        sun: v.sun,
        s_sky: s_sky.iter().map(|x| x * ks).collect(),
        s_sun: s_sun.iter().map(|x| x * ku).collect(),
        s_ground: mix,
    }
}

/// The spectral counterpart of [`super::matrix::sky_matrix`] (same options; the colours act
/// through their photopic values, see the module documentation).
pub fn spectral_sky_matrix(
    patches: &SkyPatches,
    steps: &[TimeStep],
    site: &Site,
    opts: &MatrixOptions,
    ch: &Channels,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> SpectralSkyMatrix {
    let shares = photopic_shares(ch);
    let mut columns = Vec::with_capacity(steps.len());
    for (b, block) in steps.chunks(super::matrix::BLOCK).enumerate() {
        let first = b * super::matrix::BLOCK;
        let cols: Vec<Option<Column>> = block
            .par_iter()
            .enumerate()
            .map(|(i, s)| {
                let v = perez_sky_vector(patches, s, site, &opts.perez);
                if opts.skip_night && !v.sun_in_sky() {
                    return None;
                }
                Some(column(v, first + i, ch, &shares, &opts.colours))
            })
            .collect();
        columns.extend(cols.into_iter().flatten());
        progress((first + block.len()).min(steps.len()), steps.len());
    }
    SpectralSkyMatrix {
        nrows: patches.len(),
        ch: *ch,
        columns,
    }
}

impl SpectralSkyMatrix {
    pub fn nrows(&self) -> usize {
        self.nrows
    }
    pub fn ncols(&self) -> usize {
        self.columns.len()
    }
    pub fn channels(&self) -> Channels {
        self.ch
    }
    /// Input step of each column.
    pub fn steps(&self) -> Vec<usize> {
        self.columns.iter().map(|c| c.step).collect()
    }

    /// Row `p` (`ncols * ncomp` values) into `out`.
    pub fn row(&self, p: usize, out: &mut Vec<f64>) {
        let n = self.ch.ncomp;
        out.clear();
        out.resize(self.ncols() * n, 0.0);
        for (k, c) in self.columns.iter().enumerate() {
            let o = &mut out[k * n..(k + 1) * n];
            if p == 0 {
                for (x, s) in o.iter_mut().zip(&c.s_ground) {
                    *x = c.ground * s;
                }
            } else if let Some(&v) = c.sky.get(p) {
                for (x, s) in o.iter_mut().zip(&c.s_sky) {
                    *x = f64::from(v) * s;
                }
            }
            for &(q, r) in &c.sun {
                if q == p {
                    for (x, s) in o.iter_mut().zip(&c.s_sun) {
                        *x += r * s;
                    }
                }
            }
        }
    }

    /// Radiance photopic weighting of row `p` per column, `179 sum_i v_i A_i`.
    pub fn photopic_row(&self, p: usize) -> Vec<f64> {
        let shares = photopic_shares(&self.ch);
        let mut row = Vec::new();
        self.row(p, &mut row);
        row.chunks_exact(self.ch.ncomp)
            .map(|v| 179.0 * v.iter().zip(&shares).map(|(a, b)| a * b).sum::<f64>())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sky::PerezOptions;
    use crate::sky::matrix::sky_matrix;

    fn steps() -> Vec<TimeStep> {
        // A clear noon, an overcast morning, a night.
        vec![
            TimeStep::new(6, 21, 12.5, 800.0, 100.0),
            TimeStep::new(11, 3, 9.5, 0.0, 60.0),
            TimeStep::new(1, 1, 0.5, 0.0, 0.0),
        ]
    }

    fn opts() -> MatrixOptions {
        MatrixOptions {
            perez: PerezOptions::default(),
            colours: Colours::gendaymtx(),
            skip_night: false,
        }
    }

    #[test]
    fn photopic_weighting_equals_the_rgb_matrix() {
        let site = Site {
            latitude_deg_n: 51.15,
            longitude_deg_e: -0.18,
            meridian_deg_e: 0.0,
            ..Site::default()
        };
        let p = SkyPatches::new(1);
        let ch = Channels::spectral(18, 380.0, 780.0).unwrap();
        let spec = spectral_sky_matrix(&p, &steps(), &site, &opts(), &ch, &|_, _| {});
        let rgb = sky_matrix(&p, &steps(), &site, &opts(), &|_, _| {});
        assert_eq!(spec.ncols(), rgb.ncols());
        let mut row = Vec::new();
        // The clear noon puts a sun into some patches: those rows carry it.
        let v = perez_sky_vector(&p, &steps()[0], &site, &opts().perez);
        assert!(!v.sun.is_empty());
        for r in 0..p.len() {
            rgb.row(r, &mut row);
            let y = spec.photopic_row(r);
            for (k, c) in row.chunks_exact(3).enumerate() {
                let want = 179.0 * photopic(c);
                assert!(
                    (y[k] - want).abs() <= 1e-6 * want.abs().max(1e-3),
                    "row {r} col {k}: {} vs {want}",
                    y[k]
                );
            }
        }
    }

    #[test]
    fn clear_skies_are_bluer_than_overcast_and_the_sun_redder() {
        let ch = Channels::spectral(18, 380.0, 780.0).unwrap();
        let a = photopic_shares(&ch);
        let over = daylight_bands(sky_cct(1.0), &ch, &a);
        let clear = daylight_bands(sky_cct(8.0), &ch, &a);
        let sun = daylight_bands(sun_cct(10f64.to_radians()), &ch, &a);
        // Band 17 is the bluest (380-402 nm), band 0 the reddest.
        assert!(clear[17] / clear[0] > over[17] / over[0]);
        assert!(sun[17] / sun[0] < over[17] / over[0]);
        assert_eq!(sky_cct(1.0), 6500.0);
        assert_eq!(sky_cct(20.0), 12000.0);
    }
}
