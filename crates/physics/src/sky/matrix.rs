//! # Sky matrices: one Perez sky per time step (gendaymtx)
//!
//! A sky matrix has one row per sky patch (row 0 the ground, then the Tregenza/Reinhart
//! patches in [`SkyPatches`] order, the zenith last) and one column per time step of a
//! weather file; each element is an NCOMP-channel radiance (W sr^-1 m^-2). This is
//! Radiance's `gendaymtx` (`LBNL-ETA/Radiance: src/gen/gendaymtx.c: main`); one column is
//! [`perez_sky_vector`] (Perez, Seals, Michalsky 1993, see [`crate::sky::perez`]).
//!
//! What gendaymtx's `main` does around the per-step model, reproduced here:
//!
//! ```text
//! site       .wea header, or EPW LOCATION (longitude/time zone sign-flipped, see
//!            crate::formats::weather)
//! day        leap-day rule: Feb 29 -> jd 60 and every later record +1 day (LeapDayTracker)
//! dew point  11 C for .wea input; EPW: 3-hour running mean of field 8 (DewPointMean)
//! units      .wea weather_data_file_units 1, 2 (direct horizontal), 3 (illuminance)
//! -u         drop steps whose sun is at or below -0.2665 deg altitude (half the disc)
//! -A         one column, the mean of the kept columns; NAVERAGED = their number
//! ```
//!
//! ## Memory layout (why the sky is held as f32 scalars)
//!
//! The model runs column by column (a column's normalisation needs every patch of that
//! step), but the matrix is written row-major (patch rows x time columns), so every column
//! must exist before the first row can be written. A full year at MF 4 is 2306 x 8760 x 3 =
//! 60 M values (485 MB as f64). Every column is, before colour, a scalar sky radiance per
//! patch, one ground scalar and at most 4 sun entries ([`SkyVector`]); the channels are
//! those scalars times constant colours. So [`SkyMatrix`] keeps the sky scalars as `f32`,
//! row-major (2306 x 8760 x 4 B = 81 MB for the MF 4 year; none at all with `-d`), the
//! ground per column and the sun entries per patch in `f64`, and builds each output row on
//! demand. `f32` rounding (6e-8 relative) is far below gendaymtx's own precision (it
//! computes in C `float` and prints 3 significant digits); recomputing the columns per row
//! block instead would double the model work for no gain in accuracy.
//!
//! Columns are computed in parallel (rayon) in blocks of [`BLOCK`] steps; results are
//! collected in step order, so the output does not depend on the thread count.

use super::efficacy::{DEFAULT_DEW_POINT, DewPointMean};
use super::patches::SkyPatches;
use super::perez::{InputUnits, PerezOptions, SkyVector, TimeStep, perez_sky_vector};
use super::solar::LeapDayTracker;
use crate::formats::weather::{Site, WeaUnits, Weather};
use rayon::prelude::*;

/// Time steps computed together (in parallel) before they are stored.
pub const BLOCK: usize = 256;

/// gendaymtx's `LATLONG=` header value: latitude north and longitude east, `%.8f`.
pub fn latlong(w: &Weather) -> String {
    format!(
        "{:.8} {:.8}",
        w.site.latitude_deg_n,
        w.site.longitude_deg_e + 0.0
    )
}

/// The time steps gendaymtx computes from a weather file: leap-day shifted day numbers,
/// the file's units, and (EPW input only) the running-mean dew point.
pub fn time_steps(w: &Weather) -> Vec<TimeStep> {
    let units = match w.units {
        WeaUnits::NormalIrradiance => InputUnits::DirectNormalIrradiance,
        WeaUnits::HorizontalIrradiance => InputUnits::DirectHorizontalIrradiance,
        WeaUnits::NormalIlluminance => InputUnits::DirectNormalIlluminance,
    };
    // Only EPW data carries a dew point; epw_text is set exactly for EPW input.
    let epw = w.epw_text.is_some();
    let mut leap = LeapDayTracker::new();
    let mut dew = DewPointMean::new();
    w.steps
        .iter()
        .map(|s| {
            let (month, day) = (u32::from(s.month), u32::from(s.day));
            TimeStep {
                month,
                day,
                jd: leap.day_of_year(month, day),
                hour: s.hour,
                direct: s.direct,
                diffuse: s.diffuse,
                units,
                dew_point: if epw {
                    dew.next(s.dew_point)
                } else {
                    DEFAULT_DEW_POINT
                },
            }
        })
        .collect()
}

/// Colours applied to the three parts of every column (any common channel count).
#[derive(Debug, Clone, PartialEq)]
pub struct Colours {
    /// Sky colour (gendaymtx `-c`; default [`super::perez::GENDAYMTX_SKY_COLOUR`]).
    pub sky: Vec<f64>,
    /// Ground reflectance (gendaymtx `-g`; default 0.2).
    pub ground: Vec<f64>,
    /// Sun colour (white; zero with `-s`).
    pub sun: Vec<f64>,
}

impl Colours {
    /// gendaymtx's defaults.
    pub fn gendaymtx() -> Colours {
        Colours {
            sky: super::perez::GENDAYMTX_SKY_COLOUR.to_vec(),
            ground: super::perez::GENDAYMTX_GROUND_REFLECTANCE.to_vec(),
            sun: vec![1.0; 3],
        }
    }

    pub fn ncomp(&self) -> usize {
        self.sky.len()
    }
}

/// Everything that shapes a sky matrix besides the weather.
#[derive(Debug, Clone, PartialEq)]
pub struct MatrixOptions {
    pub perez: PerezOptions,
    pub colours: Colours,
    /// gendaymtx `-u`: leave out steps with the sun below the horizon.
    pub skip_night: bool,
}

/// A sky matrix held compactly (see the module doc), rows built on demand.
#[derive(Debug, Clone)]
pub struct SkyMatrix {
    nrows: usize,
    colours: Colours,
    /// Indices (into the input steps) of the columns kept.
    columns: Vec<usize>,
    /// Sky scalars per patch row, `[patch][column]`; empty when the sky colour is all zero.
    sky: Vec<Vec<f32>>,
    /// Ground scalar per column.
    ground: Vec<f64>,
    /// Sun entries per patch: (column, radiance before the sun colour).
    sun: Vec<Vec<(usize, f64)>>,
}

impl SkyMatrix {
    /// Rows: patches including the ground.
    pub fn nrows(&self) -> usize {
        self.nrows
    }
    /// Columns: time steps kept.
    pub fn ncols(&self) -> usize {
        self.columns.len()
    }
    pub fn ncomp(&self) -> usize {
        self.colours.ncomp()
    }
    /// Which input steps the columns are.
    pub fn columns(&self) -> &[usize] {
        &self.columns
    }

    /// Row `p` (`ncols * ncomp` values, column-major within the row) into `out`.
    pub fn row(&self, p: usize, out: &mut Vec<f64>) {
        let (ncols, n) = (self.ncols(), self.ncomp());
        out.clear();
        out.resize(ncols * n, 0.0);
        if p == 0 {
            for (k, g) in self.ground.iter().enumerate() {
                for c in 0..n {
                    out[k * n + c] = g * self.colours.ground[c];
                }
            }
        } else if !self.sky.is_empty() {
            for (k, &v) in self.sky[p].iter().enumerate() {
                for c in 0..n {
                    out[k * n + c] = f64::from(v) * self.colours.sky[c];
                }
            }
        }
        for &(k, v) in &self.sun[p] {
            for c in 0..n {
                out[k * n + c] += v * self.colours.sun[c];
            }
        }
    }
}

/// Compute the columns of `steps` in blocks, in parallel, calling `each` with every block's
/// first step index and its vectors in step order; `progress(done)` after each block.
fn for_blocks(
    patches: &SkyPatches,
    steps: &[TimeStep],
    site: &Site,
    opts: &PerezOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
    mut each: impl FnMut(usize, Vec<SkyVector>),
) {
    for (b, block) in steps.chunks(BLOCK).enumerate() {
        let vectors: Vec<SkyVector> = block
            .par_iter()
            .map(|s| perez_sky_vector(patches, s, site, opts))
            .collect();
        each(b * BLOCK, vectors);
        progress((b * BLOCK + block.len()).min(steps.len()), steps.len());
    }
}

/// The gendaymtx matrix of `steps` (one column per step, or per daytime step with `-u`).
pub fn sky_matrix(
    patches: &SkyPatches,
    steps: &[TimeStep],
    site: &Site,
    opts: &MatrixOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> SkyMatrix {
    let nrows = patches.len();
    let keep_sky = opts.colours.sky.iter().any(|&c| c != 0.0);
    let mut rows: Vec<Vec<f32>> = if keep_sky {
        (0..nrows)
            .map(|_| Vec::with_capacity(steps.len()))
            .collect()
    } else {
        Vec::new()
    };
    let mut columns = Vec::with_capacity(steps.len());
    let mut ground = Vec::with_capacity(steps.len());
    let mut sun: Vec<Vec<(usize, f64)>> = vec![Vec::new(); nrows];
    for_blocks(patches, steps, site, &opts.perez, progress, |first, vs| {
        for (i, v) in vs.into_iter().enumerate() {
            if opts.skip_night && !v.sun_in_sky() {
                continue;
            }
            let k = columns.len();
            columns.push(first + i);
            ground.push(v.ground);
            for (row, &s) in rows.iter_mut().zip(&v.sky) {
                row.push(s as f32);
            }
            for &(p, r) in &v.sun {
                sun[p].push((k, r));
            }
        }
    });
    SkyMatrix {
        nrows,
        colours: opts.colours.clone(),
        columns,
        sky: rows,
        ground,
        sun,
    }
}

/// gendaymtx `-A`: the mean column (`nrows * ncomp` values) over the kept steps, and their
/// number (`NAVERAGED=`). Summed in step order in `f64`, so the result is deterministic.
pub fn average_column(
    patches: &SkyPatches,
    steps: &[TimeStep],
    site: &Site,
    opts: &MatrixOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> (Vec<f64>, usize) {
    let c = &opts.colours;
    let mut sum = vec![0.0; patches.len() * c.ncomp()];
    let mut n = 0usize;
    for_blocks(patches, steps, site, &opts.perez, progress, |_, vs| {
        for v in vs {
            if opts.skip_night && !v.sun_in_sky() {
                continue;
            }
            n += 1;
            for (s, x) in sum.iter_mut().zip(v.to_channels(&c.sky, &c.ground, &c.sun)) {
                *s += x;
            }
        }
    });
    if n > 0 {
        sum.iter_mut().for_each(|s| *s /= n as f64);
    }
    (sum, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steps() -> Vec<TimeStep> {
        (0..600)
            .map(|i| {
                let h = (i % 24) as f64 + 0.5;
                let day = 1 + (i / 24) as u32;
                let (dir, dif) = if (6.0..18.0).contains(&h) {
                    (300.0 + i as f64, 100.0 + (i % 7) as f64 * 20.0)
                } else {
                    (0.0, 0.0)
                };
                TimeStep::new(6, day.min(30), h, dir, dif)
            })
            .collect()
    }

    fn site() -> Site {
        Site {
            latitude_deg_n: 51.15,
            longitude_deg_e: -0.18,
            meridian_deg_e: 0.0,
            ..Site::default()
        }
    }

    #[test]
    fn rows_equal_the_columns_transposed() {
        let p = SkyPatches::new(1);
        let opts = MatrixOptions {
            perez: PerezOptions::default(),
            colours: Colours::gendaymtx(),
            skip_night: false,
        };
        let st = steps();
        let m = sky_matrix(&p, &st, &site(), &opts, &|_, _| {});
        assert_eq!((m.nrows(), m.ncols(), m.ncomp()), (146, 600, 3));
        let c = &opts.colours;
        let cols: Vec<Vec<f64>> = st
            .iter()
            .map(|s| {
                perez_sky_vector(&p, s, &site(), &opts.perez).to_channels(&c.sky, &c.ground, &c.sun)
            })
            .collect();
        let mut row = Vec::new();
        for r in 0..146 {
            m.row(r, &mut row);
            for (k, col) in cols.iter().enumerate() {
                for ch in 0..3 {
                    let (a, b) = (row[k * 3 + ch], col[r * 3 + ch]);
                    assert!((a - b).abs() <= 1e-7 * b.abs(), "{r} {k}: {a} {b}");
                }
            }
        }
        // The average is the mean of the rows.
        let (avg, n) = average_column(&p, &st, &site(), &opts, &|_, _| {});
        assert_eq!(n, 600);
        for r in 0..146 {
            m.row(r, &mut row);
            for ch in 0..3 {
                let mean: f64 = row.iter().skip(ch).step_by(3).sum::<f64>() / 600.0;
                assert!((mean - avg[r * 3 + ch]).abs() <= 1e-6 * mean.abs().max(1e-9));
            }
        }
    }

    #[test]
    fn weather_steps_follow_gendaymtx_conventions() {
        let wea = "place A_B\nlatitude 51.15\nlongitude 0.18\ntime_zone 0\n\
                   site_elevation 0\nweather_data_file_units 2\n\
                   2 28 12.5 100 50\n2 29 12.5 100 50\n3 1 12.5 100 50\n";
        let w = Weather::parse(wea, "t.wea").unwrap();
        let st = time_steps(&w);
        assert_eq!(
            st.iter().map(|s| s.jd).collect::<Vec<_>>(),
            vec![59, 60, 61],
            "Feb 29 is day 60 and shifts later days"
        );
        assert!(st.iter().all(|s| s.dew_point == DEFAULT_DEW_POINT));
        assert!(
            st.iter()
                .all(|s| s.units == InputUnits::DirectHorizontalIrradiance)
        );
        assert_eq!(
            (w.site.longitude_west(), w.site.meridian_west()),
            (0.18, 0.0)
        );
        assert_eq!(latlong(&w), "51.15000000 -0.18000000");
    }

    #[test]
    fn skip_night_keeps_daytime_steps_only() {
        let p = SkyPatches::new(1);
        let opts = MatrixOptions {
            perez: PerezOptions::default(),
            colours: Colours::gendaymtx(),
            skip_night: true,
        };
        let st = steps();
        let m = sky_matrix(&p, &st, &site(), &opts, &|_, _| {});
        assert!(m.ncols() > 0 && m.ncols() < 600);
        for &k in m.columns() {
            assert!(perez_sky_vector(&p, &st[k], &site(), &opts.perez).sun_in_sky());
        }
        let (_, n) = average_column(&p, &st, &site(), &opts, &|_, _| {});
        assert_eq!(n, m.ncols());
    }
}
