//! The DAYSIM weather file (`.wea`), as Radiance's `gendaymtx`/`gensdaymtx` read it.
//!
//! ```text
//! place London_GBR                 city, '_', country (split at the first '_')
//! latitude 51.15                   degrees north
//! longitude 0.180000               degrees WEST positive
//! time_zone -0                     standard meridian, degrees WEST positive (= -15 * hours east)
//! site_elevation 62.0              metres
//! weather_data_file_units 1        1: DNI+DHI W/m2, 2: direct horizontal+DHI W/m2, 3: DNI+DHI lx
//! 1 1 0.500 0 0                    month day hour direct diffuse [aod sky_cover]
//! ```
//! Sources: `src/gen/loadEPW.c` (`EPWopen`, `scan_date`, `EPWread`) and `src/cv/epw2wea.c`.
//!
//! Radiance reads the six header lines strictly in this order, one `sscanf` per line with the
//! keyword at column 0 (`place ` compared without case, the others exactly); a file with the
//! lines in another order is a "header format error". We enforce the same order and report the
//! line that breaks it. After the header Radiance checks the site ranges (`bad_location`) and
//! we do too.
//!
//! Deliberate differences, all stricter than Radiance (which would silently misread these):
//! - a data row must hold exactly 5 or 7 numbers on one line (Radiance reads `month day hour`
//!   with `fscanf`, so they could span lines, and ignores a lone 6th or any 8th column);
//! - month and day must be integers, every value a finite number (Radiance's `%f` stops at
//!   junk and keeps what it has);
//! - negative direct or diffuse values, and values above 1.5 x the extraterrestrial value
//!   other than the missing code, are errors (physically impossible; Radiance passes them
//!   to the sky model); the EPW reader applies the same policy
//!   ([`super::check_solar_value`]);
//! - at least one data row is required (`gendaymtx` exits with "no valid time steps").
//!
//! Blank lines between rows are skipped, as `fscanf` skips them.

use super::{
    Site, WeaUnits, Weather, WeatherStep, check_date, check_solar_value, integer, number,
    numbered_lines, shorten,
};
use crate::error::{Error, Location, Result};
use nom::{
    IResult, Parser,
    bytes::complete::{tag, tag_no_case, take_while, take_while1},
    character::complete::space0,
    multi::many0,
    sequence::delimited,
};
use std::io::Write;

/// How [`write_wea`] formats numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WeaStyle {
    /// Byte for byte what `epw2wea` writes: `longitude %f`, `time_zone %.0f`, rows
    /// `%d %d %.3f %.0f %.0f` (values rounded to whole units) and with `-a` ` %.3f %.1f`.
    /// Latitude and elevation are copied as the EPW wrote them when known.
    Epw2wea,
    /// Every number in its shortest exact form, so reading the file back gives the same
    /// values (the hours too).
    Exact,
}

/// The header keywords in the order Radiance requires them.
const KEYWORDS: [&str; 5] = [
    "latitude",
    "longitude",
    "time_zone",
    "site_elevation",
    "weather_data_file_units",
];

/// What each header line should look like, for messages.
const EXPECTED: [&str; 6] = [
    "'place <city>_<country>'",
    "'latitude <degrees north>'",
    "'longitude <degrees west>'",
    "'time_zone <meridian, degrees west>'",
    "'site_elevation <metres>'",
    "'weather_data_file_units <1|2|3>'",
];

/// `place <text>`: everything after `place ` (keyword without regard to case).
fn place_line(line: &str) -> IResult<&str, &str> {
    let (rest, _) = tag_no_case("place ").parse(line)?;
    Ok(("", rest))
}

/// `<keyword> <number>`: the keyword exactly at column 0, then the number's text.
fn keyword_line<'a>(line: &'a str, keyword: &str) -> IResult<&'a str, &'a str> {
    let (rest, _) = tag(keyword).parse(line)?;
    let (rest, _) = space0.parse(rest)?;
    Ok(("", rest))
}

/// The white-space separated tokens of a data row (any ASCII white space, as `fscanf`).
fn tokens(line: &str) -> IResult<&str, Vec<&str>> {
    let ws = |c: char| c.is_ascii_whitespace();
    many0(delimited(
        take_while(ws),
        take_while1(move |c: char| !ws(c)),
        take_while(ws),
    ))
    .parse(line)
}

/// Parse the text of a `.wea` file; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<Weather> {
    let mut lines = numbered_lines(text);
    let mut site = Site::default();
    let mut units = WeaUnits::NormalIrradiance;
    let mut last_header_line = 0;
    for (i, expected) in EXPECTED.iter().enumerate() {
        let Some((lno, line)) = lines.next() else {
            return Err(Error::parse(
                Location::line(file, i + 1),
                format!("file ends in the WEA header: expected {expected}"),
            ));
        };
        last_header_line = lno;
        let at = || Location::line(file, lno);
        let wrong = || {
            Error::parse(
                at(),
                format!("expected {expected}, found '{}'", shorten(line)),
            )
        };
        if i == 0 {
            let (_, place) = place_line(line).map_err(|_| wrong())?;
            // `%[^_]_%[^\r\n]`: the city must not be empty; the country may be.
            let (city, country) = place.split_once('_').unwrap_or((place, ""));
            if city.is_empty() {
                return Err(wrong());
            }
            site.name = city.to_string();
            site.country = country.to_string();
            continue;
        }
        let (_, value) = keyword_line(line, KEYWORDS[i - 1]).map_err(|_| wrong())?;
        let v = number(value).ok_or_else(wrong)?;
        match i {
            1 => site.latitude_deg_n = v,
            // Degrees west in the file; east in `Site` (loadEPW: `longitude *= -1`).
            2 => site.longitude_deg_e = -v,
            // Meridian in degrees west in the file, turned into hours east as loadEPW
            // does (`timezone *= -1./15.`) and back into degrees east as gendaymtx does
            // (`-15.*timezone`): the meridian earlier versions used, `-v` for real zones.
            3 => site.meridian_deg_e = Site::meridian_from_hours(-v / 15.0),
            4 => {
                site.elevation_m = v;
                site.check().map_err(|m| Error::parse(at(), m))?;
            }
            _ => {
                units = integer(value)
                    .and_then(WeaUnits::from_code)
                    .ok_or_else(|| {
                        Error::parse(
                            at(),
                            format!(
                                "weather_data_file_units must be 1, 2 or 3, found '{}'",
                                shorten(value.trim())
                            ),
                        )
                    })?;
            }
        }
    }
    let mut steps = Vec::new();
    for (lno, line) in lines {
        let at = || Location::line(file, lno);
        let toks = match tokens(line) {
            Ok(("", toks)) => toks,
            _ => return Err(Error::parse(at(), "unreadable data row")),
        };
        if toks.is_empty() {
            continue;
        }
        if toks.len() != 5 && toks.len() != 7 {
            return Err(Error::parse(
                at(),
                format!(
                    "expected 'month day hour value value [aod skycover]', found {} numbers",
                    toks.len()
                ),
            ));
        }
        let int = |k: usize, what: &str| {
            integer(toks[k]).ok_or_else(|| {
                Error::parse(
                    at(),
                    format!("expected an integer {what}, found '{}'", shorten(toks[k])),
                )
            })
        };
        let num = |k: usize, what: &str| {
            number(toks[k]).ok_or_else(|| {
                Error::parse(
                    at(),
                    format!("expected a number for {what}, found '{}'", shorten(toks[k])),
                )
            })
        };
        let month = int(0, "month")?;
        let day = int(1, "day")?;
        let hour = num(2, "hour")?;
        check_date(month, day, hour).map_err(|m| Error::parse(at(), m))?;
        let direct = num(3, "the direct value")?;
        let diffuse = num(4, "the diffuse value")?;
        let lux = units == WeaUnits::NormalIlluminance;
        for (v, what) in [(direct, "direct"), (diffuse, "diffuse")] {
            check_solar_value(v, what, lux).map_err(|m| Error::parse(at(), m))?;
        }
        let (aod, sky_cover) = if toks.len() == 7 {
            (Some(num(5, "aod")?), Some(num(6, "sky cover")?))
        } else {
            (None, None)
        };
        steps.push(WeatherStep {
            month: month as u8,
            day: day as u8,
            hour,
            direct,
            diffuse,
            aod,
            sky_cover,
            dew_point: None,
            year: None,
        });
    }
    if steps.is_empty() {
        return Err(Error::parse(
            Location::line(file, last_header_line + 1),
            "no data rows after the WEA header: expected 'month day hour value value'",
        ));
    }
    Ok(Weather {
        site,
        units,
        steps,
        epw_text: None,
    })
}

/// Write `weather` as a `.wea` file. `atmosphere` adds the aerosol optical depth and sky
/// cover columns (`epw2wea -a`); steps lacking them get EPW's missing codes `0.999`/`9.9`.
pub fn write_wea<W: Write + ?Sized>(
    w: &mut W,
    weather: &Weather,
    style: WeaStyle,
    atmosphere: bool,
) -> std::io::Result<()> {
    let site = &weather.site;
    // Keep the sign of zero: `epw2wea` prints `-1.0*atof("0.0")` as `-0.000000`.
    let lon_w = -site.longitude_deg_e;
    let tz_deg_w = site.meridian_west();
    writeln!(w, "place {}", site.place())?;
    match style {
        WeaStyle::Epw2wea => {
            match &weather.epw_text {
                Some(t) => writeln!(w, "latitude {}", t.latitude)?,
                None => writeln!(w, "latitude {}", site.latitude_deg_n)?,
            }
            writeln!(w, "longitude {lon_w:.6}")?;
            if site.time_zone_hours_e().fract() == 0.0 {
                writeln!(w, "time_zone {tz_deg_w:.0}")?;
            } else {
                // epw2wea truncates a fractional zone with atoi() (India's 5.5 h becomes
                // -75); we keep the exact meridian, which gendaymtx reads with %f.
                writeln!(w, "time_zone {tz_deg_w}")?;
            }
            match &weather.epw_text {
                Some(t) => writeln!(w, "site_elevation {}", t.elevation)?,
                None => writeln!(w, "site_elevation {}", site.elevation_m)?,
            }
        }
        WeaStyle::Exact => {
            writeln!(w, "latitude {}", site.latitude_deg_n)?;
            writeln!(w, "longitude {lon_w}")?;
            writeln!(w, "time_zone {tz_deg_w}")?;
            writeln!(w, "site_elevation {}", site.elevation_m)?;
        }
    }
    writeln!(w, "weather_data_file_units {}", weather.units.code())?;
    for s in &weather.steps {
        let aod = s.aod.unwrap_or(0.999);
        let cover = s.sky_cover.unwrap_or(9.9);
        match style {
            WeaStyle::Epw2wea => {
                write!(
                    w,
                    "{} {} {:.3} {:.0} {:.0}",
                    s.month, s.day, s.hour, s.direct, s.diffuse
                )?;
                if atmosphere {
                    write!(w, " {aod:.3} {cover:.1}")?;
                }
            }
            WeaStyle::Exact => {
                write!(
                    w,
                    "{} {} {} {} {}",
                    s.month, s.day, s.hour, s.direct, s.diffuse
                )?;
                if atmosphere {
                    write!(w, " {aod} {cover}")?;
                }
            }
        }
        writeln!(w)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const TINY: &str = "place San_Francisco_USA\nlatitude 37.62\nlongitude 122.4\n\
        time_zone 120\nsite_elevation 3.0\nweather_data_file_units 1\n\
        3 21 8.5 250 80\n3 21 12.5 800 120\n\n3 21 23.5 0 0 120 0.3\n";

    #[test]
    fn reads_header_with_radiance_signs() {
        let w = parse(TINY, "t.wea").unwrap();
        assert_eq!(w.site.name, "San");
        assert_eq!(w.site.country, "Francisco_USA");
        assert_eq!(w.site.longitude_deg_e, -122.4);
        assert_eq!(w.site.time_zone_hours_e(), -8.0);
        assert_eq!(w.steps.len(), 3);
        assert_eq!(w.steps[1].hour, 12.5);
        assert_eq!(w.steps[2].aod, Some(120.0));
        assert_eq!(w.steps[2].sky_cover, Some(0.3));
    }

    #[test]
    fn exact_style_round_trips() {
        let w = parse(TINY, "t.wea").unwrap();
        let mut out = Vec::new();
        write_wea(&mut out, &w, WeaStyle::Exact, false).unwrap();
        let back = parse(std::str::from_utf8(&out).unwrap(), "back.wea").unwrap();
        assert_eq!(back.site, w.site);
        for (a, b) in back.steps.iter().zip(&w.steps) {
            assert_eq!(
                (a.month, a.day, a.hour, a.direct, a.diffuse),
                (b.month, b.day, b.hour, b.direct, b.diffuse)
            );
        }
    }

    #[test]
    fn errors_name_the_line() {
        let bad = TINY.replace("3 21 12.5 800 120", "3 21 12.5 800");
        let e = parse(&bad, "site.wea").unwrap_err().to_string();
        assert_eq!(
            e,
            "site.wea:8: expected 'month day hour value value [aod skycover]', found 4 numbers"
        );
        let bad = TINY.replace("3 21 12.5", "13 21 12.5");
        let e = parse(&bad, "site.wea").unwrap_err().to_string();
        assert_eq!(e, "site.wea:8: month 13 out of range 1..12");
        let bad = TINY.replace("800 120", "-800 120");
        let e = parse(&bad, "site.wea").unwrap_err().to_string();
        assert!(
            e.starts_with("site.wea:8: negative direct value -800"),
            "{e}"
        );
    }
}
