//! # Measurements: the readings CSV (long or wide layout)
//!
//! Illuminance readings with their time stamps: calendar month and day, decimal local
//! standard time (the weather file's convention, e.g. 12.5 for the hour ending 13:00 in an
//! EPW), the sensor id (a CSV sensor id, or the 1-based line number of a `.pts` file) and
//! the illuminance. A header line naming the columns is required; blank lines and lines
//! starting with `#` are skipped. Two layouts, told apart by the header:
//!
//! ```text
//! long: one reading per row               wide: one row per time step, one column per sensor
//! month,day,hour,sensor,lux               month,day,hour,s01,s02,s03
//! 6,21,12.5,s03,1843.2                    6,21,12.5,2210.4,1843.2,960.0
//! ```
//!
//! Column names are matched ignoring case, quotes, blanks and the brackets of a unit
//! (`Illuminance (lx)` reads as `illuminance_lx`), in any order:
//!
//! - time: `month`, `day`, `hour`;
//! - sensor (long layout): `sensor`, `sensor_id`, `id`;
//! - illuminance (long layout): `lux`, `lx`, `illuminance`, `illuminance_lx`, `E`, `value`
//!   in lux; a name ending in `klx` (`klx`, `illuminance_klx`, `E_klx`) is in kilolux and
//!   one ending in `fc` (`fc`, `illuminance_fc`, `E_fc`) in foot-candles
//!   (1 fc = 1 lm/ft2 = 10.7639 lx), converted to lux on reading.
//!
//! A header with the three time columns and neither a sensor nor an illuminance column is
//! the wide layout: every other column is a sensor id (as written), values in lux, and an
//! empty cell means that sensor has no reading at that step (loggers leave gaps). In the
//! long layout every cell is required and other columns are refused, so that a misnamed
//! column cannot be silently ignored. Anything else is mapped with `--columns`
//! ([`Columns`]): `role=name` pairs, e.g. `sensor=Channel,klx=Reading` (the illuminance
//! role names its unit: `lux`, `klx` or `fc`), or `fc=*` for a wide file in foot-candles;
//! with `--columns`, unmapped columns of a long file are ignored.
//!
//! [`Measurements::parse`] checks the syntax (file:line, what was found, what was expected);
//! [`Measurements::bind`] checks every reading against the sensors and the weather's time
//! steps (unknown ids, time stamps not in the weather file, negative or missing values),
//! again with the CSV line.

use crate::csv::{self, shorten};
use crate::error::{Error, Location, Result};

/// The long layout's canonical header (what [`write_csv`] writes).
pub const HEADER: [&str; 5] = ["month", "day", "hour", "sensor", "lux"];

/// Accepted names of the sensor column (normalised, see [`normalise`]).
pub const SENSOR_NAMES: [&str; 3] = ["sensor", "sensor_id", "id"];

/// Accepted names of the illuminance column in lux (normalised); names ending in `klx` or
/// `fc` are in those units (see [`Unit::of_name`]).
pub const LUX_NAMES: [&str; 9] = [
    "lux",
    "lx",
    "illuminance",
    "illuminance_lx",
    "illuminance_lux",
    "e",
    "e_lx",
    "e_lux",
    "value",
];

/// Lux per foot-candle: 1 fc = 1 lm/ft2, 1 ft = 0.3048 m exactly, 1 / 0.3048^2.
pub const LUX_PER_FC: f64 = 1.0 / (0.3048 * 0.3048);

/// Largest distance (hours) between a reading's time stamp and a weather step it matches.
pub const TIME_TOLERANCE_H: f64 = 0.01;

/// What the accepted headers are, for messages.
const ACCEPTED: &str = "expected month,day,hour with a sensor column (sensor, sensor_id, id) \
     and an illuminance column (lux, lx, illuminance, illuminance_lx, E; in klx or fc when \
     the name says so: illuminance_klx, E_fc), or month,day,hour and one column per sensor; \
     map other names with --columns, e.g. --columns sensor=Channel,lux=Reading";

/// Unit of an illuminance column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Unit {
    #[default]
    Lux,
    Kilolux,
    FootCandle,
}

impl Unit {
    /// Lux per unit.
    pub fn to_lux(self) -> f64 {
        match self {
            Unit::Lux => 1.0,
            Unit::Kilolux => 1000.0,
            Unit::FootCandle => LUX_PER_FC,
        }
    }

    /// The unit a (normalised) column name gives, if it names an illuminance column.
    pub fn of_name(name: &str) -> Option<Unit> {
        if LUX_NAMES.contains(&name) {
            return Some(Unit::Lux);
        }
        let base = |suffix: &str| {
            name.strip_suffix(suffix)
                .map(|b| b.trim_end_matches('_'))
                .is_some_and(|b| b.is_empty() || b == "illuminance" || b == "e")
        };
        if base("klx") || base("klux") {
            Some(Unit::Kilolux)
        } else if base("fc") {
            Some(Unit::FootCandle)
        } else {
            None
        }
    }

    /// The unit of a `--columns` role (`lux`, `klx`, `fc`).
    fn of_role(role: &str) -> Option<Unit> {
        match role {
            "lux" | "lx" => Some(Unit::Lux),
            "klx" | "klux" => Some(Unit::Kilolux),
            "fc" => Some(Unit::FootCandle),
            _ => None,
        }
    }
}

/// A header name as matched: lower case, without quotes, blanks, `-` and unit brackets
/// turned into single `_`, none at the ends (`"Illuminance (lx)"` -> `illuminance_lx`).
pub fn normalise(name: &str) -> String {
    let mut out = String::new();
    for c in name.trim().trim_matches('"').trim_matches('\'').chars() {
        if c.is_whitespace() || matches!(c, '_' | '-' | '(' | ')' | '[' | ']') {
            if !out.is_empty() && !out.ends_with('_') {
                out.push('_');
            }
        } else {
            out.extend(c.to_lowercase());
        }
    }
    out.trim_end_matches('_').to_string()
}

/// `--columns`: header names for some roles (the rest are recognised by name).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Columns {
    pub month: Option<String>,
    pub day: Option<String>,
    pub hour: Option<String>,
    pub sensor: Option<String>,
    /// The illuminance column and its unit; `*` as the name: wide layout in that unit.
    pub value: Option<(String, Unit)>,
}

impl Columns {
    /// Parse `role=name,...` (roles month, day, hour, sensor, and lux, klx or fc for the
    /// illuminance column; `lux=*` etc.: every other column is a sensor). Errors are
    /// one line naming `--columns`.
    pub fn parse(spec: &str) -> Result<Columns> {
        let mut c = Columns::default();
        for pair in spec.split(',').map(str::trim).filter(|p| !p.is_empty()) {
            let Some((role, name)) = pair.split_once('=') else {
                return Err(Error::Usage(format!(
                    "--columns: expected role=name, found '{}' (e.g. --columns \
                     sensor=Channel,klx=Reading)",
                    shorten(pair)
                )));
            };
            let (role, name) = (role.trim().to_ascii_lowercase(), name.trim().to_string());
            if name.is_empty() {
                return Err(Error::Usage(format!(
                    "--columns: '{role}=' names no column"
                )));
            }
            let slot = match role.as_str() {
                "month" => &mut c.month,
                "day" => &mut c.day,
                "hour" => &mut c.hour,
                "sensor" => &mut c.sensor,
                r => match Unit::of_role(r) {
                    Some(u) if c.value.is_none() => {
                        c.value = Some((name, u));
                        continue;
                    }
                    Some(_) => {
                        return Err(Error::Usage(
                            "--columns: more than one illuminance column (lux, klx or fc)".into(),
                        ));
                    }
                    None => {
                        return Err(Error::Usage(format!(
                            "--columns: unknown role '{}'; expected month, day, hour, sensor, \
                             and lux, klx or fc for the illuminance column",
                            shorten(r)
                        )));
                    }
                },
            };
            if slot.replace(name).is_some() {
                return Err(Error::Usage(format!("--columns: '{role}' given twice")));
            }
        }
        if c.sensor.is_some() && c.value.as_ref().is_some_and(|v| v.0 == "*") {
            return Err(Error::Usage(
                "--columns: a wide layout (illuminance '*') has no sensor column".into(),
            ));
        }
        Ok(c)
    }

    fn given(&self) -> bool {
        *self != Columns::default()
    }
}

/// Where each value of a row is.
#[derive(Debug, Clone)]
enum Layout {
    Long {
        sensor: usize,
        value: usize,
        unit: Unit,
    },
    /// Sensor ids and their columns.
    Wide {
        sensors: Vec<(usize, String)>,
        unit: Unit,
    },
}

#[derive(Debug, Clone)]
struct Header {
    /// Fields of the header line: every row has as many.
    nfields: usize,
    month: usize,
    day: usize,
    hour: usize,
    layout: Layout,
}

impl Header {
    /// Resolve the header line with `cols`' names first, then the accepted spellings.
    fn resolve(l: &csv::Line, cols: &Columns) -> Result<Header> {
        let names: Vec<String> = l.fields.iter().map(|f| normalise(f)).collect();
        let found = || format!("found '{}'", shorten(l.text));
        let mut used = vec![false; names.len()];
        // A column named by --columns (exact name, ignoring case/quotes/blanks), or the
        // first column whose normalised name passes `accept`.
        let mut find = |given: &Option<String>,
                        role: &str,
                        accept: &dyn Fn(&str) -> bool|
         -> Result<Option<usize>> {
            let hit = match given {
                Some(g) => {
                    let g = normalise(g);
                    let k = names.iter().position(|n| *n == g).ok_or_else(|| {
                        l.error(format!(
                            "--columns {role}={}: no such column; {}",
                            shorten(&g),
                            found()
                        ))
                    })?;
                    Some(k)
                }
                None => names
                    .iter()
                    .enumerate()
                    .position(|(k, n)| !used[k] && accept(n)),
            };
            if let Some(k) = hit {
                used[k] = true;
            }
            Ok(hit)
        };
        let month = find(&cols.month, "month", &|n| n == "month")?;
        let day = find(&cols.day, "day", &|n| n == "day")?;
        let hour = find(&cols.hour, "hour", &|n| n == "hour")?;
        let wide_unit = match &cols.value {
            Some((n, u)) if n == "*" => Some(*u),
            _ => None,
        };
        let (sensor, value) = if wide_unit.is_some() {
            (None, None)
        } else {
            let sensor = find(&cols.sensor, "sensor", &|n| SENSOR_NAMES.contains(&n))?;
            let vname = cols.value.as_ref().map(|v| v.0.clone());
            let value = find(&vname, "lux", &|n| Unit::of_name(n).is_some())?;
            (sensor, value)
        };
        let (Some(month), Some(day), Some(hour)) = (month, day, hour) else {
            return Err(l.error(format!(
                "no month, day and hour columns in the readings header; {ACCEPTED}; {}",
                found()
            )));
        };
        let layout = match (sensor, value) {
            (Some(sensor), Some(value)) => {
                let unit = match &cols.value {
                    Some((_, u)) => *u,
                    None => Unit::of_name(&names[value]).unwrap_or_default(),
                };
                let others: Vec<&str> = l
                    .fields
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| !used[*k])
                    .map(|(_, f)| *f)
                    .collect();
                if !others.is_empty() && !cols.given() {
                    return Err(l.error(format!(
                        "unexpected column '{}' in a one-reading-per-row header; {ACCEPTED}; {}",
                        shorten(others[0]),
                        found()
                    )));
                }
                Layout::Long {
                    sensor,
                    value,
                    unit,
                }
            }
            (None, None) => {
                let sensors: Vec<(usize, String)> = l
                    .fields
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| !used[*k])
                    .map(|(k, f)| (k, f.trim_matches('"').trim().to_string()))
                    .collect();
                if sensors.is_empty() {
                    return Err(l.error(format!(
                        "no sensor or illuminance column in the readings header; {ACCEPTED}; {}",
                        found()
                    )));
                }
                if let Some((_, id)) = sensors.iter().find(|(_, id)| id.is_empty()) {
                    return Err(l.error(format!(
                        "empty sensor id '{id}' in a one-column-per-sensor header; name every \
                         column"
                    )));
                }
                for (i, (_, a)) in sensors.iter().enumerate() {
                    if sensors[..i].iter().any(|(_, b)| b == a) {
                        return Err(l.error(format!(
                            "sensor column '{}' appears twice in the header",
                            shorten(a)
                        )));
                    }
                }
                Layout::Wide {
                    sensors,
                    unit: wide_unit.unwrap_or_default(),
                }
            }
            (Some(s), None) => {
                return Err(l.error(format!(
                    "sensor column '{}' but no illuminance column; {ACCEPTED}; {}",
                    shorten(l.fields[s]),
                    found()
                )));
            }
            (None, Some(v)) => {
                return Err(l.error(format!(
                    "illuminance column '{}' but no sensor column; {ACCEPTED}; {}",
                    shorten(l.fields[v]),
                    found()
                )));
            }
        };
        Ok(Header {
            nfields: l.fields.len(),
            month,
            day,
            hour,
            layout,
        })
    }
}

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
    /// Read a measurement file from disk (columns recognised by name).
    pub fn read_path(path: &str) -> Result<Measurements> {
        Measurements::read_path_with(path, &Columns::default())
    }

    /// Read a measurement file with `--columns` names.
    pub fn read_path_with(path: &str, cols: &Columns) -> Result<Measurements> {
        Measurements::parse_with(&csv::read_text(path)?, path, cols)
    }

    /// Parse CSV text named `file` (for messages), columns recognised by name.
    pub fn parse(text: &str, file: &str) -> Result<Measurements> {
        Measurements::parse_with(text, file, &Columns::default())
    }

    /// Parse CSV text with `--columns` names (see the module doc for both layouts).
    pub fn parse_with(text: &str, file: &str, cols: &Columns) -> Result<Measurements> {
        let header = |l: &csv::Line| Header::resolve(l, cols);
        let row = |h: &mut Header, l: &csv::Line| -> Result<Vec<Reading>> {
            let f = &l.fields;
            if f.len() != h.nfields {
                return Err(l.error(format!(
                    "expected {} fields (one per header column), found {}",
                    h.nfields,
                    f.len()
                )));
            }
            let month = l.number(h.month, "for month")?;
            let day = l.number(h.day, "for day")?;
            let hour = l.number(h.hour, "for hour")?;
            check_stamp(month, day, hour, &|| l.at())?;
            let reading = |sensor: &str, k: usize, unit: Unit, what: &str| -> Result<Reading> {
                let v = l.number(k, what)?;
                if v < 0.0 {
                    return Err(l.error(format!(
                        "negative illuminance {v} {what}; expected a value >= 0"
                    )));
                }
                Ok(Reading {
                    month: month as u32,
                    day: day as u32,
                    hour,
                    sensor: sensor.to_string(),
                    value: v * unit.to_lux(),
                    line: l.no,
                })
            };
            match &h.layout {
                Layout::Long {
                    sensor,
                    value,
                    unit,
                    ..
                } => {
                    let id = f[*sensor].trim_matches('"').trim();
                    if id.is_empty() {
                        return Err(l.error("empty sensor id"));
                    }
                    Ok(vec![reading(id, *value, *unit, "for lux")?])
                }
                Layout::Wide { sensors, unit } => sensors
                    .iter()
                    .filter(|(k, _)| !f[*k].is_empty())
                    .map(|(k, id)| reading(id, *k, *unit, &format!("for sensor '{id}'")))
                    .collect(),
            }
        };
        let (_, _, rows) = csv::read(text, file, "month,day,hour,sensor,lux", header, row)?;
        let readings: Vec<Reading> = rows.into_iter().flatten().collect();
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
            ("m,d\n", "m.csv:1: no month, day and hour columns"),
            (
                "month,day,hour,sensor,lux\n6,21,12.5,a\n",
                "m.csv:2: expected 5 fields (one per header column), found 4",
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

    /// Readings of the same two sensors and steps in every accepted spelling and layout.
    fn values(text: &str, cols: &Columns) -> Vec<(String, f64, f64)> {
        let m = Measurements::parse_with(text, "m.csv", cols).unwrap_or_else(|e| panic!("{e}"));
        m.readings
            .iter()
            .map(|r| (r.sensor.clone(), r.hour, r.value))
            .collect()
    }

    fn expected(scale: f64) -> Vec<(String, f64, f64)> {
        vec![
            ("a".into(), 12.5, 100.0 * scale),
            ("b".into(), 12.5, 50.5 * scale),
            ("a".into(), 13.5, 80.0 * scale),
        ]
    }

    #[test]
    fn long_layout_spellings_and_units() {
        let rows = "6,21,12.5,a,100\n6,21,12.5,b,50.5\n6,21,13.5,a,80\n";
        let none = Columns::default();
        for sensor in [
            "sensor",
            "sensor_id",
            "id",
            "Sensor ID",
            "\"sensor_id\"",
            "SENSOR-ID",
        ] {
            for value in [
                "lux",
                "lx",
                "illuminance",
                "illuminance_lx",
                "E",
                "value",
                "Illuminance (lx)",
                "E [lux]",
            ] {
                let text = format!("month,day,hour,{sensor},{value}\n{rows}");
                assert_eq!(values(&text, &none), expected(1.0), "{sensor},{value}");
            }
        }
        for (value, scale) in [
            ("klx", 1000.0),
            ("illuminance_klx", 1000.0),
            ("E_klx", 1000.0),
            ("Illuminance [klux]", 1000.0),
            ("fc", LUX_PER_FC),
            ("E_fc", LUX_PER_FC),
            ("illuminance_fc", LUX_PER_FC),
        ] {
            let text = format!("month,day,hour,sensor_id,{value}\n{rows}");
            let got = values(&text, &none);
            for (g, w) in got.iter().zip(expected(scale)) {
                assert_eq!((&g.0, g.1), (&w.0, w.1), "{value}");
                assert!(
                    (g.2 - w.2).abs() < 1e-9 * w.2,
                    "{value}: {} vs {}",
                    g.2,
                    w.2
                );
            }
        }
        // 1 fc is 10.7639 lx (1 lm/ft2).
        assert!((LUX_PER_FC - 10.763_910_4).abs() < 1e-6);
        // Columns in another order, the logger export of issue 22 among them.
        let text = "sensor_id,illuminance_lx,hour,day,month\na,100,12.5,21,6\nb,50.5,12.5,21,6\n\
                    a,80,13.5,21,6\n";
        assert_eq!(values(text, &none), expected(1.0));
    }

    #[test]
    fn wide_layout_one_column_per_sensor() {
        let text = "month,day,hour,a,b\n6,21,12.5,100,50.5\n6,21,13.5,80,\n";
        assert_eq!(values(text, &Columns::default()), expected(1.0));
        // Quoted ids keep their case; lines name the row in later errors.
        let m =
            Measurements::parse("Month,Day,Hour,\"S01\",s02\n6,21,12.5,1,2\n", "m.csv").unwrap();
        assert_eq!(m.readings[0].sensor, "S01");
        assert_eq!(m.readings[1].line, 2);
        // A wide file in klx by --columns.
        let cols = Columns::parse("klx=*").unwrap();
        let got = values(
            "month,day,hour,a,b\n6,21,12.5,0.1,0.0505\n6,21,13.5,0.08,\n",
            &cols,
        );
        for (g, w) in got.iter().zip(expected(1.0)) {
            assert!((g.2 - w.2).abs() < 1e-9, "{g:?} {w:?}");
        }
        let e = Measurements::parse("month,day,hour,a,b\n6,21,12.5,1,x\n", "m.csv")
            .unwrap_err()
            .to_string();
        assert_eq!(e, "m.csv:2: expected a number for sensor 'b', found 'x'");
        let e = Measurements::parse("month,day,hour,a,a\n6,21,12.5,1,2\n", "m.csv")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("m.csv:1: sensor column 'a' appears twice"),
            "{e}"
        );
    }

    #[test]
    fn columns_map_other_names() {
        let text = "Mon,Tag,Zeit,Kanal,Wert,Temp\n6,21,12.5,a,0.1,20\n6,21,12.5,b,0.0505,20\n\
                    6,21,13.5,a,0.08,21\n";
        let cols = Columns::parse("month=Mon, day=Tag, hour=Zeit, sensor=Kanal, klx=Wert").unwrap();
        let got = values(text, &cols);
        for (g, w) in got.iter().zip(expected(1.0)) {
            assert_eq!(&g.0, &w.0);
            assert!((g.2 - w.2).abs() < 1e-9, "{g:?} {w:?}");
        }
        // Only some roles mapped: the others are recognised by name.
        let text =
            "month,day,hour,Channel,lux\n6,21,12.5,a,100\n6,21,12.5,b,50.5\n6,21,13.5,a,80\n";
        assert_eq!(
            values(text, &Columns::parse("sensor=Channel").unwrap()),
            expected(1.0)
        );
        for (spec, want) in [
            ("sensor", "--columns: expected role=name, found 'sensor'"),
            ("colour=x", "--columns: unknown role 'colour'"),
            ("lux=a,klx=b", "--columns: more than one illuminance column"),
            ("sensor=a,sensor=b", "--columns: 'sensor' given twice"),
            ("sensor=a,lux=*", "--columns: a wide layout"),
        ] {
            let e = Columns::parse(spec).unwrap_err().to_string();
            assert!(e.contains(want), "{spec}: {e}");
        }
        let e = Measurements::parse_with(
            "month,day,hour,sensor,lux\n6,21,12.5,a,1\n",
            "m.csv",
            &Columns::parse("sensor=Kanal").unwrap(),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("m.csv:1: --columns sensor=kanal: no such column"),
            "{e}"
        );
    }

    #[test]
    fn refused_headers_name_what_was_found_and_the_accepted_names() {
        for (text, want) in [
            (
                "month,day,hour,sensor_id\n6,21,12.5,a\n",
                "m.csv:1: sensor column 'sensor_id' but no illuminance column; expected \
                 month,day,hour with a sensor column (sensor, sensor_id, id) and an \
                 illuminance column (lux, lx, illuminance, illuminance_lx, E;",
            ),
            (
                "month,day,hour,reading,lux\n6,21,12.5,a,1\n",
                "m.csv:1: illuminance column 'lux' but no sensor column",
            ),
            (
                "month,day,hour,sensor,lux,temp\n6,21,12.5,a,1,20\n",
                "m.csv:1: unexpected column 'temp' in a one-reading-per-row header",
            ),
            (
                "sensor_id,illuminance_lx\na,1\n",
                "m.csv:1: no month, day and hour columns",
            ),
            (
                "month,day,hour\n6,21,12.5\n",
                "m.csv:1: no sensor or illuminance column",
            ),
        ] {
            let e = Measurements::parse(text, "m.csv").unwrap_err().to_string();
            assert!(e.starts_with(want), "{e}");
            assert!(e.contains("--columns"), "{e}");
            assert!(!e.contains('\n'), "one line: {e}");
        }
    }

    #[test]
    fn truncated_prefixes_never_panic() {
        let wide = "month,day,hour,a,\"b\"\n6,21,12.5,100,50.5\n6,21,13.5,80,\n";
        for text in [GOOD, wide] {
            for n in 0..text.len() {
                let _ = Measurements::parse(&text[..n], "m.csv");
            }
        }
    }
}
