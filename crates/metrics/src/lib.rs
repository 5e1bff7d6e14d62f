//! Annual daylight metrics from an illuminance matrix: what `rmetrics` computes.
//!
//! Input: a Radiance matrix with one row per sensor and one column per time step, NCOMP=1
//! in lux (`dctimestep dc.mtx sky.smx | rmtxop -c 47.4 119.9 11.6 -`), or NCOMP=3 RGB
//! irradiance (W/m2), which is converted to lux with Radiance's white efficacy and
//! photopic weights, `179 x (0.265 R + 0.670 G + 0.065 B)` ([`crate::radiometry`]), and the
//! conversion is noted in the report. Rows are streamed: memory is one row (two with a
//! direct-sun matrix) plus a few numbers per sensor.
//!
//! - [`schedule`]: column time stamps (from the weather file or `--hours`) and occupancy.
//! - [`annual`]: TAI (seed Eq. 2.2 and 4.1), UDI, DA, sDA, ASE with their conventions.
//! - [`compare`]: PE, MAPE, RMSE between model variants (seed Appendix A, Eq. A.1-A.3).
//! - [`map`]: the plan map of one metric (room outline, fixed scale, PNG or SVG).
//! - [`figures`]: temporal map (day x hour) and the distribution over the floor.
//! - [`plot`]: what every figure shares (font, palettes, PNG/SVG output).
//! - [`html`]: the self-contained HTML report frame; [`config::ReportConfig`] the study report.
//! - [`report`]: the TSV and JSON outputs.
//! - [`config`]: what `rmetrics` runs (annual metrics, melanopic, compare) as typed configs.

use rdaylight_base::{colour, error, radiometry};
use rdaylight_formats as formats;

pub mod annual;
pub mod compare;
pub mod config;
pub mod figures;
pub mod html;
pub mod map;
pub mod melanopic;
pub mod plot;
pub mod report;
pub mod schedule;

pub use annual::{SensorMetrics, Thresholds, room_means, sensor_metrics};
pub use schedule::{Schedule, Stamp};

use crate::error::{Error, Result};
use crate::formats::matrix::reader::{MatrixReader, ReadOptions};

use std::io::BufRead;

/// Streams an illuminance matrix row by row as lux, whatever its NCOMP (1 or 3).
pub struct LuxRows<R> {
    reader: MatrixReader<R>,
    buf: Vec<f64>,
    /// Set when RGB irradiance was converted to lux.
    pub converted: bool,
    /// Rows read so far (for error locations).
    rows: usize,
    /// Negative values read so far (noise of a Monte Carlo run, or a sign error upstream):
    /// kept as they are and reported as a counted note.
    pub negatives: usize,
}

impl LuxRows<Box<dyn BufRead>> {
    /// Open a matrix file (`-` = standard input).
    pub fn open(path: &str) -> Result<Self> {
        LuxRows::new(MatrixReader::open(path, &read_options())?)
    }
}

/// How we read illuminance: headerless ascii input is taken as one component (rmtxop -c
/// output) unless its header says otherwise; `EXPOSURE=` is undone as rmtxop does.
pub fn read_options() -> ReadOptions {
    ReadOptions {
        ncomp: Some(1),
        undo_exposure: true,
        ..ReadOptions::default()
    }
}

impl<R: BufRead> LuxRows<R> {
    /// Wrap a reader; refuses NCOMP other than 1 or 3.
    pub fn new(reader: MatrixReader<R>) -> Result<Self> {
        let ncomp = reader.ncomp();
        if ncomp != 1 && ncomp != 3 {
            return Err(Error::Mismatch(format!(
                "{}: NCOMP={ncomp}; rmetrics reads illuminance (NCOMP=1, lux) or RGB \
                 irradiance (NCOMP=3); reduce spectral data to lux first (rmtxop -c ...)",
                reader.name()
            )));
        }
        let buf = vec![0.0; reader.row_len()];
        Ok(LuxRows {
            reader,
            buf,
            converted: ncomp == 3,
            rows: 0,
            negatives: 0,
        })
    }
    /// Time steps per row.
    pub fn ncols(&self) -> usize {
        self.reader.ncols()
    }
    pub fn nrows(&self) -> Option<usize> {
        self.reader.nrows()
    }
    pub fn name(&self) -> &str {
        self.reader.name()
    }
    /// Next row in lux into `out` (length [`ncols`](Self::ncols)); `false` at the end.
    /// A NaN or infinite value is an error naming its row and column (every metric of the
    /// sensor would silently become NaN: issue #19 printed `TAI nan`).
    pub fn next_row(&mut self, out: &mut [f64]) -> Result<bool> {
        if !self.reader.read_row(&mut self.buf)? {
            return Ok(false);
        }
        self.rows += 1;
        let ncomp = if self.converted { 3 } else { 1 };
        if let Some(i) = self.buf.iter().position(|v| !v.is_finite()) {
            return Err(Error::parse(
                crate::error::Location::file(self.reader.name()),
                format!(
                    "row {}, column {}: value {} is not a finite number; expected illuminance",
                    self.rows,
                    i / ncomp + 1,
                    self.buf[i]
                ),
            ));
        }
        if self.converted {
            for (o, rgb) in out.iter_mut().zip(self.buf.chunks_exact(3)) {
                *o = crate::radiometry::luminance([rgb[0], rgb[1], rgb[2]]);
            }
        } else {
            out.copy_from_slice(&self.buf);
        }
        self.negatives += out.iter().filter(|&&v| v < 0.0).count();
        Ok(true)
    }
}

/// The note written into headers and logs when RGB was converted.
pub const RGB_NOTE: &str = "input was RGB irradiance (NCOMP=3): converted to lux as \
    179 x (0.265 R + 0.670 G + 0.065 B)";

/// Everything `rmetrics` computes for one matrix.
#[derive(Debug, Clone)]
pub struct Results {
    pub sensors: Vec<SensorMetrics>,
    /// Column means (room values), in [`annual::column_names`] order.
    pub room: Vec<f64>,
    pub with_ase: bool,
    /// Notes for the header (conversion, schedule).
    pub notes: Vec<String>,
    pub occupied_steps: usize,
    pub occupied_hours: f64,
}

/// Compute every metric, streaming `illum` (and `direct` in lockstep, same shape).
pub fn compute<R: BufRead, D: BufRead>(
    illum: &mut LuxRows<R>,
    direct: Option<&mut LuxRows<D>>,
    schedule: &Schedule,
    t: &Thresholds,
) -> Result<Results> {
    compute_observed(illum, direct, schedule, t, &mut |_| {})
}

/// [`compute`], handing every illuminance row (lux, one sensor) to `on_row` as it streams
/// past (the temporal map keeps what it needs of them).
pub fn compute_observed<R: BufRead, D: BufRead>(
    illum: &mut LuxRows<R>,
    mut direct: Option<&mut LuxRows<D>>,
    schedule: &Schedule,
    t: &Thresholds,
    on_row: &mut dyn FnMut(&[f64]),
) -> Result<Results> {
    t.check()?;
    let ncols = illum.ncols();
    if schedule.occupied.len() != ncols {
        return Err(Error::Mismatch(format!(
            "{}: {ncols} columns but the schedule has {} steps",
            illum.name(),
            schedule.occupied.len()
        )));
    }
    if schedule.count() == 0 {
        return Err(Error::Usage(format!(
            "no occupied time step among the {ncols} columns ({}): every percentage would be \
             0/0; check --occupied and the time stamps",
            schedule.rule
        )));
    }
    if let Some(d) = direct.as_deref() {
        if d.ncols() != ncols
            || (d.nrows().is_some() && illum.nrows().is_some() && d.nrows() != illum.nrows())
        {
            return Err(Error::Mismatch(format!(
                "direct-sun matrix {} is {:?} x {} but {} is {:?} x {ncols}; both must come from \
                 the same sensors and sky steps",
                d.name(),
                d.nrows(),
                d.ncols(),
                illum.name(),
                illum.nrows()
            )));
        }
    }
    let mut row = vec![0.0; ncols];
    let mut drow = vec![0.0; ncols];
    let mut sensors = Vec::new();
    while illum.next_row(&mut row)? {
        on_row(&row);
        let d = match direct.as_deref_mut() {
            Some(d) => {
                if !d.next_row(&mut drow)? {
                    return Err(Error::Mismatch(format!(
                        "direct-sun matrix {} ends after {} rows, {} has more",
                        d.name(),
                        sensors.len(),
                        illum.name()
                    )));
                }
                Some(drow.as_slice())
            }
            None => None,
        };
        sensors.push(sensor_metrics(
            &row,
            d,
            &schedule.occupied,
            schedule.step_hours,
            t,
        ));
    }
    if let Some(d) = direct.as_deref_mut() {
        if d.next_row(&mut drow)? {
            return Err(Error::Mismatch(format!(
                "direct-sun matrix {} has more rows than {} ({})",
                d.name(),
                illum.name(),
                sensors.len()
            )));
        }
    }
    if sensors.is_empty() {
        return Err(Error::Usage(format!("{}: no sensor rows", illum.name())));
    }
    let mut notes = vec![format!("occupancy: {}", schedule.rule)];
    if illum.converted || direct.as_deref().is_some_and(|d| d.converted) {
        notes.push(RGB_NOTE.into());
    }
    let counts = std::iter::once((illum.name(), illum.negatives))
        .chain(direct.as_deref().map(|d| (d.name(), d.negatives)));
    for (name, n) in counts.filter(|c| c.1 > 0) {
        notes.push(format!(
            "{name}: {n} negative illuminance values, used as they are (Monte Carlo noise, \
             or a sign error upstream)"
        ));
    }
    let room = room_means(&sensors);
    Ok(Results {
        sensors,
        room,
        with_ase: direct.is_some(),
        notes,
        occupied_steps: schedule.count(),
        occupied_hours: schedule.hours(),
    })
}

/// Why there is no ASE without a direct-sun matrix (printed instead of a number).
pub const ASE_REFUSAL: &str = "ASE needs a direct-sun-only illuminance matrix (--direct-sun \
    FILE: sun-only coefficients, e.g. rcontrib/rdc with -ab 0 or a sun-coefficient run, times \
    a sun-only sky such as gendaymtx -d); the total illuminance counts sky light and \
    inter-reflections as sun, so ASE is not computed from it";
