//! # A point-in-time gendaylit sky as scene text, as one typed config
//!
//! [`PointSkyConfig::text`] finds the sky's input (a weather record or given irradiances),
//! runs gendaylit's model ([`crate::sky::gendaylit`], its defaults: dew point 10.97 C, i.e.
//! 2 cm precipitable water, also for EPW records) and writes it with the sky and ground glow
//! sources ([`crate::sky::pointsky`]).

use super::ColourEdit;
use crate::error::{Error, Result};
use crate::formats::weather::{Site, Weather};
use crate::sky::gendaylit::{GendaylitInput, GendaylitOptions, GendaylitOutput, GendaylitSky};
use crate::sky::matrix::Colours;
use crate::sky::pointsky::{
    PointSkyColours, point_sky_text, record_input, split_ground_reflectance,
};
use std::io::Write;
use std::path::PathBuf;

/// Where the sky's irradiances come from.
#[derive(Debug, Clone, PartialEq)]
pub enum PointSkyInput {
    /// The record at the date of this weather file (.wea or .epw), at its site.
    Weather(PathBuf),
    /// Direct normal and diffuse horizontal irradiance, W/m2 (gendaylit `-W`), at `site`.
    Irradiance {
        direct: f64,
        diffuse: f64,
        site: Site,
    },
}

/// Everything `rspecsky --at` takes.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSkyConfig {
    /// Month 1..12.
    pub month: u32,
    /// Day 1..31.
    pub day: u32,
    /// Local standard time, hours (with a weather file, a record's own hour, e.g. 12.5).
    pub hour: f64,
    pub input: PointSkyInput,
    /// `-d`, `-s`, `-g`, `-c` in command-line order: `-s` drops the sun, `-d` blackens sky
    /// and ground glows, `-g` is split into gendaylit's grey value and the ground colour.
    pub colours: Vec<ColourEdit>,
    /// `-O 1`: solar instead of visible radiance.
    pub solar_radiance: bool,
    /// The words of the first comment line (the command line).
    pub command: Vec<String>,
}

/// Parse `"month day hour"` (`--at`): whole month and day, decimal hour, in range.
pub fn parse_date(at: &str) -> Result<(u32, u32, f64)> {
    let v: Vec<f64> = at
        .split_whitespace()
        .map(|w| w.parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .unwrap_or_default();
    let (month, day, hour) = match v[..] {
        [mo, d, h] if mo.fract() == 0.0 && d.fract() == 0.0 => (mo, d, h),
        _ => {
            return Err(Error::Usage(format!(
                "--at \"{at}\": expected \"month day hour\" (e.g. \"3 2 12.5\")"
            )));
        }
    };
    if !(1.0..=12.0).contains(&month)
        || !(1.0..=31.0).contains(&day)
        || !(0.0..=24.0).contains(&hour)
    {
        return Err(Error::Usage(format!(
            "--at \"{at}\": month 1..12, day 1..31 and hour 0..24 expected"
        )));
    }
    Ok((month as u32, day as u32, hour))
}

impl PointSkyConfig {
    /// The sky description (reads the weather file, if any).
    pub fn text(&self) -> Result<String> {
        let (month, day, hour) = (self.month, self.day, self.hour);
        let (site, input) = match &self.input {
            PointSkyInput::Weather(path) => {
                let w = Weather::read_path(path)?;
                let Some(input) = record_input(&w, month, day, hour) else {
                    return Err(Error::Usage(format!(
                        "{}: no record at month {month} day {day} hour {hour}",
                        path.display()
                    )));
                };
                (w.site, input)
            }
            PointSkyInput::Irradiance {
                direct,
                diffuse,
                site,
            } => (
                site.clone(),
                GendaylitInput::DirectNormalIrradiance {
                    direct: *direct,
                    diffuse: *diffuse,
                },
            ),
        };
        let defaults = Colours {
            sky: vec![1.0; 3],
            ground: vec![0.2; 3],
            sun: vec![1.0; 3],
        };
        let c = ColourEdit::apply_all(&self.colours, defaults);
        let (grey, ground_colour) =
            split_ground_reflectance([c.ground[0], c.ground[1], c.ground[2]]);
        let mut o = GendaylitOptions::new(input);
        o.ground_reflectance = grey;
        o.sun = c.sun[0] != 0.0;
        if self.solar_radiance {
            o.output = GendaylitOutput::Solar;
        }
        let (pos, sky) = GendaylitSky::for_date(&site, month, day, hour, false, None, &o);
        let colours = PointSkyColours {
            sky: [c.sky[0], c.sky[1], c.sky[2]],
            ground: ground_colour,
        };
        Ok(point_sky_text(
            &[self.command.join(" ")],
            &pos,
            &sky,
            &colours,
        ))
    }

    /// Write [`Self::text`] to `out` (`name` in errors).
    pub fn write(&self, mut out: impl Write, name: &str) -> Result<()> {
        let text = self.text()?;
        out.write_all(text.as_bytes())
            .and_then(|_| out.flush())
            .map_err(|e| Error::io(name, e))
    }
}
