//! Weather data for sky generation: DAYSIM `.wea` files and EnergyPlus `.epw` files.
//!
//! Both formats reduce to one [`Weather`]: a [`Site`] and a list of [`WeatherStep`]s holding
//! the two solar quantities Radiance's `gendaymtx` needs (direct and diffuse, in the units of
//! [`WeaUnits`]) at a decimal local standard time, plus what sky models use besides (dew point,
//! aerosol optical depth, sky cover). [`Weather::read`] tells the two formats apart by their
//! first line (`place ...` or `LOCATION,...`), never by the file name, as Radiance's
//! `EPWopen` does (`src/gen/loadEPW.c`).
//!
//! Conventions, all following Radiance (`src/gen/loadEPW.c`, `src/cv/epw2wea.c`):
//!
//! | quantity | `.wea` header | `.epw` LOCATION | [`Site`] field |
//! |---|---|---|---|
//! | latitude | degrees north | degrees north | `latitude_deg_n` |
//! | longitude | degrees **west** positive | degrees **east** positive | `longitude_deg_e` = EPW value = −wea value |
//! | time zone | standard meridian, degrees **west** positive (e.g. `120` for UTC−8) | hours **east** of GMT (e.g. `-8.0`) | `meridian_deg_e` = 15 × EPW value = 15 × (−wea/15); [`Site::time_zone_hours_e`] = EPW value = −wea/15 |
//! | elevation | metres | metres | `elevation_m` |
//!
//! Time of a step: `.wea` rows carry decimal local standard time directly (e.g. `12.5`, the
//! middle of the hour from 12:00 to 13:00). EPW rows carry an hour `1..=24` that *ends* the
//! interval; Radiance's loader turns an hourly EPW hour `h` into `h - 1 + 0.5` (the middle of
//! the hour), and a sub-hourly one into `h - 1 + minute/60` (`scan_date` in `loadEPW.c`); we
//! do the same. `epw2wea` writes `h - 0.5` for hourly files, the same instant.
//!
//! Submodules: [`wea`] (reader and writer), [`epw`] (reader with every field kept).

pub mod epw;
pub mod wea;

use crate::error::{Error, Location, Result};
use nom::Parser;
use std::path::Path;

pub use epw::{Epw, EpwField, EpwHeader, EpwRecord};
pub use wea::{WeaStyle, write_wea};

/// What the two numbers of a `.wea` row are: the `weather_data_file_units` header keyword
/// (`loadEPW.c`: `WEAradnorm=1, WEAradhoriz=2, WEAphotnorm=3`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WeaUnits {
    /// 1: direct normal and diffuse horizontal irradiance, W/m² (what `epw2wea` writes).
    NormalIrradiance = 1,
    /// 2: direct horizontal and diffuse horizontal irradiance, W/m² (`gendaymtx` divides the
    /// direct value by sin(solar altitude)).
    HorizontalIrradiance = 2,
    /// 3: direct normal and diffuse horizontal illuminance, lx (`gensdaymtx` needs this).
    NormalIlluminance = 3,
}

/// Solar constant, W/m² (Kopp & Lean 2011, 1360.8 ± 0.5).
pub const SOLAR_CONSTANT: f64 = 1361.0;
/// Extraterrestrial solar illuminance, lx (Darula, Kittler & Gueymard 2005: 133.8 klx).
pub const SOLAR_ILLUMINANCE: f64 = 133_800.0;
/// How far above the top-of-atmosphere value a measured direct or diffuse value may be:
/// cloud enhancement reaches about 1.3 x the clear-sky value, never 1.5 x the solar
/// constant, so anything beyond is a unit or column mix-up (issue #19: a DNI of 1e308
/// became a sky of inf and NaN).
pub const MAX_OVER_EXTRATERRESTRIAL: f64 = 1.5;

/// The one policy for the direct and diffuse values of both weather formats (issue #19:
/// a negative DNI was an error in a `.wea` and silently a dark sky in an EPW): the missing
/// code as written (9999 W/m², EPW's; 999900 lx, EPW's for illuminance; `epw2wea` copies
/// it into `.wea` files) passes through unchanged, as Radiance passes it; any other value
/// must lie in 0 ..= 1.5 x the extraterrestrial value. `what` names the value.
pub(crate) fn check_solar_value(v: f64, what: &str, lux: bool) -> std::result::Result<(), String> {
    let (code, top, unit) = if lux {
        (999_900.0, SOLAR_ILLUMINANCE, "lx")
    } else {
        (9999.0, SOLAR_CONSTANT, "W/m2")
    };
    let max = MAX_OVER_EXTRATERRESTRIAL * top;
    // 1e308 written out in full is 309 digits.
    let v_shown = if v.abs() < 1e9 {
        format!("{v}")
    } else {
        format!("{v:e}")
    };
    if v < 0.0 {
        Err(format!(
            "negative {what} value {v_shown}: irradiance/illuminance cannot be negative"
        ))
    } else if v > max && v != code {
        Err(format!(
            "{what} value {v_shown} {unit} is above {max} {unit} (1.5 x the extraterrestrial value): \
             a unit or column mix-up? ({code} marks a missing value)"
        ))
    } else {
        Ok(())
    }
}

impl WeaUnits {
    /// The header code `1`, `2` or `3`.
    pub fn code(self) -> u8 {
        self as u8
    }
    pub fn from_code(code: i64) -> Option<WeaUnits> {
        match code {
            1 => Some(WeaUnits::NormalIrradiance),
            2 => Some(WeaUnits::HorizontalIrradiance),
            3 => Some(WeaUnits::NormalIlluminance),
            _ => None,
        }
    }
}

/// Where the weather was measured, or where a sky is generated: the one site type of the
/// workspace, in one sign convention (north and east positive).
///
/// Radiance's generators (`gensky -a -o -m`, `gendaymtx` after `loadEPW.c`) work in degrees
/// **west**; the sky code takes those numbers from [`Site::longitude_west`] and
/// [`Site::meridian_west`], and command lines that give west-positive values convert them
/// once, where they are parsed (`docs/radiance-notes.md` §5.4 and §7.1).
///
/// The time zone is stored as the standard meridian in degrees east (`meridian_deg_e`), not
/// in hours, because that keeps every sky path bit-identical to earlier versions (and so to
/// Radiance wherever they matched it; Radiance itself keeps a `.wea` zone as a C `float`):
/// - gensky/genssky `-m deg` is used by Radiance as given (`s_meridian = atof(...)`):
///   `meridian_deg_e = -deg` and `meridian_west() = -(-deg)` are exact for any value, where
///   hours (`-deg / 15`, then `-15 × hours`) lose the last bit for many meridians that are
///   not multiples of 3.75° (e.g. 122.04).
/// - An EPW gives hours `h` and gendaymtx uses `s_meridian = -15.*timezone`: the reader stores
///   `15 × h`, so `meridian_west()` is exactly `-15 × h`.
/// - A `.wea` `time_zone v` goes through hours in Radiance's loader (`timezone *= -1./15.`)
///   and back in gendaymtx; the reader stores `15 × (-v / 15)`, the meridian earlier versions
///   used (equal to `-v` for every real zone, all multiples of 3.75°).
///
/// [`Site::time_zone_hours_e`] gives the hours back (`meridian_deg_e / 15`): exact for every
/// quarter-hour zone, and it returns the `-v / 15` a `.wea` gave (checked numerically on
/// 2·10⁷ meridians); only for an EPW zone that is not a multiple of 0.25 h can
/// `(15 × h) / 15` differ from `h` in the last bit.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Site {
    /// City (EPW LOCATION field 1; the part of a `.wea` `place` before the first `_`).
    pub name: String,
    /// Country (EPW LOCATION field 3; the part of a `.wea` `place` after the first `_`).
    pub country: String,
    /// Degrees north (−90..=90); gensky `-a`.
    pub latitude_deg_n: f64,
    /// Degrees east (−180..=180). A `.wea` file and gensky `-o` give the negative of this.
    pub longitude_deg_e: f64,
    /// Standard meridian of the time zone in degrees east (−180..=180), `15 ×` the zone's
    /// hours east of GMT. A `.wea` `time_zone` and gensky `-m` give the negative of this.
    pub meridian_deg_e: f64,
    /// Metres above sea level (−1000..=9999.9).
    pub elevation_m: f64,
}

impl Site {
    /// The standard meridian of a time zone `hours` east of GMT, in degrees east, as
    /// Radiance computes it from a weather file's zone (`15 × hours`).
    pub fn meridian_from_hours(hours: f64) -> f64 {
        15.0 * hours
    }

    /// Standard time zone in hours east of GMT (−12..=12), the EPW LOCATION value.
    pub fn time_zone_hours_e(&self) -> f64 {
        self.meridian_deg_e / 15.0
    }

    /// Longitude in degrees **west** of Greenwich, Radiance's generator convention
    /// (gensky `-o`, gendaymtx's `s_longitude = -loc.longitude`; `docs/radiance-notes.md`
    /// §5.4, §7.1): `-longitude_deg_e`, exact.
    pub fn longitude_west(&self) -> f64 {
        -self.longitude_deg_e
    }

    /// Standard meridian in degrees **west**, Radiance's generator convention (gensky `-m`,
    /// gendaymtx's `s_meridian = -15.*loc.timezone`; `docs/radiance-notes.md` §5.4, §7.1):
    /// `-meridian_deg_e`, exact (see the type's documentation for why the meridian is stored).
    pub fn meridian_west(&self) -> f64 {
        -self.meridian_deg_e
    }

    /// The `.wea` `place` value: `city_country` (`epw2wea` joins them with `_`, and
    /// `loadEPW.c` splits at the first `_`).
    pub fn place(&self) -> String {
        if self.country.is_empty() {
            self.name.clone()
        } else {
            format!("{}_{}", self.name, self.country)
        }
    }

    /// Range checks Radiance applies to every site (`bad_location` in `loadEPW.c`); `what`
    /// names the offending quantity and its allowed range on failure.
    pub(crate) fn check(&self) -> std::result::Result<(), String> {
        fn within(v: f64, lo: f64, hi: f64, what: &str) -> std::result::Result<(), String> {
            if (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(format!("{what} {v} out of range [{lo}, {hi}]"))
            }
        }
        within(self.latitude_deg_n, -90.0, 90.0, "latitude")?;
        within(self.longitude_deg_e, -180.0, 180.0, "longitude")?;
        within(self.time_zone_hours_e(), -12.0, 12.0, "time zone (hours)")?;
        within(self.elevation_m, -1000.0, 9999.9, "elevation")
    }
}

/// One time step of weather data.
#[derive(Debug, Clone, PartialEq)]
pub struct WeatherStep {
    /// Calendar month 1..=12.
    pub month: u8,
    /// Day of the month 1..=31 (Feb 29 allowed, as Radiance does).
    pub day: u8,
    /// Decimal local standard time 0..=24, the instant Radiance evaluates the sky at (see
    /// the module documentation for how EPW hours map to it).
    pub hour: f64,
    /// Direct component in the file's [`WeaUnits`]: direct normal (1, 3) or direct horizontal
    /// (2). From an EPW: Direct Normal Radiation (field 15) as written, missing code included.
    pub direct: f64,
    /// Diffuse horizontal component in the file's [`WeaUnits`]. From an EPW: Diffuse
    /// Horizontal Radiation (field 16) as written.
    pub diffuse: f64,
    /// Aerosol optical depth as the file writes it (`.wea` 6th column, EPW field 30; both in
    /// EPW's "thousandths" convention, which `loadEPW.c` multiplies by 1e-3). `None` when the
    /// file has no such column. Missing codes are passed through, as `epw2wea -a` does.
    pub aod: Option<f64>,
    /// Total sky cover as a fraction 0..=1 (`.wea` 7th column; EPW field 23 is in tenths and
    /// is divided by 10 here, as `epw2wea -a` does; a missing `99` becomes `9.9`).
    pub sky_cover: Option<f64>,
    /// Dew point temperature, °C (EPW field 8), `None` when absent or missing (`>= 99.9`).
    /// `gendaymtx` uses a 3-hour running mean of it for precipitable water and 11 °C when a
    /// `.wea` file (which has no dew point) is read.
    pub dew_point: Option<f64>,
    /// Year (EPW only; typical-year files mix years).
    pub year: Option<i32>,
}

/// Weather data from either format, in Radiance's conventions (see the module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct Weather {
    pub site: Site,
    /// Units of every step's `direct` and `diffuse`. EPW data is always
    /// [`WeaUnits::NormalIrradiance`].
    pub units: WeaUnits,
    pub steps: Vec<WeatherStep>,
    /// The EPW LOCATION values exactly as written (latitude and elevation text), when the
    /// data came from an EPW: `epw2wea` copies those two verbatim, so keeping them lets
    /// [`WeaStyle::Epw2wea`] reproduce its output byte for byte.
    pub epw_text: Option<EpwSiteText>,
}

/// Verbatim LOCATION texts that `epw2wea` copies into the `.wea` header unchanged.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EpwSiteText {
    pub latitude: String,
    pub elevation: String,
}

/// Which of the two supported formats a text is, from its first line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WeatherFormat {
    Wea,
    Epw,
}

/// Tell the formats apart by content like `EPWopen`: a `.wea` starts with `place `, an EPW
/// with `LOCATION,` (both compared without regard to case).
pub fn detect(text: &str) -> Option<WeatherFormat> {
    let head = text.as_bytes();
    let starts =
        |p: &str| head.len() >= p.len() && head[..p.len()].eq_ignore_ascii_case(p.as_bytes());
    if starts("place ") {
        Some(WeatherFormat::Wea)
    } else if starts("LOCATION,") {
        Some(WeatherFormat::Epw)
    } else {
        None
    }
}

impl Weather {
    /// Read a `.wea` or `.epw` file, whichever it is.
    pub fn read_path(path: impl AsRef<Path>) -> Result<Weather> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| Error::io(&name, e))?;
        Weather::parse(&decode_text(&bytes), &name)
    }

    /// Parse the text of a `.wea` or `.epw` file; `file` names it in error messages.
    pub fn parse(text: &str, file: &str) -> Result<Weather> {
        match detect(text) {
            Some(WeatherFormat::Wea) => wea::parse(text, file),
            Some(WeatherFormat::Epw) => Ok(Weather::from_epw(&epw::Epw::parse(text, file)?)),
            None => {
                let first = text.lines().next().unwrap_or("");
                Err(Error::parse(
                    Location::line(file, 1),
                    format!(
                        "expected a WEA header ('place <city>_<country>') or an EPW \
                         'LOCATION,' record, found '{}'",
                        shorten(first)
                    ),
                ))
            }
        }
    }

    /// The steps Radiance's `gendaymtx` reads from an EPW: direct normal and diffuse
    /// horizontal irradiance (fields 15, 16), times as in the module documentation.
    pub fn from_epw(epw: &epw::Epw) -> Weather {
        let loc = &epw.header.location;
        let site = Site {
            name: loc.city.clone(),
            country: loc.country.clone(),
            latitude_deg_n: loc.latitude,
            longitude_deg_e: loc.longitude,
            meridian_deg_e: Site::meridian_from_hours(loc.time_zone),
            elevation_m: loc.elevation,
        };
        let per_hour = epw.header.records_per_hour();
        let steps = epw
            .records
            .iter()
            .map(|r| WeatherStep {
                month: r.month,
                day: r.day,
                hour: r.local_hour(per_hour),
                direct: r.raw(EpwField::DirectNormalRadiation).unwrap_or(9999.0),
                diffuse: r
                    .raw(EpwField::DiffuseHorizontalRadiation)
                    .unwrap_or(9999.0),
                aod: r.raw(EpwField::AerosolOpticalDepth),
                sky_cover: r.raw(EpwField::TotalSkyCover).map(|v| v / 10.0),
                dew_point: r.get(EpwField::DewPointTemperature),
                year: Some(r.year),
            })
            .collect();
        Weather {
            site,
            units: WeaUnits::NormalIrradiance,
            steps,
            epw_text: Some(EpwSiteText {
                latitude: loc.latitude_text.clone(),
                elevation: loc.elevation_text.clone(),
            }),
        }
    }

    /// The `.wea` text `epw2wea` would write for this weather (see [`WeaStyle::Epw2wea`]),
    /// with the aerosol/sky-cover columns when `atmosphere` is set (`epw2wea -a`).
    pub fn to_wea(&self, atmosphere: bool) -> String {
        let mut out = Vec::new();
        // Writing to a Vec cannot fail.
        let _ = write_wea(&mut out, self, WeaStyle::Epw2wea, atmosphere);
        String::from_utf8(out).unwrap_or_default()
    }
}

/// Weather files are ASCII in practice, but EPW comments and city names are sometimes
/// Latin-1: take UTF-8 when it is valid, otherwise map each byte to the same code point.
pub fn decode_text(bytes: &[u8]) -> String {
    match std::str::from_utf8(bytes) {
        Ok(s) => s.to_string(),
        Err(_) => bytes.iter().map(|&b| b as char).collect(),
    }
}

/// Days in each month with February 29 allowed, as `date_OK` in `loadEPW.c` does.
pub(crate) fn days_in_month(month: u8) -> u8 {
    match month {
        2 => 29,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// Check a calendar date and decimal hour as Radiance's `date_OK` does.
pub(crate) fn check_date(month: i64, day: i64, hour: f64) -> std::result::Result<(), String> {
    if !(1..=12).contains(&month) {
        return Err(format!("month {month} out of range 1..12"));
    }
    let dim = days_in_month(month as u8) as i64;
    if !(1..=dim).contains(&day) {
        return Err(format!("day {day} out of range 1..{dim} for month {month}"));
    }
    if !(0.0..=24.0).contains(&hour) {
        return Err(format!("hour {hour} out of range 0..24"));
    }
    Ok(())
}

/// A finite decimal number filling all of `token` (surrounding blanks allowed), with
/// nom's float grammar; `inf`/`nan` are refused because no weather quantity can be either.
pub(crate) fn number(token: &str) -> Option<f64> {
    let t = token.trim_matches([' ', '\t']);
    let r: nom::IResult<&str, f64> =
        nom::combinator::all_consuming(nom::number::complete::double).parse(t);
    match r {
        Ok((_, v)) if v.is_finite() && !t.is_empty() => Some(v),
        _ => None,
    }
}

/// A decimal integer filling all of `token` (surrounding blanks allowed, as in EPW's
/// `12/ 1` dates).
pub(crate) fn integer(token: &str) -> Option<i64> {
    let t = token.trim_matches([' ', '\t']);
    let r: nom::IResult<&str, i64> =
        nom::combinator::all_consuming(nom::character::complete::i64).parse(t);
    r.ok().map(|(_, v)| v)
}

/// Quote at most 60 characters of user input in a message.
pub(crate) fn shorten(s: &str) -> String {
    let s = s.trim_end_matches(['\r', '\n']);
    if s.chars().count() > 60 {
        let cut: String = s.chars().take(57).collect();
        format!("{cut}...")
    } else {
        s.to_string()
    }
}

/// Lines of a text with their 1-based numbers and without `\n` / `\r\n`.
pub(crate) fn numbered_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.split_inclusive('\n').enumerate().map(|(i, l)| {
        let l = l.strip_suffix('\n').unwrap_or(l);
        (i + 1, l.strip_suffix('\r').unwrap_or(l))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_refuse_junk_and_non_finite() {
        assert_eq!(number(" 12.5 "), Some(12.5));
        assert_eq!(number("-1e3"), Some(-1000.0));
        assert_eq!(number("1.2.3"), None);
        assert_eq!(number("inf"), None);
        assert_eq!(number("nan"), None);
        assert_eq!(number(""), None);
        assert_eq!(integer(" 1"), Some(1));
        assert_eq!(integer("1.5"), None);
    }

    #[test]
    fn dates_follow_radiance() {
        assert!(check_date(2, 29, 12.0).is_ok());
        assert!(check_date(2, 30, 12.0).is_err());
        assert!(check_date(13, 1, 12.0).is_err());
        assert!(check_date(1, 1, 24.0).is_ok());
        assert!(check_date(1, 1, 24.01).is_err());
        assert!(check_date(1, 0, 1.0).is_err());
    }

    #[test]
    fn detection_is_by_content() {
        assert_eq!(detect("place X_Y\n"), Some(WeatherFormat::Wea));
        assert_eq!(detect("PLACE X\n"), Some(WeatherFormat::Wea));
        assert_eq!(detect("location,a,b"), Some(WeatherFormat::Epw));
        assert_eq!(detect("latitude 5"), None);
        assert_eq!(detect(""), None);
    }
}
