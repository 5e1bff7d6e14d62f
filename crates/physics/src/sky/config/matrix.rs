//! # Sky matrices from a weather file: `gendaymtx` and `gensdaymtx` as one typed config
//!
//! [`SkyMatrixConfig::write`] reads the weather, computes the matrix with the chosen model
//! ([`super::super::matrix`] and [`super::super::spectral`] for Perez,
//! [`super::super::atmosphere_matrix`] for the physically based sky) and writes it with
//! gendaymtx's header lines. Rows are the ground (row 0) and the Tregenza/Reinhart patches
//! in gendaymtx's order, columns the time steps.

use super::{ColourEdit, Messages};
use crate::error::{Error, Result};
use crate::formats::header::Header;
use crate::formats::matrix::writer::{DOUBLE_DIGITS, FLOAT_DIGITS};
use crate::formats::matrix::{DataFormat, MatrixWriter, WriteOptions};
use crate::formats::weather::Weather;
use crate::formats::weather::epw::Epw;
use crate::progress::Stage;
use crate::radiometry::Channels;
use crate::sky::atmosphere::cache::{self, CacheStatus};
use crate::sky::atmosphere_matrix::{
    AtmosphereMatrixOptions, atmosphere_matrix, atmosphere_steps, native_channels,
};
use crate::sky::matrix::{Colours, MatrixOptions, average_column, latlong, sky_matrix, time_steps};
use crate::sky::spectral::spectral_sky_matrix;
use crate::sky::{PerezOptions, SkyPatches};
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};

/// The sky model of the matrix (`--model`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SkyModel {
    /// gendaymtx's Perez all-weather sky (with [`Bands`], a CIE daylight spectrum per part).
    #[default]
    Perez,
    /// gensdaymtx's physically based spectral sky (Bruneton's precomputed scattering).
    Atmosphere,
}

/// Spectral bands (Radiance's `-cs N -cw MIN MAX`); a missing value takes the model's
/// default (18 bands for Perez, 20 for the atmosphere; 380-780 nm).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Bands {
    pub n: Option<usize>,
    pub range: Option<(f64, f64)>,
}

impl Bands {
    fn channels(&self, default_n: usize) -> Result<Channels> {
        let (lo, hi) = self.range.unwrap_or((380.0, 780.0));
        Channels::spectral(self.n.unwrap_or(default_n), lo, hi)
    }
}

/// Everything `rspecsky`'s matrix mode takes (gendaymtx's letters in brackets).
#[derive(Debug, Clone, PartialEq)]
pub struct SkyMatrixConfig {
    /// The weather file (.wea or .epw, recognised by content).
    pub weather: PathBuf,
    /// Reinhart multiplication factor (`-m`, 1 = Tregenza).
    pub mf: usize,
    /// Output format (`-oa`, `-of`, `-od`).
    pub format: DataFormat,
    /// Write the header (`-h` clears it).
    pub header: bool,
    /// The command line for the header.
    pub command: Vec<String>,
    /// The output is a seekable file (NROWS may be patched in afterwards).
    pub seekable: bool,
    /// `--model`.
    pub model: SkyModel,
    /// `-d`, `-s`, `-g`, `-c` in command-line order.
    pub colours: Vec<ColourEdit>,
    /// `-r`: counter-clockwise rotation about the zenith, degrees.
    pub rotation_deg: f64,
    /// `-5`: five-phase suns with the solid angle of a disc of this diameter, degrees.
    pub five_phase_sun_deg: Option<f64>,
    /// `-O 1`: solar instead of visible radiance.
    pub solar_radiance: bool,
    /// `-i`: sunrise/sunset interval correction, minutes.
    pub interval_minutes: Option<f64>,
    /// `-u`: leave out night steps.
    pub skip_night: bool,
    /// `-A`: one column, the mean of the kept steps (`NAVERAGED=`).
    pub average: bool,
    /// `-cs`/`-cw`: a spectral matrix.
    pub bands: Option<Bands>,
    /// `--aod` (atmosphere only): one aerosol optical depth for every record.
    pub aod: Option<f64>,
    /// `-p` (atmosphere only): folder of the cached tables (default [`cache::default_dir`]).
    pub table_dir: Option<PathBuf>,
    /// `-l` (atmosphere only): aerosol profile file.
    pub mie: Option<PathBuf>,
}

impl SkyMatrixConfig {
    /// gendaymtx's defaults for `weather`.
    pub fn new(weather: impl Into<PathBuf>) -> Self {
        SkyMatrixConfig {
            weather: weather.into(),
            mf: 1,
            format: DataFormat::Ascii,
            header: true,
            command: Vec::new(),
            seekable: false,
            model: SkyModel::Perez,
            colours: Vec::new(),
            rotation_deg: 0.0,
            five_phase_sun_deg: None,
            solar_radiance: false,
            interval_minutes: None,
            skip_night: false,
            average: false,
            bands: None,
            aod: None,
            table_dir: None,
            mie: None,
        }
    }

    /// The rules about values and combinations, as one-line usage errors.
    pub fn validate(&self) -> Result<()> {
        if !(1..=100).contains(&self.mf) {
            return Err(Error::Usage(format!(
                "-m {}: expected a multiplication factor from 1 to 100",
                self.mf
            )));
        }
        if let Some(d) = self.five_phase_sun_deg {
            if !(d > 0.0 && d < 180.0) {
                return Err(Error::Usage(format!(
                    "-5 {d}: expected a sun diameter in degrees (e.g. 0.533)"
                )));
            }
        }
        match self.model {
            SkyModel::Perez => self.validate_perez(),
            SkyModel::Atmosphere => self.validate_atmosphere(),
        }
    }

    fn validate_perez(&self) -> Result<()> {
        for (set, what) in [
            (self.aod.is_some(), "--aod"),
            (self.table_dir.is_some(), "-p"),
            (self.mie.is_some(), "-l"),
        ] {
            if set {
                return Err(Error::Usage(format!(
                    "{what} is only used with --model atmosphere"
                )));
            }
        }
        Ok(())
    }

    fn validate_atmosphere(&self) -> Result<()> {
        let colour = self.colours.iter().any(|c| matches!(c, ColourEdit::Sky(_)));
        for (set, what) in [
            (colour, "-c (the model gives the sky colour)"),
            (self.five_phase_sun_deg.is_some(), "-5"),
            (self.solar_radiance, "-O 1"),
            (self.interval_minutes.is_some(), "-i"),
        ] {
            if set {
                return Err(Error::Usage(format!(
                    "{what} is not supported with --model atmosphere"
                )));
            }
        }
        if let Some(a) = self.aod {
            if !(0.0..10.0).contains(&a) {
                return Err(Error::Usage(format!(
                    "--aod {a}: aerosol optical depth must be 0 to 10"
                )));
            }
        }
        Ok(())
    }

    /// Validate, read the weather, compute and write the matrix to `out` (`name` in errors).
    pub fn write<W: Write>(&self, out: W, name: &str, msgs: &dyn Messages) -> Result<()> {
        self.validate()?;
        let weather = Weather::read_path(&self.weather)?;
        match self.model {
            SkyModel::Perez => self.write_perez(&weather, out, name, msgs),
            SkyModel::Atmosphere => self.write_atmosphere(&weather, out, name, msgs),
        }
    }

    fn header(&self, weather: &Weather) -> Header {
        let mut header = Header::new();
        header.push_command(&self.command);
        header.set("LATLONG", format!(" {}", latlong(weather)));
        header
    }

    fn write_options(&self) -> WriteOptions {
        let mut wopts = WriteOptions::new(self.format);
        wopts.header = self.header;
        wopts.seekable = self.seekable;
        wopts.ascii_digits = if self.format == DataFormat::Double {
            DOUBLE_DIGITS
        } else {
            FLOAT_DIGITS
        };
        wopts
    }

    /// The gendaymtx (Perez) matrix, RGB or spectral.
    fn write_perez<W: Write>(
        &self,
        weather: &Weather,
        out: W,
        name: &str,
        msgs: &dyn Messages,
    ) -> Result<()> {
        let site = &weather.site;
        let steps = time_steps(weather);
        let opts = MatrixOptions {
            perez: PerezOptions {
                rotation_deg: self.rotation_deg,
                five_phase_sun_deg: self.five_phase_sun_deg,
                solar_radiance: self.solar_radiance,
                interval_minutes: self.interval_minutes.unwrap_or(0.0),
            },
            colours: ColourEdit::apply_all(&self.colours, Colours::gendaymtx()),
            skip_night: self.skip_night,
        };
        let patches = SkyPatches::new(self.mf);
        // The matrix functions say how many steps are done after each block; the stage
        // counts what each call adds.
        let stage = Stage::new(
            msgs.progress(),
            "sky matrix",
            Some(steps.len() as u64),
            "time steps",
        );
        let counted = AtomicU64::new(0);
        let progress = |done: usize, _total: usize| {
            let before = counted.fetch_max(done as u64, Ordering::Relaxed);
            stage.advance((done as u64).saturating_sub(before));
        };
        let spectral = self.bands.map(|b| b.channels(18)).transpose()?;
        let mut header = self.header(weather);
        let wopts = self.write_options();
        if let Some(ch) = spectral {
            let mtx = spectral_sky_matrix(&patches, &steps, site, &opts, &ch, &progress);
            let shape = (mtx.nrows(), mtx.ncols(), ch);
            write_rows(out, name, header, shape, wopts, self.average, |p, row| {
                mtx.row(p, row)
            })
        } else if self.average {
            let (col, n) = average_column(&patches, &steps, site, &opts, &progress);
            header.set("NAVERAGED", n);
            let shape = (patches.len(), 1, Channels::rgb());
            write_rows(out, name, header, shape, wopts, false, |p, row| {
                row.clear();
                row.extend_from_slice(&col[3 * p..3 * p + 3]);
            })
        } else {
            let mtx = sky_matrix(&patches, &steps, site, &opts, &progress);
            let shape = (mtx.nrows(), mtx.ncols(), Channels::rgb());
            write_rows(out, name, header, shape, wopts, false, |p, row| {
                mtx.row(p, row)
            })
        }
    }

    /// The gensdaymtx (atmosphere) matrix.
    fn write_atmosphere<W: Write>(
        &self,
        weather: &Weather,
        out: W,
        name: &str,
        msgs: &dyn Messages,
    ) -> Result<()> {
        let opts = AtmosphereMatrixOptions {
            ground_reflectance: self.ground_mean(),
            aod: self.aod,
            rotation_deg: self.rotation_deg,
            with_sun: !self.colours.contains(&ColourEdit::SkyOnly),
            with_sky: !self.colours.contains(&ColourEdit::SunOnly),
            skip_night: self.skip_night,
        };
        let ch = match self.bands {
            None => native_channels(),
            Some(b) => b.channels(20)?,
        };
        // gensdaymtx reads the EPW's illuminance fields: parse it as EPW too when it is one.
        let epw = if weather.epw_text.is_some() {
            Some(Epw::read_path(&self.weather)?)
        } else {
            None
        };
        let patches = SkyPatches::new(self.mf);
        let steps = atmosphere_steps(weather, epw.as_ref(), &patches, &opts);
        let mie = crate::sky::genssky::load_mie(self.mie.as_deref())?;
        let mie_source = mie.source.clone();
        let dir = self.table_dir.clone().unwrap_or_else(cache::default_dir);
        msgs.info(&format!(
            "{} time steps; atmosphere tables in {} (computed once per climate and AOD)",
            steps.len(),
            dir.display()
        ));
        let (mtx, used) = atmosphere_matrix(
            &patches,
            &steps,
            &weather.site,
            &opts,
            &mie,
            &dir,
            &ch,
            msgs.progress(),
        )?;
        let mut header = self.header(weather);
        header.set(
            "SKYMODEL",
            " atmosphere (Bruneton precomputed scattering, gensdaymtx)",
        );
        header.set("AEROSOL", format!(" {mie_source}"));
        let tables: Vec<String> = used
            .iter()
            .map(|u| {
                let how = match &u.status {
                    CacheStatus::Hit(_) => "cached",
                    _ => "computed",
                };
                format!("{} AOD {} ({how})", u.climate.tag(), u.aod)
            })
            .collect();
        header.set("ATMOSPHERE", format!(" {}", tables.join(", ")));
        let shape = (mtx.nrows(), mtx.ncols(), ch);
        let wopts = self.write_options();
        write_rows(out, name, header, shape, wopts, self.average, |p, row| {
            mtx.row(p, row)
        })
    }

    /// The atmosphere model takes one ground reflectance: the mean of `-g r g b`.
    fn ground_mean(&self) -> f64 {
        self.colours
            .iter()
            .rev()
            .find_map(|c| match c {
                ColourEdit::Ground(g) => Some(g.iter().sum::<f64>() / g.len().max(1) as f64),
                _ => None,
            })
            .unwrap_or(0.2)
    }
}

/// Write `nrows` rows of `ncols` columns (or, with `average`, their mean as one column
/// with `NAVERAGED=`), each row filled by `row(p, buf)`.
fn write_rows<W: Write>(
    out: W,
    name: &str,
    mut header: Header,
    (nrows, ncols, ch): (usize, usize, Channels),
    wopts: WriteOptions,
    average: bool,
    mut row: impl FnMut(usize, &mut Vec<f64>),
) -> Result<()> {
    if average {
        header.set("NAVERAGED", ncols);
    }
    let out_cols = if average { 1 } else { ncols };
    let mut w = MatrixWriter::new(out, name, header, Some(nrows), out_cols, ch, wopts)?;
    let mut buf = Vec::new();
    for p in 0..nrows {
        row(p, &mut buf);
        if average {
            buf = average_columns(&buf, ch.ncomp, ncols);
        }
        w.write_row(&buf)?;
    }
    w.finish()?.flush().map_err(|e| Error::io(name, e))
}

/// The mean over `ncols` columns of a row of `ncomp`-channel values (gendaymtx -A).
fn average_columns(row: &[f64], ncomp: usize, ncols: usize) -> Vec<f64> {
    let mut out = vec![0.0; ncomp];
    for c in row.chunks_exact(ncomp) {
        for (o, v) in out.iter_mut().zip(c) {
            *o += v;
        }
    }
    out.iter().map(|s| s / ncols.max(1) as f64).collect()
}
