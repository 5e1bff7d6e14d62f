//! # Spectral measurements: long-form CSV, one column per sensor channel
//!
//! As the photopic readings ([`crate::measurements`]) with the single `lux` column
//! replaced by one column per channel of a spectral sensor, the header naming each
//! channel by its centre wavelength (`410nm`, `410 nm` or `410`):
//!
//! ```text
//! month,day,hour,sensor,391nm,413nm,436nm,...
//! 11,13,10.5,nPC_C,0.0123,0.0141,0.0158,...
//! ```
//!
//! Values are what the channel reports in the unit [`super::channels`] states (spectral
//! irradiance in W m-2 nm-1 without response curves). Blank lines and `#` lines are
//! skipped. [`SpectralReadings::parse`] checks the syntax (file:line, what was found, what
//! was expected: missing or negative values, field counts, the header);
//! [`SpectralReadings::bind`] matches readings to sensors and weather steps with the
//! photopic readings' rules and messages (unknown sensor ids, time stamps not in the
//! weather file, duplicates).

use crate::csv::{self, shorten};
use crate::error::{Error, Location, Result};
use crate::measurements::{Bound, Measurements, Reading, check_stamp};
use nom::Parser;
use nom::bytes::complete::tag_no_case;
use nom::character::complete::space0;
use nom::combinator::{all_consuming, opt};
use nom::number::complete::double;

/// Leading columns before the channels.
pub const KEYS: [&str; 4] = ["month", "day", "hour", "sensor"];

/// Largest number of channels accepted (a hyperspectral sensor with 1 nm steps).
pub const MAX_CHANNELS: usize = 2048;

/// One reading: all channels of one sensor at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralReading {
    pub month: u32,
    pub day: u32,
    pub hour: f64,
    pub sensor: String,
    pub values: Vec<f64>,
    /// 1-based CSV line.
    pub line: usize,
}

/// A spectral measurement file.
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralReadings {
    pub file: String,
    /// Channel names as written in the header.
    pub names: Vec<String>,
    /// Centre wavelength of each channel (nm).
    pub centres: Vec<f64>,
    /// Line of the header.
    pub header_line: usize,
    pub readings: Vec<SpectralReading>,
}

/// A channel name's centre wavelength: `410nm`, `410 nm`, `410`.
pub fn wavelength_of(name: &str) -> Option<f64> {
    let r: nom::IResult<&str, (f64, &str, Option<&str>)> =
        all_consuming((double, space0, opt(tag_no_case("nm")))).parse(name.trim());
    match r {
        Ok((_, (v, _, _))) if v.is_finite() && v > 0.0 => Some(v),
        _ => None,
    }
}

/// The header: the keys, then channel names with their centre wavelengths.
fn header(l: &csv::Line) -> Result<(Vec<String>, Vec<f64>)> {
    let f = &l.fields;
    let keys_ok =
        f.len() > KEYS.len() && f.iter().zip(KEYS).all(|(a, b)| a.eq_ignore_ascii_case(b));
    if !keys_ok {
        return Err(l.error(format!(
            "expected the header 'month,day,hour,sensor,' then one column per \
             channel named by its centre wavelength (e.g. 410nm), found '{}'",
            shorten(l.text)
        )));
    }
    if f.len() - KEYS.len() > MAX_CHANNELS {
        return Err(l.error(format!(
            "{} channels; at most {MAX_CHANNELS} are supported",
            f.len() - KEYS.len()
        )));
    }
    let mut centres = Vec::new();
    for (k, name) in f[KEYS.len()..].iter().enumerate() {
        let c = wavelength_of(name).ok_or_else(|| {
            l.error(format!(
                "column {}: expected a channel's centre wavelength such as \
                 410nm, found '{}'",
                k + KEYS.len() + 1,
                shorten(name)
            ))
        })?;
        centres.push(c);
    }
    Ok((
        f[KEYS.len()..].iter().map(|s| s.to_string()).collect(),
        centres,
    ))
}

/// A row: time stamp, sensor and one value per channel of the header's `names`.
fn row(names: &[String], l: &csv::Line) -> Result<SpectralReading> {
    let f = &l.fields;
    let want = KEYS.len() + names.len();
    if f.len() != want {
        return Err(l.error(format!(
            "expected {want} fields (month,day,hour,sensor and {} channels), found {}",
            names.len(),
            f.len()
        )));
    }
    let (month, day, hour) = (
        l.number(0, "for month")?,
        l.number(1, "for day")?,
        l.number(2, "for hour")?,
    );
    check_stamp(month, day, hour, &|| l.at())?;
    let sensor = f.get(3).copied().unwrap_or("");
    if sensor.is_empty() {
        return Err(l.error("empty sensor id"));
    }
    let mut values = Vec::with_capacity(names.len());
    for (k, name) in names.iter().enumerate() {
        let v = l.number(KEYS.len() + k, &format!("for channel {name}"))?;
        if v < 0.0 {
            return Err(l.error(format!(
                "negative value {v} for channel {name}; expected a value >= 0"
            )));
        }
        values.push(v);
    }
    Ok(SpectralReading {
        month: month as u32,
        day: day as u32,
        hour,
        sensor: sensor.to_string(),
        values,
        line: l.no,
    })
}

impl SpectralReadings {
    pub fn read_path(path: &str) -> Result<SpectralReadings> {
        SpectralReadings::parse(&csv::read_text(path)?, path)
    }

    /// Parse CSV text named `file`.
    pub fn parse(text: &str, file: &str) -> Result<SpectralReadings> {
        let (head, header_line, readings) = csv::read(
            text,
            file,
            "month,day,hour,sensor,<channels>",
            header,
            |(names, _): &mut (Vec<String>, Vec<f64>), l| row(names, l),
        )?;
        let (names, centres) = head;
        if readings.is_empty() {
            return Err(Error::parse(
                Location::file(file),
                "no readings after the header",
            ));
        }
        Ok(SpectralReadings {
            file: file.to_string(),
            names,
            centres,
            header_line,
            readings,
        })
    }

    /// Match readings to sensors and weather steps (as [`Measurements::bind`], with its
    /// messages); `values[i]` belongs to the `i`-th bound reading.
    pub fn bind(
        &self,
        sensor_ids: &[String],
        steps: &[(u32, u32, f64)],
        weather_name: &str,
    ) -> Result<(Vec<Bound>, Vec<Vec<f64>>)> {
        let m = Measurements {
            file: self.file.clone(),
            readings: self
                .readings
                .iter()
                .map(|r| Reading {
                    month: r.month,
                    day: r.day,
                    hour: r.hour,
                    sensor: r.sensor.clone(),
                    value: r.values.iter().sum(),
                    line: r.line,
                })
                .collect(),
        };
        let b = m.bind(sensor_ids, steps, weather_name)?;
        Ok((b, self.readings.iter().map(|r| r.values.clone()).collect()))
    }
}

/// Write readings in the format [`SpectralReadings::parse`] reads.
pub fn write_csv(
    w: &mut dyn std::io::Write,
    names: &[String],
    readings: &[SpectralReading],
) -> Result<()> {
    let io = |e| Error::io("<spectral measurements>", e);
    writeln!(w, "month,day,hour,sensor,{}", names.join(",")).map_err(io)?;
    for r in readings {
        let v: Vec<String> = r.values.iter().map(|x| format!("{x:.6e}")).collect();
        writeln!(
            w,
            "{},{},{},{},{}",
            r.month,
            r.day,
            r.hour,
            r.sensor,
            v.join(",")
        )
        .map_err(io)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = "month,day,hour,sensor,410nm,435 nm,460\n# c\n\
                        11,13,10.5,a,0.1,0.2,0.3\n11,13,11.5,b,1e-2,0,3\n";

    #[test]
    fn parses_header_and_rows() {
        let s = SpectralReadings::parse(GOOD, "s.csv").unwrap();
        assert_eq!(s.centres, vec![410.0, 435.0, 460.0]);
        assert_eq!(s.readings[1].values, vec![0.01, 0.0, 3.0]);
        assert_eq!(s.readings[1].line, 4);
        let ids = vec!["a".to_string(), "b".to_string()];
        let (b, v) = s
            .bind(&ids, &[(11, 13, 10.5), (11, 13, 11.5)], "w.wea")
            .unwrap();
        assert_eq!((b[1].sensor, b[1].step), (1, 1));
        assert_eq!(v[0], vec![0.1, 0.2, 0.3]);
    }

    #[test]
    fn truncated_prefixes_never_panic() {
        for n in 0..=GOOD.len() {
            let _ = SpectralReadings::parse(&GOOD[..n], "s.csv");
        }
    }

    #[test]
    fn random_bytes_never_panic() {
        // A fixed LCG (Knuth's MMIX constants): reproducible garbage, some of it CSV-like.
        let mut x: u64 = 1;
        let alphabet = b"0123456789.,-enm\n#month,day,hour,sensor, ";
        for len in [0usize, 1, 7, 60, 300] {
            for _ in 0..50 {
                let bytes: Vec<u8> = (0..len)
                    .map(|_| {
                        x = x
                            .wrapping_mul(6364136223846793005)
                            .wrapping_add(1442695040888963407);
                        alphabet[(x >> 33) as usize % alphabet.len()]
                    })
                    .collect();
                let text = String::from_utf8_lossy(&bytes);
                let _ = SpectralReadings::parse(&format!("{GOOD}{text}"), "s.csv");
                let _ = SpectralReadings::parse(&text, "s.csv");
            }
        }
    }
}
