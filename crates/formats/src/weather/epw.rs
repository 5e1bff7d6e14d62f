//! The EnergyPlus weather file (EPW), every field kept.
//!
//! Layout (EnergyPlus Auxiliary Programs, "EnergyPlus Weather File (EPW) Data Dictionary";
//! Radiance reads the same records in `src/gen/loadEPW.c`):
//! ```text
//! 1 LOCATION,city,state,country,source,WMO,latitude (N+),longitude (E+),time zone (h, E+),elevation (m)
//! 2 DESIGN CONDITIONS,...
//! 3 TYPICAL/EXTREME PERIODS,...
//! 4 GROUND TEMPERATURES,...
//! 5 HOLIDAYS/DAYLIGHT SAVINGS,...
//! 6 COMMENTS 1,...
//! 7 COMMENTS 2,...
//! 8 DATA PERIODS,<n periods>,<records per hour>,<name>,<start weekday>,<start m/d>,<end m/d>[,...]
//! 9.. year,month,day,hour (1-24, ends the interval),minute,flags,<29 more fields, see EpwField>
//! ```
//! Records 2..=7 are kept as text (daylighting does not use them); Radiance checks their
//! keywords in this order and so do we. Data rows have 35 fields; the last three (albedo and
//! liquid precipitation) may be absent, as `loadEPW.c` allows (32 is the minimum).
//!
//! Missing data: each numeric field has a code; a value at or above it means "missing"
//! (the dictionary's `\missing` rule). [`EpwRecord::get`] applies it, [`EpwRecord::raw`]
//! does not, and [`Epw::missing_counts`] reports them per field. An empty field is missing
//! too (`loadEPW.c` leaves its default in place).

use super::{check_date, check_solar_value, integer, number, numbered_lines, shorten};
use crate::error::{Error, Location, Result};
use nom::{
    IResult, Parser, bytes::complete::take_while, character::complete::char, multi::separated_list1,
};

/// A numeric EPW data field (1-based field numbers of the data dictionary).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum EpwField {
    DryBulbTemperature,
    DewPointTemperature,
    RelativeHumidity,
    AtmosphericPressure,
    ExtraterrestrialHorizontalRadiation,
    ExtraterrestrialDirectNormalRadiation,
    HorizontalInfraredRadiation,
    GlobalHorizontalRadiation,
    DirectNormalRadiation,
    DiffuseHorizontalRadiation,
    GlobalHorizontalIlluminance,
    DirectNormalIlluminance,
    DiffuseHorizontalIlluminance,
    ZenithLuminance,
    WindDirection,
    WindSpeed,
    TotalSkyCover,
    OpaqueSkyCover,
    Visibility,
    CeilingHeight,
    PresentWeatherObservation,
    PrecipitableWater,
    AerosolOpticalDepth,
    SnowDepth,
    DaysSinceLastSnowfall,
    Albedo,
    LiquidPrecipitationDepth,
    LiquidPrecipitationQuantity,
}

/// Number of numeric fields kept per record.
pub const NUMERIC_FIELDS: usize = 28;

impl EpwField {
    /// All numeric fields in file order.
    pub const ALL: [EpwField; NUMERIC_FIELDS] = {
        use EpwField::*;
        [
            DryBulbTemperature,
            DewPointTemperature,
            RelativeHumidity,
            AtmosphericPressure,
            ExtraterrestrialHorizontalRadiation,
            ExtraterrestrialDirectNormalRadiation,
            HorizontalInfraredRadiation,
            GlobalHorizontalRadiation,
            DirectNormalRadiation,
            DiffuseHorizontalRadiation,
            GlobalHorizontalIlluminance,
            DirectNormalIlluminance,
            DiffuseHorizontalIlluminance,
            ZenithLuminance,
            WindDirection,
            WindSpeed,
            TotalSkyCover,
            OpaqueSkyCover,
            Visibility,
            CeilingHeight,
            PresentWeatherObservation,
            PrecipitableWater,
            AerosolOpticalDepth,
            SnowDepth,
            DaysSinceLastSnowfall,
            Albedo,
            LiquidPrecipitationDepth,
            LiquidPrecipitationQuantity,
        ]
    };

    /// 1-based field number in a data row (field 28, present weather codes, is text).
    pub fn number(self) -> usize {
        let i = self as usize;
        if i < 21 { i + 7 } else { i + 8 }
    }

    /// The data dictionary's name, with its unit.
    pub fn name(self) -> &'static str {
        use EpwField::*;
        match self {
            DryBulbTemperature => "Dry Bulb Temperature (C)",
            DewPointTemperature => "Dew Point Temperature (C)",
            RelativeHumidity => "Relative Humidity (%)",
            AtmosphericPressure => "Atmospheric Station Pressure (Pa)",
            ExtraterrestrialHorizontalRadiation => "Extraterrestrial Horizontal Radiation (Wh/m2)",
            ExtraterrestrialDirectNormalRadiation => {
                "Extraterrestrial Direct Normal Radiation (Wh/m2)"
            }
            HorizontalInfraredRadiation => "Horizontal Infrared Radiation Intensity (Wh/m2)",
            GlobalHorizontalRadiation => "Global Horizontal Radiation (Wh/m2)",
            DirectNormalRadiation => "Direct Normal Radiation (Wh/m2)",
            DiffuseHorizontalRadiation => "Diffuse Horizontal Radiation (Wh/m2)",
            GlobalHorizontalIlluminance => "Global Horizontal Illuminance (lux)",
            DirectNormalIlluminance => "Direct Normal Illuminance (lux)",
            DiffuseHorizontalIlluminance => "Diffuse Horizontal Illuminance (lux)",
            ZenithLuminance => "Zenith Luminance (Cd/m2)",
            WindDirection => "Wind Direction (degrees)",
            WindSpeed => "Wind Speed (m/s)",
            TotalSkyCover => "Total Sky Cover (tenths)",
            OpaqueSkyCover => "Opaque Sky Cover (tenths)",
            Visibility => "Visibility (km)",
            CeilingHeight => "Ceiling Height (m)",
            PresentWeatherObservation => "Present Weather Observation",
            PrecipitableWater => "Precipitable Water (mm)",
            AerosolOpticalDepth => "Aerosol Optical Depth (thousandths)",
            SnowDepth => "Snow Depth (cm)",
            DaysSinceLastSnowfall => "Days Since Last Snowfall",
            Albedo => "Albedo",
            LiquidPrecipitationDepth => "Liquid Precipitation Depth (mm)",
            LiquidPrecipitationQuantity => "Liquid Precipitation Quantity (hr)",
        }
    }

    /// The missing-data code: a value `>=` this is missing (EnergyPlus data dictionary
    /// `\missing`; for the three illuminances the dictionary's note "missing if >= 999900",
    /// which `loadEPW.c` also uses). `None`: the field has no code.
    pub fn missing_from(self) -> Option<f64> {
        use EpwField::*;
        Some(match self {
            DryBulbTemperature | DewPointTemperature => 99.9,
            RelativeHumidity => 999.0,
            AtmosphericPressure => 999999.0,
            ExtraterrestrialHorizontalRadiation
            | ExtraterrestrialDirectNormalRadiation
            | HorizontalInfraredRadiation
            | GlobalHorizontalRadiation
            | DirectNormalRadiation
            | DiffuseHorizontalRadiation => 9999.0,
            GlobalHorizontalIlluminance
            | DirectNormalIlluminance
            | DiffuseHorizontalIlluminance => 999900.0,
            ZenithLuminance => 9999.0,
            WindDirection | WindSpeed => 999.0,
            TotalSkyCover | OpaqueSkyCover => 99.0,
            Visibility => 9999.0,
            CeilingHeight => 99999.0,
            PresentWeatherObservation => return None,
            PrecipitableWater => 999.0,
            AerosolOpticalDepth => 0.999,
            SnowDepth => 999.0,
            DaysSinceLastSnowfall => 99.0,
            Albedo | LiquidPrecipitationDepth => 999.0,
            LiquidPrecipitationQuantity => 99.0,
        })
    }
}

/// The LOCATION record.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EpwLocation {
    pub city: String,
    pub state: String,
    pub country: String,
    pub source: String,
    pub wmo: String,
    /// Degrees north.
    pub latitude: f64,
    /// Degrees EAST positive (EPW convention; a `.wea` file stores the negative).
    pub longitude: f64,
    /// Hours from GMT, east positive.
    pub time_zone: f64,
    /// Metres.
    pub elevation: f64,
    /// Latitude and elevation exactly as written (`epw2wea` copies them verbatim).
    pub latitude_text: String,
    pub elevation_text: String,
}

/// A date in the DATA PERIODS record: `m/d`, `m/d/y`, or a day of the year.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EpwDate {
    pub month: u8,
    pub day: u8,
    pub year: Option<i32>,
}

/// One data period of the DATA PERIODS record.
#[derive(Debug, Clone, PartialEq)]
pub struct DataPeriod {
    pub name: String,
    /// Day of the week the period starts on, as written (`Sunday`, `Mon`...).
    pub start_weekday: String,
    pub start: EpwDate,
    pub end: EpwDate,
}

/// The eight header records.
#[derive(Debug, Clone, PartialEq)]
pub struct EpwHeader {
    pub location: EpwLocation,
    /// Records 2..=7, everything after the keyword's comma, as written.
    pub design_conditions: String,
    pub typical_extreme_periods: String,
    pub ground_temperatures: String,
    pub holidays_daylight_savings: String,
    pub comments1: String,
    pub comments2: String,
    /// Records per hour (DATA PERIODS field 2): 1 for hourly files.
    pub records_per_hour: u32,
    /// At least one; Radiance uses only the first.
    pub periods: Vec<DataPeriod>,
}

impl EpwHeader {
    pub fn records_per_hour(&self) -> u32 {
        self.records_per_hour
    }
}

/// One data row.
#[derive(Debug, Clone, PartialEq)]
pub struct EpwRecord {
    pub year: i32,
    pub month: u8,
    pub day: u8,
    /// 1..=24, the hour that ENDS the interval (hour 1 is 00:00-01:00).
    pub hour: u8,
    /// 0..=60.
    pub minute: u8,
    /// Field 6, data source and uncertainty flags.
    pub flags: String,
    /// Field 28, present weather codes (text; `None` if the row is shorter).
    pub present_weather_codes: String,
    /// Numeric fields in [`EpwField`] order, as written; `None` for an empty or absent field.
    pub values: [Option<f64>; NUMERIC_FIELDS],
    /// 1-based line in the file.
    pub line: usize,
}

impl EpwRecord {
    /// The value as written, missing codes included; `None` if the field was empty/absent.
    pub fn raw(&self, f: EpwField) -> Option<f64> {
        self.values[f as usize]
    }

    /// The value unless empty, absent or marked missing.
    pub fn get(&self, f: EpwField) -> Option<f64> {
        let v = self.raw(f)?;
        match f.missing_from() {
            Some(code) if v >= code => None,
            _ => Some(v),
        }
    }

    /// True when the field holds a missing code (or nothing).
    pub fn is_missing(&self, f: EpwField) -> bool {
        self.get(f).is_none()
    }

    /// Decimal local standard time Radiance evaluates this record at (`scan_date` in
    /// `loadEPW.c`): the middle of the hour for hourly files (`hour - 1 + 0.5`), otherwise
    /// `hour - 1 + minute/60`.
    pub fn local_hour(&self, records_per_hour: u32) -> f64 {
        let h = f64::from(self.hour) - 1.0;
        if records_per_hour == 1 {
            h + 0.5
        } else {
            h + f64::from(self.minute) / 60.0
        }
    }
}

/// A whole EPW file.
#[derive(Debug, Clone, PartialEq)]
pub struct Epw {
    pub header: EpwHeader,
    pub records: Vec<EpwRecord>,
}

/// Fewest and most fields in a data row (`loadEPW.c` needs 32; the dictionary has 35).
const MIN_FIELDS: usize = 32;
const MAX_FIELDS: usize = 35;

/// Comma-separated fields of a line (fields may be empty).
fn fields(line: &str) -> IResult<&str, Vec<&str>> {
    separated_list1(char(','), take_while(|c: char| c != ',')).parse(line)
}

fn split(line: &str) -> Vec<&str> {
    // `fields` accepts any line (an empty field matches nothing), so the Err arm is only
    // there to satisfy the types.
    fields(line).map(|(_, f)| f).unwrap_or_else(|_| vec![line])
}

/// Keywords of header records 2..=8, in the order Radiance checks them.
const RECORDS: [&str; 7] = [
    "DESIGN CONDITIONS",
    "TYPICAL/EXTREME PERIODS",
    "GROUND TEMPERATURES",
    "HOLIDAYS/DAYLIGHT SAVINGS",
    "COMMENTS 1",
    "COMMENTS 2",
    "DATA PERIODS",
];

/// `KEYWORD,rest` without regard to case: returns `rest`.
fn record<'a>(line: &'a str, keyword: &str) -> Option<&'a str> {
    let n = keyword.len();
    let b = line.as_bytes();
    (b.len() > n && b[..n].eq_ignore_ascii_case(keyword.as_bytes()) && b[n] == b',')
        .then(|| &line[n + 1..])
}

/// `m/d`, `m/d/y` or a day of the year (1..=365), as `get_date` in `loadEPW.c`.
fn parse_date(s: &str) -> Option<EpwDate> {
    let parts: Vec<&str> = s.split('/').collect();
    let ints: Option<Vec<i64>> = parts.iter().map(|p| integer(p)).collect();
    let ints = ints?;
    let (month, day, year) = match ints.as_slice() {
        [jd] => {
            const START: [i64; 13] = [0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334, 365];
            if !(1..=365).contains(jd) {
                return None;
            }
            let m = START.iter().position(|&s| s >= *jd)?;
            (m as i64, jd - START[m - 1], None)
        }
        [m, d] => (*m, *d, None),
        [m, d, y] => (*m, *d, i32::try_from(*y).ok()),
        _ => return None,
    };
    check_date(month, day, 0.0).ok()?;
    Some(EpwDate {
        month: month as u8,
        day: day as u8,
        year,
    })
}

/// Radiance's `get_day`: a day name or an abbreviation of at least 3 letters.
fn is_weekday(s: &str) -> bool {
    const DAYS: [&str; 7] = [
        "sunday",
        "monday",
        "tuesday",
        "wednesday",
        "thursday",
        "friday",
        "saturday",
    ];
    let s = s.trim().to_ascii_lowercase();
    s.len() >= 3 && DAYS.iter().any(|d| d.starts_with(&s))
}

impl Epw {
    /// Read an EPW file from disk.
    pub fn read_path(path: impl AsRef<std::path::Path>) -> Result<Epw> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| Error::io(&name, e))?;
        Epw::parse(&super::decode_text(&bytes), &name)
    }

    /// Parse the text of an EPW file; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Epw> {
        let mut lines = numbered_lines(text);
        let header = parse_header(&mut lines, file)?;
        let mut records = Vec::new();
        for (lno, line) in lines {
            if line.trim().is_empty() {
                continue;
            }
            records.push(parse_record(line, lno, file)?);
        }
        if records.is_empty() {
            return Err(Error::parse(
                Location::line(file, 9),
                "no data rows after the 8 EPW header records",
            ));
        }
        Ok(Epw { header, records })
    }

    /// How many values of each field are missing (codes or empty), fields with none left out.
    pub fn missing_counts(&self) -> Vec<(EpwField, usize)> {
        EpwField::ALL
            .iter()
            .map(|&f| (f, self.records.iter().filter(|r| r.is_missing(f)).count()))
            .filter(|&(_, n)| n > 0)
            .collect()
    }
}

fn parse_header<'a>(
    lines: &mut impl Iterator<Item = (usize, &'a str)>,
    file: &str,
) -> Result<EpwHeader> {
    let mut next = |lno: usize, what: &str| {
        lines.next().map(|(_, l)| l).ok_or_else(|| {
            Error::parse(
                Location::line(file, lno),
                format!("file ends in the EPW header: expected the {what} record"),
            )
        })
    };
    // 1: LOCATION
    let line = next(1, "LOCATION")?;
    let at = |lno: usize| Location::line(file, lno);
    let rest = record(line, "LOCATION").ok_or_else(|| {
        Error::parse(
            at(1),
            format!("expected 'LOCATION,city,...', found '{}'", shorten(line)),
        )
    })?;
    let f = split(rest);
    if f.len() < 9 {
        return Err(Error::parse(
            at(1),
            format!(
                "LOCATION needs 9 fields (city,state,country,source,WMO,latitude,longitude,\
                 time zone,elevation), found {}",
                f.len()
            ),
        ));
    }
    let num = |k: usize, what: &str| {
        number(f[k]).ok_or_else(|| {
            Error::parse(
                at(1),
                format!(
                    "LOCATION: expected a number for {what}, found '{}'",
                    shorten(f[k])
                ),
            )
        })
    };
    let location = EpwLocation {
        city: f[0].to_string(),
        state: f[1].to_string(),
        country: f[2].to_string(),
        source: f[3].to_string(),
        wmo: f[4].to_string(),
        latitude: num(5, "latitude")?,
        longitude: num(6, "longitude")?,
        time_zone: num(7, "time zone")?,
        elevation: num(8, "elevation")?,
        latitude_text: f[5].to_string(),
        elevation_text: f[8].trim().to_string(),
    };
    let site = super::Site {
        latitude_deg_n: location.latitude,
        longitude_deg_e: location.longitude,
        meridian_deg_e: super::Site::meridian_from_hours(location.time_zone),
        elevation_m: location.elevation,
        ..Default::default()
    };
    site.check()
        .map_err(|m| Error::parse(at(1), format!("LOCATION: {m}")))?;
    // 2..=7: kept as text, keywords checked in Radiance's order.
    let mut texts = Vec::with_capacity(6);
    for (i, kw) in RECORDS.iter().enumerate().take(6) {
        let lno = i + 2;
        let line = next(lno, kw)?;
        let rest = record(line, kw).ok_or_else(|| {
            Error::parse(
                at(lno),
                format!("expected the '{kw},' record, found '{}'", shorten(line)),
            )
        })?;
        texts.push(rest.to_string());
    }
    // 8: DATA PERIODS,n,records per hour,name,weekday,start,end[,...]
    let line = next(8, "DATA PERIODS")?;
    let rest = record(line, "DATA PERIODS").ok_or_else(|| {
        Error::parse(
            at(8),
            format!(
                "expected the 'DATA PERIODS,' record, found '{}'",
                shorten(line)
            ),
        )
    })?;
    let f = split(rest);
    let bad = |m: String| Error::parse(at(8), format!("DATA PERIODS: {m}"));
    let n = f
        .first()
        .and_then(|s| integer(s))
        .filter(|&n| n >= 1)
        .ok_or_else(|| {
            bad(format!(
                "expected the number of periods (>= 1), found '{}'",
                shorten(f.first().copied().unwrap_or(""))
            ))
        })?;
    let per_hour = f
        .get(1)
        .and_then(|s| integer(s))
        .filter(|&r| (1..=60).contains(&r))
        .ok_or_else(|| {
            bad(format!(
                "expected records per hour (1..60), found '{}'",
                shorten(f.get(1).copied().unwrap_or(""))
            ))
        })?;
    let listed = (f.len() - 2) / 4;
    if (n as usize) > listed {
        return Err(bad(format!(
            "declares {n} period(s) but lists {listed} (name,weekday,start,end each)"
        )));
    }
    let mut periods = Vec::new();
    for p in 0..n as usize {
        let g = &f[2 + 4 * p..2 + 4 * p + 4];
        if !is_weekday(g[1]) {
            return Err(bad(format!(
                "period {}: expected a day of the week, found '{}'",
                p + 1,
                shorten(g[1])
            )));
        }
        let date = |s: &str| {
            parse_date(s).ok_or_else(|| {
                bad(format!(
                    "period {}: expected a date 'month/day', found '{}'",
                    p + 1,
                    shorten(s)
                ))
            })
        };
        periods.push(DataPeriod {
            name: g[0].to_string(),
            start_weekday: g[1].trim().to_string(),
            start: date(g[2])?,
            end: date(g[3])?,
        });
    }
    let mut t = texts.into_iter();
    let mut take = || t.next().unwrap_or_default();
    Ok(EpwHeader {
        location,
        design_conditions: take(),
        typical_extreme_periods: take(),
        ground_temperatures: take(),
        holidays_daylight_savings: take(),
        comments1: take(),
        comments2: take(),
        records_per_hour: per_hour as u32,
        periods,
    })
}

fn parse_record(line: &str, lno: usize, file: &str) -> Result<EpwRecord> {
    let at = || Location::line(file, lno);
    let f = split(line);
    if !(MIN_FIELDS..=MAX_FIELDS).contains(&f.len()) {
        return Err(Error::parse(
            at(),
            format!(
                "expected {MAX_FIELDS} comma-separated fields (at least {MIN_FIELDS}), found {}",
                f.len()
            ),
        ));
    }
    let int = |k: usize, what: &str| {
        integer(f[k]).ok_or_else(|| {
            Error::parse(
                at(),
                format!(
                    "expected an integer {what} (field {}), found '{}'",
                    k + 1,
                    shorten(f[k])
                ),
            )
        })
    };
    let year = int(0, "year")?;
    let month = int(1, "month")?;
    let day = int(2, "day")?;
    let hour = int(3, "hour")?;
    let minute = int(4, "minute")?;
    if !(1..=24).contains(&hour) {
        return Err(Error::parse(
            at(),
            format!("hour {hour} out of range 1..24 (EPW hours end their interval)"),
        ));
    }
    if !(0..=60).contains(&minute) {
        return Err(Error::parse(
            at(),
            format!("minute {minute} out of range 0..60"),
        ));
    }
    check_date(month, day, 0.0).map_err(|m| Error::parse(at(), m))?;
    let year =
        i32::try_from(year).map_err(|_| Error::parse(at(), format!("year {year} out of range")))?;
    let mut values = [None; NUMERIC_FIELDS];
    for (slot, field) in values.iter_mut().zip(EpwField::ALL) {
        let Some(text) = f.get(field.number() - 1) else {
            continue;
        };
        if text.trim().is_empty() {
            continue;
        }
        *slot = Some(number(text).ok_or_else(|| {
            Error::parse(
                at(),
                format!(
                    "expected a number for {} (field {}), found '{}'",
                    field.name(),
                    field.number(),
                    shorten(text)
                ),
            )
        })?);
    }
    // The direct and diffuse values the sky models read: the same policy as a `.wea`
    // file's (negative or beyond 1.5 x the solar constant is an error, 9999 is missing).
    for field in [
        EpwField::DirectNormalRadiation,
        EpwField::DiffuseHorizontalRadiation,
    ] {
        if let Some(v) = values[field as usize] {
            let what = format!("{} (field {})", field.name(), field.number());
            check_solar_value(v, &what, false).map_err(|m| Error::parse(at(), m))?;
        }
    }
    Ok(EpwRecord {
        year,
        month: month as u8,
        day: day as u8,
        hour: hour as u8,
        minute: minute as u8,
        flags: f[5].to_string(),
        present_weather_codes: f.get(27).map(|s| s.to_string()).unwrap_or_default(),
        values,
        line: lno,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_numbers_follow_the_dictionary() {
        assert_eq!(EpwField::DryBulbTemperature.number(), 7);
        assert_eq!(EpwField::GlobalHorizontalRadiation.number(), 14);
        assert_eq!(EpwField::DirectNormalRadiation.number(), 15);
        assert_eq!(EpwField::DiffuseHorizontalRadiation.number(), 16);
        assert_eq!(EpwField::ZenithLuminance.number(), 20);
        assert_eq!(EpwField::TotalSkyCover.number(), 23);
        assert_eq!(EpwField::PresentWeatherObservation.number(), 27);
        assert_eq!(EpwField::PrecipitableWater.number(), 29);
        assert_eq!(EpwField::AerosolOpticalDepth.number(), 30);
        assert_eq!(EpwField::LiquidPrecipitationQuantity.number(), 35);
    }

    #[test]
    fn dates_and_weekdays() {
        assert_eq!(
            parse_date(" 1/ 1"),
            Some(EpwDate {
                month: 1,
                day: 1,
                year: None
            })
        );
        assert_eq!(
            parse_date("12/31/1999"),
            Some(EpwDate {
                month: 12,
                day: 31,
                year: Some(1999)
            })
        );
        assert_eq!(
            parse_date("60"),
            Some(EpwDate {
                month: 3,
                day: 1,
                year: None
            })
        );
        assert_eq!(
            parse_date("31"),
            Some(EpwDate {
                month: 1,
                day: 31,
                year: None
            })
        );
        assert_eq!(parse_date("2/30"), None);
        assert!(is_weekday("Sunday") && is_weekday("mon") && !is_weekday("Su"));
    }
}
