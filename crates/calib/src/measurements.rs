//! # Measurements: long-form CSV of illuminance readings
//!
//! One reading per line, `month,day,hour,sensor,value`: calendar month and day, decimal
//! local standard time (the weather file's convention, e.g. 12.5 for the hour ending 13:00
//! in an EPW), the sensor id (a CSV sensor id, or the 1-based line number of a `.pts` file)
//! and the illuminance in lux. A header line naming the columns is required (case and blanks
//! ignored); blank lines and lines starting with `#` are skipped.
//!
//! ```text
//! month,day,hour,sensor,lux
//! 6,21,12.5,s03,1843.2
//! ```
//!
//! [`Measurements::parse`] checks the syntax (file:line, what was found, what was expected);
//! [`Measurements::bind`] checks every reading against the sensors and the weather's time
//! steps (unknown ids, time stamps not in the weather file, negative or missing values),
//! again with the CSV line.

use crate::csv::{self, shorten};
use crate::error::{Error, Location, Result};

/// The column names the header must give (the last may be `lux` or `value`).
pub const HEADER: [&str; 5] = ["month", "day", "hour", "sensor", "lux"];

/// Largest distance (hours) between a reading's time stamp and a weather step it matches.
pub const TIME_TOLERANCE_H: f64 = 0.01;

/// One reading as written.
#[derive(Debug, Clone, PartialEq)]
pub struct Reading {
    pub month: u32,
    pub day: u32,
    pub hour: f64,
    pub sensor: String,
    /// Illuminance in lux.
    pub value: f64,
    /// 1-based line in the CSV (for messages).
    pub line: usize,
}

/// All readings of a file.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurements {
    pub file: String,
    pub readings: Vec<Reading>,
}

/// A reading matched to a sensor index and a weather step index.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    pub sensor: usize,
    pub step: usize,
    pub value: f64,
}

/// Check a reading's month (1-12), day (1-31) and decimal hour (0-24).
pub(crate) fn check_stamp(
    month: f64,
    day: f64,
    hour: f64,
    at: &dyn Fn() -> Location,
) -> Result<()> {
    if !(1.0..=12.0).contains(&month) || month.fract() != 0.0 {
        return Err(Error::parse(
            at(),
            format!("month {month}: expected 1 to 12"),
        ));
    }
    if !(1.0..=31.0).contains(&day) || day.fract() != 0.0 {
        return Err(Error::parse(at(), format!("day {day}: expected 1 to 31")));
    }
    if !(0.0..=24.0).contains(&hour) {
        return Err(Error::parse(
            at(),
            format!("hour {hour}: expected decimal hours 0 to 24"),
        ));
    }
    Ok(())
}

impl Measurements {
    /// Read a measurement file from disk.
    pub fn read_path(path: &str) -> Result<Measurements> {
        Measurements::parse(&csv::read_text(path)?, path)
    }

    /// Parse CSV text named `file` (for messages).
    pub fn parse(text: &str, file: &str) -> Result<Measurements> {
        let header = |l: &csv::Line| {
            let f = &l.fields;
            let ok = f.len() == 5
                && f.iter().zip(HEADER).enumerate().all(|(k, (a, b))| {
                    a.eq_ignore_ascii_case(b) || (k == 4 && a.eq_ignore_ascii_case("value"))
                });
            if !ok {
                return Err(l.error(format!(
                    "expected the header 'month,day,hour,sensor,lux', found '{}'",
                    shorten(l.text)
                )));
            }
            Ok(())
        };
        let row = |_: &mut (), l: &csv::Line| {
            let f = &l.fields;
            if f.len() != 5 {
                return Err(l.error(format!(
                    "expected 5 fields (month,day,hour,sensor,lux), found {}",
                    f.len()
                )));
            }
            let num = |k: usize| l.number(k, &format!("for {}", HEADER[k]));
            let (month, day, hour, value) = (num(0)?, num(1)?, num(2)?, num(4)?);
            check_stamp(month, day, hour, &|| l.at())?;
            if value < 0.0 {
                return Err(l.error(format!(
                    "negative illuminance {value} lx; expected a value >= 0"
                )));
            }
            if f[3].is_empty() {
                return Err(l.error("empty sensor id"));
            }
            Ok(Reading {
                month: month as u32,
                day: day as u32,
                hour,
                sensor: f[3].to_string(),
                value,
                line: l.no,
            })
        };
        let ((), _, readings) = csv::read(text, file, "month,day,hour,sensor,lux", header, row)?;
        if readings.is_empty() {
            return Err(Error::parse(
                Location::file(file),
                "no readings after the header",
            ));
        }
        Ok(Measurements {
            file: file.to_string(),
            readings,
        })
    }

    /// Match every reading to a sensor (by id) and a weather step (same month and day, hour
    /// within [`TIME_TOLERANCE_H`]). `steps` are (month, day, hour) of the weather file
    /// `weather_name`.
    pub fn bind(
        &self,
        sensor_ids: &[String],
        steps: &[(u32, u32, f64)],
        weather_name: &str,
    ) -> Result<Vec<Bound>> {
        let ids: std::collections::HashMap<&str, usize> = sensor_ids
            .iter()
            .enumerate()
            .map(|(i, s)| (s.as_str(), i))
            .collect();
        let mut seen = std::collections::HashMap::new();
        let mut out = Vec::with_capacity(self.readings.len());
        for r in &self.readings {
            let at = || Location::line(&self.file, r.line);
            let sensor = *ids.get(r.sensor.as_str()).ok_or_else(|| {
                let known: Vec<&str> = sensor_ids.iter().take(5).map(String::as_str).collect();
                Error::parse(
                    at(),
                    format!(
                        "unknown sensor id '{}'; the sensor file has {} ids ({}{})",
                        shorten(&r.sensor),
                        sensor_ids.len(),
                        known.join(", "),
                        if sensor_ids.len() > 5 { ", ..." } else { "" }
                    ),
                )
            })?;
            let step = steps
                .iter()
                .position(|&(m, d, h)| {
                    m == r.month && d == r.day && (h - r.hour).abs() <= TIME_TOLERANCE_H
                })
                .ok_or_else(|| {
                    let same_day: Vec<String> = steps
                        .iter()
                        .filter(|s| s.0 == r.month && s.1 == r.day)
                        .map(|s| format!("{}", s.2))
                        .take(4)
                        .collect();
                    let hint = if same_day.is_empty() {
                        format!("{weather_name} has no steps on {}/{}", r.month, r.day)
                    } else {
                        format!(
                            "{weather_name} has hours {} ... on that day",
                            same_day.join(", ")
                        )
                    };
                    Error::parse(
                        at(),
                        format!(
                            "time {} {} {} is not a time step of the weather file ({hint}); \
                             readings must use the weather file's time stamps",
                            r.month, r.day, r.hour
                        ),
                    )
                })?;
            if let Some(first) = seen.insert((sensor, step), r.line) {
                return Err(Error::parse(
                    at(),
                    format!(
                        "second reading of sensor '{}' at {} {} {} (first on line {first})",
                        r.sensor, r.month, r.day, r.hour
                    ),
                ));
            }
            out.push(Bound {
                sensor,
                step,
                value: r.value,
            });
        }
        Ok(out)
    }
}

/// Write readings as the CSV [`Measurements::parse`] reads.
pub fn write_csv(w: &mut dyn std::io::Write, readings: &[Reading]) -> Result<()> {
    let io = |e| Error::io("<measurements>", e);
    writeln!(w, "month,day,hour,sensor,lux").map_err(io)?;
    for r in readings {
        writeln!(
            w,
            "{},{},{},{},{:.2}",
            r.month, r.day, r.hour, r.sensor, r.value
        )
        .map_err(io)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = "month,day,hour,sensor,lux\n# c\n6,21,12.5,a,100\n6,21,13.5,b,50.5\n";

    #[test]
    fn parses_and_binds() {
        let m = Measurements::parse(GOOD, "m.csv").unwrap();
        assert_eq!(m.readings.len(), 2);
        assert_eq!(m.readings[1].line, 4);
        let ids = vec!["a".to_string(), "b".to_string()];
        let steps = [(6, 21, 12.5), (6, 21, 13.5)];
        let b = m.bind(&ids, &steps, "w.wea").unwrap();
        assert_eq!((b[1].sensor, b[1].step, b[1].value), (1, 1, 50.5));
    }

    #[test]
    fn errors_name_the_line() {
        let cases = [
            (
                "month,day,hour,sensor,lux\n6,21,12.5,a,-3\n",
                "m.csv:2: negative",
            ),
            (
                "month,day,hour,sensor,lux\n6,21,12.5,a,\n",
                "m.csv:2: expected a number for lux, found a missing value",
            ),
            (
                "month,day,hour,sensor,lux\n13,21,12.5,a,1\n",
                "m.csv:2: month 13",
            ),
            ("m,d\n", "m.csv:1: expected the header"),
            (
                "month,day,hour,sensor,lux\n6,21,12.5,a\n",
                "m.csv:2: expected 5 fields",
            ),
        ];
        for (text, want) in cases {
            let e = Measurements::parse(text, "m.csv").unwrap_err().to_string();
            assert!(e.starts_with(want), "{e}");
        }
        let m = Measurements::parse(
            "month,day,hour,sensor,lux\n6,21,12.5,zz,1\n6,21,9,a,1\n",
            "m.csv",
        )
        .unwrap();
        let ids = vec!["a".to_string()];
        let e = m
            .bind(&ids, &[(6, 21, 12.5)], "w.wea")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("m.csv:2: unknown sensor id 'zz'"), "{e}");
        let m = Measurements::parse("month,day,hour,sensor,lux\n6,21,9,a,1\n", "m.csv").unwrap();
        let e = m
            .bind(&ids, &[(6, 21, 12.5)], "w.wea")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("m.csv:2: time 6 21 9 is not a time step"),
            "{e}"
        );
    }

    #[test]
    fn truncated_prefixes_never_panic() {
        for n in 0..GOOD.len() {
            let _ = Measurements::parse(&GOOD[..n], "m.csv");
        }
    }
}
