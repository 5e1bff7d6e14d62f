//! # What `rmetrics` computes, as typed configs with one `run` each
//!
//! | config | `rmetrics` command | writes |
//! |---|---|---|
//! | [`AnnualConfig`] | `rmetrics [options] illum.mtx` | TSV table, optional JSON and PNG map |
//! | [`MelanopicConfig`] | `rmetrics melanopic ...` | NCOMP=1 matrix, optional summary TSV and PNG |
//! | [`CompareConfig`] | `rmetrics compare bench variant...` | PE, MAPE, RMSE table |
//!
//! Each `run` takes the writer that stands for standard output (used when no output file
//! is named, or `-`); named files are written atomically. Rules about values and
//! combinations are checked in the order the tool has always reported them.

use crate::annual::column_names;
use crate::error::{Error, Result};
use crate::formats::sensors::{RayFormat, SensorRay, read_rays};
use crate::melanopic::{DailyRule, Quantity, Summary};
use crate::schedule::{ScheduleSpec, Stamp, parse_range};
use crate::{LuxRows, Thresholds, compare, map, melanopic, report, schedule};
use rdaylight_base::io::write_atomically;
use std::io::Write;
use std::path::Path;

/// Where the time stamps and the occupancy come from, as the options spell them.
///
/// `occupied` stays text until a schedule is needed ([`Self::spec`]): comparing two
/// rmetrics tables needs none, so a range there is never parsed.
#[derive(Debug, Clone, PartialEq)]
pub struct ScheduleOptions {
    /// `--weather`: the `.wea`/`.epw` the sky matrix was made from.
    pub weather: Option<String>,
    /// `--hours`: a `month day hour` file, one line per column.
    pub hours: Option<String>,
    /// `--occupied START-END` (decimal hours, `START <= hour < END`).
    pub occupied: String,
    /// `--weekdays`: Monday to Friday only.
    pub weekdays: bool,
    /// `--jan1`: weekday of 1 January.
    pub jan1: Option<String>,
    /// `--schedule`: 0/1 flags, one per column.
    pub flags: Option<String>,
    /// `--all-steps`: every column is an occupied one-hour step.
    pub all_steps: bool,
}

impl Default for ScheduleOptions {
    fn default() -> Self {
        ScheduleOptions {
            weather: None,
            hours: None,
            occupied: "8-18".into(),
            weekdays: false,
            jan1: None,
            flags: None,
            all_steps: false,
        }
    }
}

impl ScheduleOptions {
    /// The schedule's specification (parses `occupied`).
    pub fn spec(&self) -> Result<ScheduleSpec> {
        Ok(ScheduleSpec {
            weather: self.weather.clone(),
            hours: self.hours.clone(),
            occupied: Some(parse_range(&self.occupied)?),
            weekdays: self.weekdays,
            jan1: self.jan1.clone(),
            flags: self.flags.clone(),
            all_steps: self.all_steps,
        })
    }
}

/// Write to the file `path` atomically, or (none or `-`) to `stdout`, then flush it.
pub fn write_out(
    path: Option<&str>,
    stdout: &mut dyn Write,
    f: impl FnOnce(&mut dyn Write) -> Result<()>,
) -> Result<()> {
    match path {
        Some(p) if p != "-" => write_atomically(Path::new(p), f),
        _ => {
            f(stdout)?;
            stdout.flush().map_err(|e| Error::io("<stdout>", e))
        }
    }
}

/// Sensor rays (rtrace ascii `x y z dx dy dz`) from `path`.
pub fn read_points(path: &str) -> Result<Vec<SensorRay>> {
    let f = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    read_rays(std::io::BufReader::new(f), path, RayFormat::Ascii)
}

/// Refuse a sensor file whose count differs from the matrix rows.
fn check_points(pts: &str, npts: usize, matrix: &str, nrows: usize) -> Result<()> {
    if npts != nrows {
        return Err(Error::Mismatch(format!(
            "{pts}: {npts} sensor points but {matrix} has {nrows} rows"
        )));
    }
    Ok(())
}

/// Write a falsecolor map of `vals` over the plan positions `xy` as a PNG file.
fn write_map(png: &str, xy: &[[f64; 2]], vals: &[f64]) -> Result<()> {
    let bytes = map::png_bytes(&map::render(xy, vals)?)?;
    write_atomically(Path::new(png), |w| {
        w.write_all(&bytes).map_err(|e| Error::io(png, e))
    })
}

/// The annual metrics of one illuminance matrix.
#[derive(Debug, Clone, PartialEq)]
pub struct AnnualConfig {
    /// Illuminance matrix (`-` = standard input).
    pub illum: String,
    pub schedule: ScheduleOptions,
    pub thresholds: Thresholds,
    /// Direct-sun-only matrix for ASE (without it ASE is not computed).
    pub direct_sun: Option<String>,
    /// Sensor points: x y z columns, and the plan for the map.
    pub pts: Option<String>,
    /// TSV table file (none or `-`: standard output).
    pub output: Option<String>,
    /// JSON file.
    pub json: Option<String>,
    /// Metric (a column name) and PNG file of the map.
    pub map: Option<(String, String)>,
}

impl AnnualConfig {
    /// Thresholds, and a map's metric and inputs.
    pub fn validate(&self) -> Result<()> {
        self.thresholds.check()?;
        if let Some((m, _)) = &self.map {
            if !column_names(true).contains(&m.as_str()) {
                return Err(Error::Usage(format!(
                    "--map: unknown metric '{m}'; one of {}",
                    column_names(true).join(", ")
                )));
            }
            if m.starts_with("ASE") && self.direct_sun.is_none() {
                return Err(Error::Usage(crate::ASE_REFUSAL.into()));
            }
            if self.pts.is_none() {
                return Err(Error::Usage(
                    "--map needs the sensor positions (--pts FILE)".into(),
                ));
            }
        }
        Ok(())
    }

    /// Compute and write; `note` receives remarks about the input (an RGB conversion).
    pub fn run(&self, stdout: &mut dyn Write, note: &dyn Fn(&str)) -> Result<()> {
        self.validate()?;
        let positions = self.pts.as_deref().map(read_points).transpose()?;
        let mut illum = LuxRows::open(&self.illum)?;
        let schedule = self.schedule.spec()?.build(illum.ncols(), illum.name())?;
        let mut direct = self.direct_sun.as_deref().map(LuxRows::open).transpose()?;
        let t = &self.thresholds;
        let res = crate::compute(&mut illum, direct.as_mut(), &schedule, t)?;
        if let Some(p) = &positions {
            let pts = self.pts.as_deref().unwrap_or("");
            check_points(pts, p.len(), illum.name(), res.sensors.len())?;
        }
        for n in &res.notes {
            if n.starts_with("input was RGB") || n.contains("negative illuminance") {
                note(n);
            }
        }
        let pos = positions.as_deref();
        if let Some((m, png)) = &self.map {
            let k = column_names(res.with_ase)
                .iter()
                .position(|c| c == m)
                .ok_or_else(|| Error::Usage(crate::ASE_REFUSAL.into()))?;
            let xy: Vec<[f64; 2]> = pos
                .unwrap_or(&[])
                .iter()
                .map(|r| [r.org[0], r.org[1]])
                .collect();
            let vals: Vec<f64> = res.sensors.iter().map(|s| s.values()[k]).collect();
            write_map(png, &xy, &vals)?;
        }
        if let Some(j) = &self.json {
            write_atomically(Path::new(j), |w| {
                report::write_json(w, &self.illum, &res, t, pos)
            })?;
        }
        write_out(self.output.as_deref(), stdout, |w| {
            report::write_tsv(w, &self.illum, &res, t, pos)
        })
    }
}

/// Model-variant errors against a benchmark (seed Appendix A).
#[derive(Debug, Clone, PartialEq)]
pub struct CompareConfig {
    /// Benchmark: an rmetrics TSV table or an illuminance matrix.
    pub benchmark: String,
    /// Variants of the same kind.
    pub variants: Vec<String>,
    /// Time stamps of matrices (unused for tables).
    pub schedule: ScheduleOptions,
}

impl CompareConfig {
    /// Compare and write the table to `stdout`.
    pub fn run(&self, stdout: &mut dyn Write) -> Result<()> {
        let (bench, variants) = (&self.benchmark, &self.variants);
        let rows = if is_table(bench)? {
            let text = |p: &str| std::fs::read(p).map_err(|e| Error::io(p, e));
            let b = report::read_tsv(&String::from_utf8_lossy(&text(bench)?), bench)?;
            let mut vs = Vec::new();
            for v in variants {
                vs.push((
                    v.clone(),
                    report::read_tsv(&String::from_utf8_lossy(&text(v)?), v)?,
                ));
            }
            compare::compare_tables(&b, bench, &vs)?
        } else {
            let mut b = LuxRows::open(bench)?;
            let schedule = self.schedule.spec()?.build(b.ncols(), bench)?;
            let mut vs = variants
                .iter()
                .map(|v| LuxRows::open(v))
                .collect::<Result<Vec<_>>>()?;
            compare::compare_matrices(&mut b, &mut vs, &schedule)?
        };
        write_out(None, stdout, |w| {
            compare::write_comparison(w, bench, variants, &rows)
        })
    }
}

/// Whether `path` holds an rmetrics TSV table: only the start decides (a matrix is then
/// streamed, never loaded whole).
fn is_table(path: &str) -> Result<bool> {
    use std::io::Read;
    let mut first = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(4096).read_to_end(&mut first))
        .map_err(|e| Error::io(path, e))?;
    Ok(String::from_utf8_lossy(&first)
        .lines()
        .find(|l| !l.starts_with('#') && !l.trim().is_empty())
        .is_some_and(|l| l.starts_with("sensor\t")))
}

/// Melanopic quantities of a spectral irradiance matrix (`rmetrics melanopic`).
#[derive(Debug, Clone, PartialEq)]
pub struct MelanopicConfig {
    /// Spectral irradiance matrix (`-` = standard input).
    pub input: String,
    /// Quantity per sensor and step.
    pub quantity: Quantity,
    /// Matrix file (none or `-`: standard output).
    pub output: Option<String>,
    /// Per-sensor summary TSV.
    pub summary: Option<String>,
    /// Sensor points (one per row) for the summary and the map.
    pub pts: Option<String>,
    /// PNG map (needs `pts`).
    pub png: Option<String>,
    /// Weather file of the sky matrix: enables the daily rule.
    pub weather: Option<String>,
    /// m-EDI threshold and the daily rule (Brown et al. 2022).
    pub rule: DailyRule,
    /// The command line for the matrix header.
    pub command: Vec<String>,
}

impl MelanopicConfig {
    /// Compute and write the matrix (to `stdout` unless `output`), the summary and map.
    pub fn run(&self, stdout: &mut dyn Write) -> Result<()> {
        let positions: Option<Vec<[f64; 3]>> = match self.pts.as_deref() {
            Some(p) => Some(read_points(p)?.iter().map(|r| r.org).collect()),
            None => None,
        };
        let opts = melanopic::read_options();
        let mut reader = crate::formats::matrix::MatrixReader::open(&self.input, &opts)?;
        let stamps = self.stamps(reader.ncols())?;
        // Everything that can be checked before the matrix is written (issue #19: a header
        // cut off at NCOLS= came out before the error): the bands, the sensor count, and a
        // file's data.
        melanopic::BandWeights::new(&reader.info().channels).map_err(|e| match e {
            Error::Mismatch(m) => Error::Mismatch(format!("{}: {m}", self.input)),
            other => other,
        })?;
        if let (Some(p), Some(rows)) = (&positions, reader.nrows()) {
            check_points(
                self.pts.as_deref().unwrap_or(""),
                p.len(),
                &self.input,
                rows,
            )?;
        }
        crate::formats::matrix::reader::check_data(&self.input, &opts)?;
        let sums = self.write_matrix(&mut reader, stamps.as_deref(), stdout)?;
        if let Some(p) = &positions {
            let pts = self.pts.as_deref().unwrap_or("");
            check_points(pts, p.len(), &self.input, sums.len())?;
        }
        if let Some(s) = &self.summary {
            write_atomically(Path::new(s), |w| {
                melanopic::write_summary(w, s, &sums, self.rule.threshold, positions.as_deref())
            })?;
        }
        if let (Some(png), Some(p)) = (&self.png, &positions) {
            let xy: Vec<[f64; 2]> = p.iter().map(|q| [q[0], q[1]]).collect();
            let vals: Vec<f64> = if stamps.is_some() {
                sums.iter().map(|s| s.days_share()).collect()
            } else {
                sums.iter().map(|s| s.mean_medi).collect()
            };
            write_map(png, &xy, &vals)?;
        }
        Ok(())
    }

    /// The weather's time stamps, one per matrix column.
    fn stamps(&self, ncols: usize) -> Result<Option<Vec<Stamp>>> {
        let Some(w) = self.weather.as_deref() else {
            return Ok(None);
        };
        let st = schedule::stamps_from_weather(&crate::formats::weather::Weather::read_path(w)?);
        if st.len() != ncols {
            return Err(Error::Mismatch(format!(
                "{w}: {} weather steps but {} has {} columns (make the sky matrix \
                 without -u)",
                st.len(),
                self.input,
                ncols
            )));
        }
        Ok(Some(st))
    }

    /// Stream the input into the NCOMP=1 matrix of the quantity; the per-sensor sums.
    fn write_matrix<R: std::io::BufRead>(
        &self,
        reader: &mut crate::formats::matrix::MatrixReader<R>,
        stamps: Option<&[Stamp]>,
        stdout: &mut dyn Write,
    ) -> Result<Vec<Summary>> {
        use crate::formats::header::Header;
        use crate::formats::matrix::{DataFormat, MatrixWriter, WriteOptions};
        let step = stamps.map_or(1.0, schedule::step_hours);
        let daily = stamps.map(|s| (s, step, &self.rule));
        let mut header = Header::new();
        header.push_command(&self.command);
        let mut sums = Vec::new();
        let output = self.output.as_deref();
        write_out(output, stdout, |w| {
            let mut mw = MatrixWriter::new(
                w,
                output.unwrap_or("<stdout>"),
                header,
                reader.nrows(),
                reader.ncols(),
                rdaylight_base::radiometry::Channels::mono(),
                WriteOptions::new(DataFormat::Ascii),
            )?;
            let mut row = Vec::new();
            sums = melanopic::reduce(reader, self.rule.threshold, daily, |_, vals| {
                row.clear();
                row.extend(vals.iter().map(|m| self.quantity.of(m)));
                mw.write_row(&row)
            })?;
            mw.finish()?;
            Ok(())
        })?;
        Ok(sums)
    }
}
