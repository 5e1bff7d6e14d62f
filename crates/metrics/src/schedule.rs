//! Time stamps of the illuminance matrix's columns and the occupancy schedule over them.
//!
//! An illuminance matrix (`dctimestep dc.mtx sky.smx | rmtxop -c 47.4 119.9 11.6 -`) has one
//! column per time step of the sky matrix, and `gendaymtx` writes one column per step of the
//! weather file it read (night steps included, unless `-u` was given). So the column stamps
//! come from the same weather file ([`stamps_from_weather`]), and we **require the same
//! count**: a sky made with `gendaymtx -u` (night steps dropped) cannot be matched to its
//! weather file without repeating gendaymtx's sun-up test, so such a matrix must come with
//! an explicit `--hours` list ([`parse_hours`], one `month day hour` line per column).
//!
//! Occupancy ([`Schedule`]): a step with decimal local standard time `h` is occupied when
//! `start <= h < end` (default 8 and 18). Weather stamps are mid-interval (`.wea` and
//! Radiance's EPW loader put the 08:00-09:00 hour at 8.5), so the default counts the ten
//! hourly steps 8.5, 9.5, ..., 17.5: the hours 08:00-18:00 of the LEED/IES LM-83 schedule.
//! (The seed's chapter 2 uses 9:00-17:00 for TAI, Appendix A 8:00-17:00 for RMSE: pass
//! `--occupied 9-17` or `8-17` to reproduce those.) Optionally only weekdays (Monday to
//! Friday) count; weather files give month and day but no reliable weekday (typical-year EPW
//! rows mix years), so the weekday comes from the weekday of 1 January or, for an EPW, from
//! its DATA PERIODS record ([`Weekdays`]). Or a file gives one 0/1 flag per column
//! ([`parse_flags`]).
//!
//! Sub-hourly EPW steps carry Radiance's stamp `h - 1 + minute/60`, the *end* of each
//! interval (08:00 for 07:45-08:00), so with 15-minute data the half-open range counts the
//! intervals ending at 8.00 ... 17.75; shift `--occupied` by one step if that matters.
//!
//! Step length: the smallest positive gap between consecutive stamps of one day, capped at
//! one hour (hourly files: 1 h; 15-minute EPW: 0.25 h); a lone step per day counts 1 h.
//! Sums over time (TAI) and hour counts (ASE) are weighted by it.

use crate::error::{Error, Location, Result};
use crate::formats::weather::{Weather, WeatherFormat, detect, epw::Epw};
use nom::{
    IResult, Parser,
    character::complete::{digit1, space0, space1},
    number::complete::double,
};

/// When one column of the matrix was simulated: month, day, decimal local standard time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stamp {
    pub month: u8,
    pub day: u8,
    pub hour: f64,
}

/// One stamp per weather step, in file order (the column order of `gendaymtx` without `-u`).
pub fn stamps_from_weather(w: &Weather) -> Vec<Stamp> {
    w.steps
        .iter()
        .map(|s| Stamp {
            month: s.month,
            day: s.day,
            hour: s.hour,
        })
        .collect()
}

fn hours_line(input: &str) -> IResult<&str, (u8, u8, f64)> {
    let (rest, (_, m, _, d, _, h)) =
        (space0, digit1, space1, digit1, space1, double).parse(input)?;
    let (Ok(m), Ok(d)) = (m.parse::<u8>(), d.parse::<u8>()) else {
        return Err(nom::Err::Error(nom::error::Error::new(
            input,
            nom::error::ErrorKind::Digit,
        )));
    };
    Ok((rest, (m, d, h)))
}

/// Parse a `--hours` file: one `month day hour` line per matrix column (a `.wea` body
/// without its header works too: extra columns after the hour are ignored). Blank lines and
/// `#` comments are skipped.
pub fn parse_hours(text: &str, file: &str) -> Result<Vec<Stamp>> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let loc = || Location::line(file, i + 1);
        let (rest, (month, day, hour)) = hours_line(t).map_err(|_| {
            Error::parse(
                loc(),
                format!("expected 'month day hour' (e.g. '3 21 12.5'), found '{t}'"),
            )
        })?;
        if !rest.is_empty() && !rest.starts_with(|c: char| c.is_ascii_whitespace()) {
            return Err(Error::parse(
                loc(),
                format!("expected white space after the hour, found '{rest}'"),
            ));
        }
        if !(1..=12).contains(&month) || day == 0 || day > 31 || !(0.0..=24.0).contains(&hour) {
            return Err(Error::parse(
                loc(),
                format!("month {month} day {day} hour {hour} out of range (1-12, 1-31, 0-24)"),
            ));
        }
        out.push(Stamp { month, day, hour });
    }
    Ok(out)
}

/// Parse a schedule file of occupancy flags: one `0` or `1` per matrix column, one per line
/// (blank lines and `#` comments skipped).
pub fn parse_flags(text: &str, file: &str) -> Result<Vec<bool>> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        match t {
            "0" => out.push(false),
            "1" => out.push(true),
            _ => {
                return Err(Error::parse(
                    Location::line(file, i + 1),
                    format!("expected an occupancy flag 0 or 1, found '{t}'"),
                ));
            }
        }
    }
    Ok(out)
}

/// Parse `--occupied START-END` (decimal hours, `0 <= START < END <= 24`).
pub fn parse_range(s: &str) -> Result<(f64, f64)> {
    let bad = || {
        Error::Usage(format!(
            "--occupied: expected START-END in decimal hours such as 8-18, found '{s}'"
        ))
    };
    let (a, b) = s.split_once('-').ok_or_else(bad)?;
    let a: f64 = a.trim().parse().map_err(|_| bad())?;
    let b: f64 = b.trim().parse().map_err(|_| bad())?;
    if !((0.0..24.0).contains(&a) && a < b && b <= 24.0) {
        return Err(bad());
    }
    Ok((a, b))
}

/// Where the weekday of a stamp comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weekdays {
    /// Weekday of 1 January, 0 = Monday ... 6 = Sunday.
    pub jan1: u8,
    /// Whether the year has 29 February (shifts every later date by one day).
    pub leap: bool,
}

const DAY_NAMES: [&str; 7] = [
    "monday",
    "tuesday",
    "wednesday",
    "thursday",
    "friday",
    "saturday",
    "sunday",
];

/// Weekday number (0 = Monday) from a name or its first three letters or more.
pub fn weekday_from_name(s: &str) -> Option<u8> {
    let s = s.trim().to_ascii_lowercase();
    if s.len() < 3 {
        return None;
    }
    DAY_NAMES
        .iter()
        .position(|d| d.starts_with(&s))
        .map(|i| i as u8)
}

/// Day of the year, 0-based, 29 February counted in leap years
/// (`rdaylight_base::calendar::day_index`).
pub fn day_of_year(month: u8, day: u8, leap: bool) -> u32 {
    rdaylight_base::calendar::day_index(month.into(), day.into(), leap)
}

impl Weekdays {
    /// From an EPW's DATA PERIODS record: its start weekday and start date fix the weekday
    /// of every date (the year column is not used: typical years mix years).
    pub fn from_epw_text(text: &str, file: &str) -> Result<Option<Weekdays>> {
        if detect(text) != Some(WeatherFormat::Epw) {
            return Ok(None);
        }
        let epw = Epw::parse(text, file)?;
        let leap = epw.records.iter().any(|r| r.month == 2 && r.day == 29);
        let Some(p) = epw.header.periods.first() else {
            return Ok(None);
        };
        let Some(wd) = weekday_from_name(&p.start_weekday) else {
            return Err(Error::parse(
                Location::line(file, 8),
                format!(
                    "DATA PERIODS start weekday '{}' is not a day name; give --jan1",
                    p.start_weekday
                ),
            ));
        };
        let start = day_of_year(p.start.month, p.start.day, leap);
        let jan1 = ((i64::from(wd) - i64::from(start)).rem_euclid(7)) as u8;
        Ok(Some(Weekdays { jan1, leap }))
    }

    /// 0 = Monday ... 6 = Sunday.
    pub fn weekday(&self, month: u8, day: u8) -> u8 {
        ((u32::from(self.jan1) + day_of_year(month, day, self.leap)) % 7) as u8
    }
}

/// Which columns are occupied, and how long each step lasts.
#[derive(Debug, Clone, PartialEq)]
pub struct Schedule {
    /// One flag per matrix column.
    pub occupied: Vec<bool>,
    /// Length of one step in hours.
    pub step_hours: f64,
    /// What rule made the flags, for headers and logs.
    pub rule: String,
}

/// Step length in hours from the stamps (see the module documentation).
pub fn step_hours(stamps: &[Stamp]) -> f64 {
    let mut best = 1.0f64;
    for w in stamps.windows(2) {
        if w[0].month == w[1].month && w[0].day == w[1].day {
            let d = w[1].hour - w[0].hour;
            if d > 1e-9 && d < best {
                best = d;
            }
        }
    }
    best
}

impl Schedule {
    /// Every column occupied, one hour each (when no time stamps are known).
    pub fn all(ncols: usize) -> Schedule {
        Schedule {
            occupied: vec![true; ncols],
            step_hours: 1.0,
            rule: "every column (no time stamps given), 1 h each".into(),
        }
    }

    /// Occupied when `start <= hour < end`, and, if `weekdays` is given, Monday to Friday.
    pub fn from_range(
        stamps: &[Stamp],
        start: f64,
        end: f64,
        weekdays: Option<Weekdays>,
    ) -> Schedule {
        let occupied = stamps
            .iter()
            .map(|s| {
                let in_day = start <= s.hour && s.hour < end;
                let workday = weekdays.is_none_or(|w| w.weekday(s.month, s.day) < 5);
                in_day && workday
            })
            .collect();
        let step = step_hours(stamps);
        let days = if weekdays.is_some() {
            "Monday to Friday"
        } else {
            "every day"
        };
        Schedule {
            occupied,
            step_hours: step,
            rule: format!("{start} <= hour < {end}, {days}, {step} h steps"),
        }
    }

    /// Explicit flags (from [`parse_flags`]); `step_hours` from the stamps if known.
    pub fn from_flags(flags: Vec<bool>, step_hours: f64, file: &str) -> Schedule {
        Schedule {
            occupied: flags,
            step_hours,
            rule: format!("flags from {file}, {step_hours} h steps"),
        }
    }

    /// Number of occupied steps.
    pub fn count(&self) -> usize {
        self.occupied.iter().filter(|&&o| o).count()
    }

    /// Occupied hours (steps x step length).
    pub fn hours(&self) -> f64 {
        self.count() as f64 * self.step_hours
    }

    /// Check the schedule has one flag per matrix column.
    pub fn check_columns(&self, ncols: usize, matrix: &str, source: &str) -> Result<()> {
        if self.occupied.len() != ncols {
            return Err(Error::Mismatch(format!(
                "{matrix}: {ncols} columns (time steps), but {source} gives {} steps; make the \
                 sky with every weather step (gendaymtx without -u) or give --hours with one \
                 'month day hour' line per column",
                self.occupied.len()
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn day(month: u8, d: u8) -> Vec<Stamp> {
        (0..24)
            .map(|h| Stamp {
                month,
                day: d,
                hour: h as f64 + 0.5,
            })
            .collect()
    }

    #[test]
    fn default_range_counts_ten_mid_hour_steps() {
        let s = Schedule::from_range(&day(3, 21), 8.0, 18.0, None);
        assert_eq!(s.count(), 10);
        assert!(!s.occupied[7] && s.occupied[8] && s.occupied[17] && !s.occupied[18]);
        assert_eq!(s.step_hours, 1.0);
    }

    #[test]
    fn range_boundaries_are_half_open() {
        let st = [8.0, 17.999, 18.0, 7.999].map(|hour| Stamp {
            month: 1,
            day: 1,
            hour,
        });
        let s = Schedule::from_range(&st, 8.0, 18.0, None);
        assert_eq!(s.occupied, vec![true, true, false, false]);
    }

    #[test]
    fn weekdays_from_jan1() {
        // 2024-01-01 was a Monday and 2024 is leap: 21 Mar 2024 was a Thursday, 23 Mar a
        // Saturday.
        let w = Weekdays {
            jan1: 0,
            leap: true,
        };
        assert_eq!(w.weekday(3, 21), 3);
        assert_eq!(w.weekday(3, 23), 5);
        // 2023-01-01 was a Sunday; 21 Jun 2023 a Wednesday.
        let w = Weekdays {
            jan1: 6,
            leap: false,
        };
        assert_eq!(w.weekday(6, 21), 2);
        let mut st = day(6, 24); // Saturday in 2023
        st.extend(day(6, 21));
        let s = Schedule::from_range(&st, 8.0, 18.0, Some(w));
        assert_eq!(s.count(), 10);
        assert!(s.occupied[24 + 8] && !s.occupied[8]);
    }

    #[test]
    fn sub_hourly_steps() {
        let st: Vec<Stamp> = (0..8)
            .map(|i| Stamp {
                month: 1,
                day: 1,
                hour: 8.0 + 0.25 * i as f64,
            })
            .collect();
        assert_eq!(step_hours(&st), 0.25);
        assert_eq!(Schedule::from_range(&st, 8.0, 18.0, None).hours(), 2.0);
    }

    #[test]
    fn hours_file_parses_and_reports_lines() {
        let st = parse_hours("# c\n3 21 12.5\n\n12 21 0.5 0 0\n", "h.txt").unwrap();
        assert_eq!(st.len(), 2);
        assert_eq!(st[1].month, 12);
        let e = parse_hours("3 21 12.5\n3 x 1\n", "h.txt").unwrap_err();
        assert_eq!(
            e.to_string(),
            "h.txt:2: expected 'month day hour' (e.g. '3 21 12.5'), found '3 x 1'"
        );
        let e = parse_hours("13 1 1\n", "h.txt").unwrap_err();
        assert!(e.to_string().starts_with("h.txt:1: month 13"), "{e}");
        let text = "3 21 12.5\n6 21 1.5\n";
        for n in 0..text.len() {
            let _ = parse_hours(&text[..n], "h.txt");
        }
    }

    #[test]
    fn flags_and_ranges() {
        assert_eq!(
            parse_flags("1\n0\n#x\n1\n", "f").unwrap(),
            [true, false, true]
        );
        assert_eq!(
            parse_flags("1\n2\n", "f").unwrap_err().to_string(),
            "f:2: expected an occupancy flag 0 or 1, found '2'"
        );
        let text = "1\n0\n1\n";
        for n in 0..text.len() {
            let _ = parse_flags(&text[..n], "f");
        }
        assert_eq!(parse_range("8-18").unwrap(), (8.0, 18.0));
        assert_eq!(parse_range("8.5-17").unwrap(), (8.5, 17.0));
        assert!(parse_range("18-8").is_err());
        assert!(parse_range("8").is_err());
        assert_eq!(weekday_from_name("Sunday"), Some(6));
        assert_eq!(weekday_from_name("mon"), Some(0));
        assert_eq!(weekday_from_name("mo"), None);
    }

    #[test]
    fn column_count_mismatch_names_the_fix() {
        let s = Schedule::all(3);
        let e = s
            .check_columns(4, "e.mtx", "w.wea")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("e.mtx: 4 columns (time steps), but w.wea gives 3 steps"));
        assert!(e.contains("gendaymtx without -u"));
    }
}

/// Where the time stamps and the occupancy come from (the command-line choices).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ScheduleSpec {
    /// The `.wea`/`.epw` the sky matrix was made from (one column per step).
    pub weather: Option<String>,
    /// A `month day hour` file, one line per column.
    pub hours: Option<String>,
    /// Occupied hours `start <= hour < end`; `None` = 8-18.
    pub occupied: Option<(f64, f64)>,
    /// Only Monday to Friday.
    pub weekdays: bool,
    /// Weekday of 1 January (name), for `weekdays`.
    pub jan1: Option<String>,
    /// A 0/1 flag file, one per column (replaces the range rule).
    pub flags: Option<String>,
    /// Count every column as occupied (no time stamps).
    pub all_steps: bool,
}

fn read_text(path: &str) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    Ok(crate::formats::weather::decode_text(&bytes))
}

impl ScheduleSpec {
    /// Build the schedule for a matrix with `ncols` columns, checking the counts agree.
    /// The columns' time stamps from `--weather` or `--hours` (none without either): what
    /// the temporal map places on its day and hour axes.
    pub fn stamps(&self) -> Result<Option<Vec<Stamp>>> {
        if let Some(w) = &self.weather {
            let text = read_text(w)?;
            Ok(Some(stamps_from_weather(&Weather::parse(&text, w)?)))
        } else if let Some(h) = &self.hours {
            Ok(Some(parse_hours(&read_text(h)?, h)?))
        } else {
            Ok(None)
        }
    }

    pub fn build(&self, ncols: usize, matrix: &str) -> Result<Schedule> {
        if self.weather.is_some() && self.hours.is_some() {
            return Err(Error::Usage(
                "give the time stamps once: --weather or --hours, not both".into(),
            ));
        }
        let mut weekdays = None;
        let stamps = if let Some(w) = &self.weather {
            let text = read_text(w)?;
            if self.weekdays && self.jan1.is_none() {
                weekdays = Weekdays::from_epw_text(&text, w)?;
            }
            let s = stamps_from_weather(&Weather::parse(&text, w)?);
            Some((s, w.as_str()))
        } else if let Some(h) = &self.hours {
            Some((parse_hours(&read_text(h)?, h)?, h.as_str()))
        } else {
            None
        };
        if let Some(f) = &self.flags {
            let flags = parse_flags(&read_text(f)?, f)?;
            let step = stamps.as_ref().map_or(1.0, |(s, _)| step_hours(s));
            let s = Schedule::from_flags(flags, step, f);
            s.check_columns(ncols, matrix, f)?;
            return Ok(s);
        }
        let Some((stamps, source)) = stamps else {
            if self.all_steps {
                return Ok(Schedule::all(ncols));
            }
            return Err(Error::Usage(
                "no time stamps: give --weather FILE (the .wea/.epw the sky matrix was made \
                 from), --hours FILE, --schedule FILE, or --all-steps to count every column"
                    .into(),
            ));
        };
        if self.weekdays {
            if let Some(name) = &self.jan1 {
                let jan1 = weekday_from_name(name).ok_or_else(|| {
                    Error::Usage(format!(
                        "--jan1: expected a day name such as Monday, found '{name}'"
                    ))
                })?;
                let leap = stamps.iter().any(|s| s.month == 2 && s.day == 29);
                weekdays = Some(Weekdays { jan1, leap });
            } else if weekdays.is_none() {
                return Err(Error::Usage(
                    "--weekdays needs the weekday of 1 January (--jan1 DAY): only an EPW's \
                     DATA PERIODS record says which weekday its dates fall on"
                        .into(),
                ));
            }
        }
        let (a, b) = self.occupied.unwrap_or((8.0, 18.0));
        let s = Schedule::from_range(&stamps, a, b, weekdays);
        s.check_columns(ncols, matrix, source)?;
        Ok(s)
    }
}
