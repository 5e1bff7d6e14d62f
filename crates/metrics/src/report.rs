//! The outputs of `rmetrics`: a TSV table (one row per sensor, then a `room` row of means)
//! and the same content as JSON; and reading such a TSV back (for `rmetrics compare`).
//!
//! TSV layout: `#` lines (input, occupancy, thresholds, units, notes), then a header row
//! `sensor [x y z] TAI_klxh UDI_n UDI_s UDI_a UDI_e DA sDA [ASE_h ASE]`, one row per sensor
//! (1-based matrix row number; `x y z` when sensor positions were given) and a last row
//! `room` holding the mean of every column: Eq. 2.2 TAI, mean UDI and DA, sDA and ASE as
//! percentages of sensors. Numbers are written with at most 6 decimals.

use super::Results;
use super::annual::{Thresholds, column_names};
use crate::error::{Error, Location, Result};
use crate::formats::sensors::SensorRay;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Write;

/// A number with at most 6 decimals and no trailing zeros (`12`, `33.333333`, `nan`).
pub fn fmt_num(v: f64) -> String {
    if !v.is_finite() {
        return "nan".into();
    }
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// Header lines describing a run.
pub fn header_lines(input: &str, res: &Results, t: &Thresholds) -> Vec<String> {
    let mut v = vec![
        format!("rmetrics: {input}"),
        format!(
            "occupied steps: {} ({} h)",
            res.occupied_steps,
            fmt_num(res.occupied_hours)
        ),
        format!(
            "thresholds: UDI-n < {low} <= UDI-s < {mid} <= UDI-a <= {high} < UDI-e lx; DA >= {da} \
             lx; sDA: DA >= {sda} %; ASE: direct sun > {al} lx for > {ah} h",
            low = t.udi_low,
            mid = t.udi_mid,
            high = t.udi_high,
            da = t.da,
            sda = t.sda_percent,
            al = t.ase_lux,
            ah = t.ase_hours
        ),
        "units: TAI_klxh = seed Eq. 4.1 / 1000 (klx.h over the occupied steps, not \
         annualised); room row TAI_klxh = seed Eq. 2.2; UDI, DA in % of occupied steps; sDA, \
         ASE per sensor 100 (passes) or 0, room row = % of sensors; ASE_h in hours"
            .to_string(),
    ];
    v.extend(res.notes.iter().cloned());
    if !res.with_ase {
        v.push(format!("ASE not computed: {}", super::ASE_REFUSAL));
    }
    v
}

/// Write the TSV table.
pub fn write_tsv(
    w: &mut dyn Write,
    input: &str,
    res: &Results,
    t: &Thresholds,
    positions: Option<&[SensorRay]>,
) -> Result<()> {
    let io = |e| Error::io("<output>", e);
    for l in header_lines(input, res, t) {
        writeln!(w, "# {l}").map_err(io)?;
    }
    let cols = column_names(res.with_ase);
    let xyz = if positions.is_some() { "\tx\ty\tz" } else { "" };
    writeln!(w, "sensor{xyz}\t{}", cols.join("\t")).map_err(io)?;
    for (i, s) in res.sensors.iter().enumerate() {
        let pos = match positions.and_then(|p| p.get(i)) {
            Some(r) => format!(
                "\t{}\t{}\t{}",
                fmt_num(r.org[0]),
                fmt_num(r.org[1]),
                fmt_num(r.org[2])
            ),
            None if positions.is_some() => "\t-\t-\t-".into(),
            None => String::new(),
        };
        let vals: Vec<String> = s.values().into_iter().map(fmt_num).collect();
        writeln!(w, "{}{pos}\t{}", i + 1, vals.join("\t")).map_err(io)?;
    }
    let pos = if positions.is_some() { "\t-\t-\t-" } else { "" };
    let vals: Vec<String> = res.room.iter().copied().map(fmt_num).collect();
    writeln!(w, "room{pos}\t{}", vals.join("\t")).map_err(io)?;
    Ok(())
}

#[derive(Serialize)]
struct JsonSensor<'a> {
    sensor: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    position: Option<[f64; 3]>,
    #[serde(flatten)]
    metrics: &'a super::SensorMetrics,
}

#[derive(Serialize)]
struct JsonReport<'a> {
    input: &'a str,
    notes: Vec<String>,
    occupied_steps: usize,
    occupied_hours: f64,
    thresholds: &'a Thresholds,
    room: BTreeMap<&'static str, f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    ase_not_computed: Option<&'static str>,
    sensors: Vec<JsonSensor<'a>>,
}

/// Write the JSON report (same content as the TSV; NaN becomes `null`).
pub fn write_json(
    w: &mut dyn Write,
    input: &str,
    res: &Results,
    t: &Thresholds,
    positions: Option<&[SensorRay]>,
) -> Result<()> {
    let room = column_names(res.with_ase)
        .into_iter()
        .zip(res.room.iter().copied())
        .collect();
    let rep = JsonReport {
        input,
        notes: res.notes.clone(),
        occupied_steps: res.occupied_steps,
        occupied_hours: res.occupied_hours,
        thresholds: t,
        room,
        ase_not_computed: (!res.with_ase).then_some(super::ASE_REFUSAL),
        sensors: res
            .sensors
            .iter()
            .enumerate()
            .map(|(i, m)| JsonSensor {
                sensor: i + 1,
                position: positions.and_then(|p| p.get(i)).map(|r| r.org),
                metrics: m,
            })
            .collect(),
    };
    serde_json::to_writer_pretty(&mut *w, &rep)
        .map_err(|e| Error::io("<json>", std::io::Error::other(e)))?;
    writeln!(w).map_err(|e| Error::io("<json>", e))
}

/// A metrics table read back from a TSV: column names (metrics only, no `sensor x y z`),
/// per-sensor rows and the room row.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub columns: Vec<String>,
    pub sensors: Vec<Vec<f64>>,
    pub room: Option<Vec<f64>>,
}

/// Read a TSV written by [`write_tsv`] (any subset of metric columns; `#` lines skipped).
pub fn read_tsv(text: &str, file: &str) -> Result<Table> {
    let mut header: Option<(Vec<String>, Vec<usize>, usize)> = None;
    let mut sensors = Vec::new();
    let mut room = None;
    for (i, line) in text.lines().enumerate() {
        let loc = || Location::line(file, i + 1);
        if line.trim().is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line.split('\t').collect();
        let Some((cols, idx, width)) = &header else {
            if fields.first() != Some(&"sensor") {
                return Err(Error::parse(
                    loc(),
                    format!(
                        "expected the header row 'sensor<TAB>...' of an rmetrics table, found \
                         '{}'",
                        line.chars().take(40).collect::<String>()
                    ),
                ));
            }
            let idx: Vec<usize> = (1..fields.len())
                .filter(|&k| !matches!(fields[k], "x" | "y" | "z"))
                .collect();
            let cols = idx.iter().map(|&k| fields[k].to_string()).collect();
            header = Some((cols, idx, fields.len()));
            continue;
        };
        if fields.len() != *width {
            return Err(Error::parse(
                loc(),
                format!(
                    "expected {width} tab-separated fields as in the header, found {}",
                    fields.len()
                ),
            ));
        }
        let mut vals = Vec::with_capacity(idx.len());
        for &k in idx {
            let f = fields[k];
            let v = if f == "nan" {
                f64::NAN
            } else {
                f.parse::<f64>().map_err(|_| {
                    Error::parse(
                        loc(),
                        format!(
                            "column '{}': expected a number, found '{f}'",
                            cols[vals.len()]
                        ),
                    )
                })?
            };
            vals.push(v);
        }
        if fields[0] == "room" {
            room = Some(vals);
        } else {
            sensors.push(vals);
        }
    }
    let Some((columns, _, _)) = header else {
        return Err(Error::parse(
            Location::file(file),
            "no header row 'sensor<TAB>...': not an rmetrics table",
        ));
    };
    Ok(Table {
        columns,
        sensors,
        room,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_short() {
        assert_eq!(fmt_num(12.0), "12");
        assert_eq!(fmt_num(100.0 / 3.0), "33.333333");
        assert_eq!(fmt_num(-0.0000001), "0");
        assert_eq!(fmt_num(f64::NAN), "nan");
    }

    #[test]
    fn tsv_reads_back_and_errors_name_lines() {
        let text =
            "# x\nsensor\tx\ty\tz\tTAI_klxh\tDA\n1\t0\t0\t0.8\t1.5\t50\nroom\t-\t-\t-\t1.5\t50\n";
        let t = read_tsv(text, "a.tsv").unwrap();
        assert_eq!(t.columns, ["TAI_klxh", "DA"]);
        assert_eq!(t.sensors, vec![vec![1.5, 50.0]]);
        assert_eq!(t.room, Some(vec![1.5, 50.0]));
        let e = read_tsv("sensor\tDA\n1\tabc\n", "a.tsv").unwrap_err();
        assert_eq!(
            e.to_string(),
            "a.tsv:2: column 'DA': expected a number, found 'abc'"
        );
        let e = read_tsv("hello\n", "a.tsv").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("a.tsv:1: expected the header row")
        );
        for n in 0..text.len() {
            let _ = read_tsv(&text[..n], "a.tsv");
        }
    }
}
