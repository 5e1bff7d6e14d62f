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
use crate::figures::{CdfFigure, TemporalFigure};
use crate::formats::sensors::{RayFormat, SensorRay, read_rays};
use crate::map::{MapFigure, MapSpec, Plan};
use crate::melanopic::{DailyRule, Quantity, Summary};
use crate::plot::{self, Palette};
use crate::schedule::{ScheduleSpec, Stamp, parse_range};
use crate::{LuxRows, Results, Thresholds, compare, html, melanopic, report, schedule};
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

/// How a metric is titled, labelled and scaled on figures.
#[derive(Debug, Clone, PartialEq)]
pub struct MetricInfo {
    pub title: String,
    /// Colour-bar or axis caption: the quantity and its unit.
    pub unit: String,
    /// The fixed, documented scale of maps and distributions.
    pub scale: (f64, f64),
    /// Decimals for room values and values written on maps.
    pub decimals: usize,
}

/// Top of TAI's fixed scale in klx·h: a mean of 2.74 klx over 3650 occupied hours (8-18 h
/// every day). Deep-plan values spread below it; sunlit sensors near windows exceed it
/// and show the over-range colour.
pub const TAI_SCALE_KLXH: f64 = 10_000.0;
/// Top of ASE_h's fixed scale in hours (four times the LM-83 250 h criterion).
pub const ASE_H_SCALE: f64 = 1000.0;

/// Title, caption, fixed scale and precision of an rmetrics column (thresholds in titles).
///
/// Fixed scales: TAI_klxh 0-[`TAI_SCALE_KLXH`] klx·h; UDI_n/s/a/e, DA 0-100 % of occupied
/// hours; sDA and ASE per sensor 0 (fails) or 100 (passes) on 0-100 %; ASE_h
/// 0-[`ASE_H_SCALE`] h.
pub fn metric_info(m: &str, t: &Thresholds) -> MetricInfo {
    let pct = |title: String, unit: &str| MetricInfo {
        title,
        unit: unit.into(),
        scale: (0.0, 100.0),
        decimals: 1,
    };
    let (low, mid, high) = (t.udi_low, t.udi_mid, t.udi_high);
    match m {
        "TAI_klxh" => MetricInfo {
            title: "Total annual illuminance, TAI (seed Eq. 4.1)".into(),
            unit: "TAI (klx·h)".into(),
            scale: (0.0, TAI_SCALE_KLXH),
            decimals: 0,
        },
        "UDI_n" => pct(
            format!("Useful daylight illuminance UDI-n (E < {low} lx)"),
            "UDI-n (%)",
        ),
        "UDI_s" => pct(
            format!("Useful daylight illuminance UDI-s ({low} ≤ E < {mid} lx)"),
            "UDI-s (%)",
        ),
        "UDI_a" => pct(
            format!("Useful daylight illuminance UDI-a ({mid} ≤ E ≤ {high} lx)"),
            "UDI-a (%)",
        ),
        "UDI_e" => pct(
            format!("Useful daylight illuminance UDI-e (E > {high} lx)"),
            "UDI-e (%)",
        ),
        "DA" => pct(format!("Daylight autonomy, DA (E ≥ {} lx)", t.da), "DA (%)"),
        "sDA" => pct(
            format!(
                "Spatial daylight autonomy: sensors with DA ≥ {} % (100 = passes)",
                t.sda_percent
            ),
            "sDA per sensor (%)",
        ),
        "ASE_h" => MetricInfo {
            title: format!(
                "Annual sunlight exposure: hours of direct sun > {} lx",
                t.ase_lux
            ),
            unit: "ASE (h)".into(),
            scale: (0.0, ASE_H_SCALE),
            decimals: 0,
        },
        "ASE" => pct(
            format!(
                "ASE: sensors with direct sun > {} lx for > {} h (100 = exceeds)",
                t.ase_lux, t.ase_hours
            ),
            "ASE per sensor (%)",
        ),
        other => MetricInfo {
            title: other.into(),
            unit: other.into(),
            scale: (0.0, 1.0),
            decimals: 2,
        },
    }
}

/// Options every figure of a run shares.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FigureOptions {
    /// Scene whose walls and glazing outline the maps.
    pub scene: Option<String>,
    /// `--range LO,HI` instead of the metric's fixed scale.
    pub range: Option<(f64, f64)>,
    pub palette: Palette,
    /// Write values in the map cells.
    pub values: bool,
}

/// The temporal map (day of year x hour) of illuminance.
#[derive(Debug, Clone, PartialEq)]
pub struct TemporalOptions {
    /// Figure file (.png or .svg).
    pub path: String,
    /// 1-based sensor (matrix row); none: the room median of every step.
    pub sensor: Option<usize>,
    /// Colour scale in lux (default 0-3000 lx: UDI's upper bound).
    pub range: (f64, f64),
}

/// The default temporal-map scale: 0 to UDI's upper threshold, 3000 lx.
pub const TEMPORAL_RANGE_LX: (f64, f64) = (0.0, 3000.0);

/// The default scale of the m-EDI temporal map: 0 to 1000 lx (four times the daytime
/// recommendation of 250 lx, Brown et al. 2022).
pub const TEMPORAL_RANGE_MEDI_LX: (f64, f64) = (0.0, 1000.0);

/// `LO,HI` with LO < HI (`--range`, `--temporal-range`).
pub fn parse_pair(s: &str, what: &str) -> Result<(f64, f64)> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| Error::Usage(format!("{what}: expected LO,HI such as 0,100, found '{s}'")))?;
    match v[..] {
        [a, b] if a.is_finite() && b.is_finite() && a < b => Ok((a, b)),
        _ => Err(Error::Usage(format!(
            "{what}: expected LO,HI with LO < HI such as 0,100, found '{s}'"
        ))),
    }
}

/// Sensor positions in plan.
fn plan_xy(pos: &[SensorRay]) -> Vec<[f64; 2]> {
    pos.iter().map(|r| [r.org[0], r.org[1]]).collect()
}

/// The outline of `scene` near the sensors (none without a scene).
fn load_plan(scene: Option<&str>, xy: &[[f64; 2]]) -> Result<Plan> {
    let Some(path) = scene else {
        return Ok(Plan::default());
    };
    let sc = crate::formats::scene::load(&[path], &crate::formats::scene::LoadOptions::from_env())?;
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in xy {
        lo = [lo[0].min(p[0]), lo[1].min(p[1])];
        hi = [hi[0].max(p[0]), hi[1].max(p[1])];
    }
    Ok(Plan::from_scene(&sc, (lo, hi), 1.0))
}

/// Per-step median over sensors (NaN-free input; an even count takes the mean of the middle two).
fn column_medians(rows: &[Vec<f32>]) -> Vec<f64> {
    let ncols = rows.first().map_or(0, Vec::len);
    let mut col = Vec::with_capacity(rows.len());
    (0..ncols)
        .map(|j| {
            col.clear();
            col.extend(rows.iter().map(|r| r[j] as f64));
            col.sort_by(f64::total_cmp);
            let n = col.len();
            if n % 2 == 1 {
                col[n / 2]
            } else {
                (col[n / 2 - 1] + col[n / 2]) / 2.0
            }
        })
        .collect()
}

/// What one pass over the matrices gives: the metrics, positions, and the illuminance rows
/// the temporal map needs.
struct Study {
    res: Results,
    positions: Option<Vec<SensorRay>>,
    /// Per-step values for the temporal map and their stamps.
    temporal: Option<(Vec<f64>, Vec<Stamp>)>,
    occupied: Option<(f64, f64)>,
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
    /// Metric (a column name) of the map and the distribution.
    pub map: Option<String>,
    /// Map file (.png or .svg).
    pub png: Option<String>,
    /// Distribution over the floor of the `map` metric (.png or .svg).
    pub cdf: Option<String>,
    pub figures: FigureOptions,
    pub temporal: Option<TemporalOptions>,
}

impl AnnualConfig {
    /// Thresholds, and a map's metric and inputs.
    pub fn validate(&self) -> Result<()> {
        self.thresholds.check()?;
        if let Some(m) = &self.map {
            if !column_names(true).contains(&m.as_str()) {
                return Err(Error::Usage(format!(
                    "--map: unknown metric '{m}'; one of {}",
                    column_names(true).join(", ")
                )));
            }
            if m.starts_with("ASE") && self.direct_sun.is_none() {
                return Err(Error::Usage(crate::ASE_REFUSAL.into()));
            }
            if self.png.is_some() && self.pts.is_none() {
                return Err(Error::Usage(
                    "--map needs the sensor positions (--pts FILE)".into(),
                ));
            }
        }
        for f in [&self.png, &self.cdf].into_iter().flatten() {
            plot::Format::of(f)?;
        }
        if let Some(t) = &self.temporal {
            plot::Format::of(&t.path)?;
            if self.schedule.weather.is_none() && self.schedule.hours.is_none() {
                return Err(Error::Usage(
                    "--temporal needs the time stamps of the columns (--weather or --hours)".into(),
                ));
            }
        }
        Ok(())
    }

    /// One pass: metrics, positions and (when asked) the temporal map's values.
    fn study(&self, note: &dyn Fn(&str)) -> Result<Study> {
        let positions = self.pts.as_deref().map(read_points).transpose()?;
        let mut illum = LuxRows::open(&self.illum)?;
        let spec = self.schedule.spec()?;
        let schedule = spec.build(illum.ncols(), illum.name())?;
        let mut direct = self.direct_sun.as_deref().map(LuxRows::open).transpose()?;
        let t = &self.thresholds;
        // The room median needs every sensor's row (kept as f32: 4 bytes per sensor and
        // step); one sensor only its own.
        let mut rows: Vec<Vec<f32>> = Vec::new();
        let mut kept: Option<Vec<f64>> = None;
        let mut k = 0usize;
        let want = self.temporal.as_ref().map(|t| t.sensor);
        let res = crate::compute_observed(&mut illum, direct.as_mut(), &schedule, t, &mut |row| {
            k += 1;
            match want {
                Some(None) => rows.push(row.iter().map(|&v| v as f32).collect()),
                Some(Some(s)) if s == k => kept = Some(row.to_vec()),
                _ => {}
            }
        })?;
        if let Some(p) = &positions {
            let pts = self.pts.as_deref().unwrap_or("");
            check_points(pts, p.len(), illum.name(), res.sensors.len())?;
        }
        for n in &res.notes {
            if n.starts_with("input was RGB") || n.contains("negative illuminance") {
                note(n);
            }
        }
        let temporal = match want {
            None => None,
            Some(sensor) => {
                let values = match sensor {
                    None => column_medians(&rows),
                    Some(s) => kept.ok_or_else(|| {
                        Error::Usage(format!(
                            "--temporal-sensor {s}: {} has {} sensor rows (numbered from 1)",
                            self.illum,
                            res.sensors.len()
                        ))
                    })?,
                };
                let stamps = spec.stamps()?.unwrap_or_default();
                Some((values, stamps))
            }
        };
        let occupied = if self.schedule.flags.is_none() && !self.schedule.all_steps {
            spec.occupied
        } else {
            None
        };
        Ok(Study {
            res,
            positions,
            temporal,
            occupied,
        })
    }

    /// The subtitle of figures: input, sensors, occupancy.
    fn subtitle(&self, study: &Study) -> String {
        format!(
            "{}: {} sensors; {} occupied steps ({})",
            self.illum,
            study.res.sensors.len(),
            study.res.occupied_steps,
            study
                .res
                .notes
                .first()
                .map_or("", |n| n.trim_start_matches("occupancy: "))
        )
    }

    /// The map spec of metric `m`.
    fn map_spec(&self, m: &str, subtitle: &str) -> MapSpec {
        let info = metric_info(m, &self.thresholds);
        MapSpec {
            title: info.title,
            subtitle: subtitle.into(),
            unit: info.unit,
            range: self.figures.range.unwrap_or(info.scale),
            fixed: true,
            palette: self.figures.palette,
            values: self.figures.values,
            decimals: info.decimals,
        }
    }

    fn column(res: &Results, m: &str) -> Result<Vec<f64>> {
        let k = column_names(res.with_ase)
            .iter()
            .position(|c| c == &m)
            .ok_or_else(|| Error::Usage(crate::ASE_REFUSAL.into()))?;
        Ok(res.sensors.iter().map(|s| s.values()[k]).collect())
    }

    fn cdf_figure<'a>(&self, m: &str, vals: &'a [f64], subtitle: &str) -> CdfFigure<'a> {
        let info = metric_info(m, &self.thresholds);
        let marks = match m {
            "DA" => vec![(
                self.thresholds.sda_percent,
                format!(" sDA: DA ≥ {} %", self.thresholds.sda_percent),
            )],
            "ASE_h" => vec![(
                self.thresholds.ase_hours,
                format!(" ASE: > {} h", self.thresholds.ase_hours),
            )],
            _ => vec![],
        };
        CdfFigure {
            title: format!("Distribution over the floor: {}", info.title),
            subtitle: subtitle.into(),
            unit: info.unit,
            values: vals,
            range: self.figures.range.unwrap_or(info.scale),
            marks,
        }
    }

    fn temporal_figure<'a>(&self, study: &'a Study, subtitle: &str) -> Option<TemporalFigure<'a>> {
        let (values, stamps) = study.temporal.as_ref()?;
        let t = self.temporal.as_ref()?;
        let which = match t.sensor {
            None => "room median".to_string(),
            Some(s) => format!("sensor {s}"),
        };
        Some(TemporalFigure {
            title: format!("Work-plane illuminance through the year, {which}"),
            subtitle: subtitle.into(),
            unit: "E (lx)".into(),
            stamps,
            values,
            range: t.range,
            palette: self.figures.palette,
            occupied: study.occupied,
        })
    }

    /// Compute and write; `note` receives remarks about the input (an RGB conversion).
    pub fn run(&self, stdout: &mut dyn Write, note: &dyn Fn(&str)) -> Result<()> {
        self.validate()?;
        let study = self.study(note)?;
        let res = &study.res;
        let pos = study.positions.as_deref();
        let subtitle = self.subtitle(&study);
        if let Some(m) = &self.map {
            let vals = Self::column(res, m)?;
            if let (Some(path), Some(p)) = (&self.png, pos) {
                let xy = plan_xy(p);
                let plan = load_plan(self.figures.scene.as_deref(), &xy)?;
                let spec = self.map_spec(m, &subtitle);
                plot::write(&MapFigure::new(&xy, &vals, &spec, &plan)?, path)?;
            }
            if let Some(path) = &self.cdf {
                plot::write(&self.cdf_figure(m, &vals, &subtitle), path)?;
            }
        }
        if let (Some(fig), Some(t)) = (self.temporal_figure(&study, &subtitle), &self.temporal) {
            fig.check()?;
            if fig.stamps.len() != fig.values.len() {
                return Err(Error::Mismatch(format!(
                    "{}: {} columns but {} time stamps",
                    self.illum,
                    fig.values.len(),
                    fig.stamps.len()
                )));
            }
            plot::write(&fig, &t.path)?;
        }
        let t = &self.thresholds;
        if let Some(j) = &self.json {
            write_atomically(Path::new(j), |w| {
                report::write_json(w, &self.illum, res, t, pos)
            })?;
        }
        write_out(self.output.as_deref(), stdout, |w| {
            report::write_tsv(w, &self.illum, res, t, pos)
        })
    }
}

/// The study's HTML report (`rmetrics report`): metrics, maps, temporal map, distribution,
/// settings, provenance and warnings in one self-contained page ([`crate::html`]).
#[derive(Debug, Clone, PartialEq)]
pub struct ReportConfig {
    /// The metrics and figures to report (its `output`, `json` and figure files unused).
    pub annual: AnnualConfig,
    /// The HTML file.
    pub html: String,
    pub title: String,
    /// Settings as `name=value` pairs, in order (rdc options, sky model, ...).
    pub settings: Vec<(String, String)>,
    /// The commands that made the inputs, in order.
    pub commands: Vec<String>,
    /// Files to list with their SHA-256 (the matrices, scene, sensors, weather are added).
    pub inputs: Vec<String>,
    /// Tool version lines (`rdc 0.1.0`).
    pub tools: Vec<String>,
}

impl ReportConfig {
    /// Compute, draw and write the page.
    pub fn run(&self, note: &dyn Fn(&str)) -> Result<()> {
        let a = &self.annual;
        a.validate()?;
        let pts = a.pts.as_deref().ok_or_else(|| {
            Error::Usage("report: the maps need the sensor positions (--pts FILE)".into())
        })?;
        let study = a.study(note)?;
        let res = &study.res;
        let t = &a.thresholds;
        let subtitle = a.subtitle(&study);
        let xy = plan_xy(study.positions.as_deref().unwrap_or(&[]));
        let plan = load_plan(a.figures.scene.as_deref(), &xy)?;
        let mut page = html::Page::new(&self.title, &subtitle);
        let mut warnings: Vec<String> = res.notes.iter().skip(1).cloned().collect();
        if !res.with_ase {
            warnings.push(format!("ASE not computed: {}", crate::ASE_REFUSAL));
        }
        if a.figures.scene.is_none() {
            warnings.push("no scene given (--scene): maps show no room outline or windows".into());
        }
        // Room metrics.
        let cols = column_names(res.with_ase);
        let mut rows = Vec::new();
        for (k, c) in cols.iter().enumerate() {
            let info = metric_info(c, t);
            let what = match *c {
                "sDA" => format!("share of sensors with DA ≥ {} %", t.sda_percent),
                "ASE" => format!(
                    "share of sensors with direct sun > {} lx for > {} h",
                    t.ase_lux, t.ase_hours
                ),
                "TAI_klxh" => "mean over sensors (seed Eq. 2.2)".into(),
                _ => "mean over sensors".into(),
            };
            let unit = match *c {
                "TAI_klxh" => "klx·h",
                "ASE_h" => "h",
                "sDA" | "ASE" => "% of sensors",
                _ => "% of occupied hours",
            };
            rows.push(vec![
                info.title,
                format!("{:.*}", info.decimals, res.room[k]),
                unit.into(),
                what,
            ]);
        }
        let mut body = html::table(&["metric", "room", "unit", "room value is"], &rows, &[1]);
        body += &format!(
            "<p>{} sensors, {} occupied time steps ({} h); {}.</p>",
            res.sensors.len(),
            res.occupied_steps,
            report::fmt_num(res.occupied_hours),
            html::escape(res.notes.first().map_or("", String::as_str))
        );
        page.section("metrics", "Room metrics", &body);
        // Maps.
        let mut maps = String::from("<div class=\"grid\">");
        for c in &cols {
            let vals = AnnualConfig::column(res, c)?;
            let spec = a.map_spec(c, &subtitle);
            let png = plot::encode(
                &MapFigure::new(&xy, &vals, &spec, &plan)?,
                plot::Format::Png,
            )?;
            maps += &html::figure_png(
                &png,
                &format!("map of {c}"),
                &format!(
                    "{} on its fixed scale {}–{}",
                    spec.title, spec.range.0, spec.range.1
                ),
            );
        }
        maps += "</div>";
        page.section("maps", "Maps", &maps);
        // Temporal map and distributions.
        let mut figs = String::from("<div class=\"grid\">");
        if let Some(fig) = a.temporal_figure(&study, &subtitle) {
            fig.check()?;
            if fig.stamps.len() == fig.values.len() {
                figs += &html::figure_png(
                    &plot::encode(&fig, plot::Format::Png)?,
                    "temporal map",
                    &fig.title,
                );
            } else {
                warnings
                    .push("temporal map left out: the time stamps do not match the columns".into());
            }
        }
        for c in ["DA", "TAI_klxh"] {
            let vals = AnnualConfig::column(res, c)?;
            let fig = a.cdf_figure(c, &vals, &subtitle);
            figs += &html::figure_png(
                &plot::encode(&fig, plot::Format::Png)?,
                &format!("distribution of {c}"),
                &fig.title,
            );
        }
        figs += "</div>";
        page.section("time", "Through the year and over the floor", &figs);
        // Per-sensor table.
        let mut headers = vec!["sensor", "x", "y", "z"];
        headers.extend(cols.iter().copied());
        let pos = study.positions.as_deref().unwrap_or(&[]);
        let srows: Vec<Vec<String>> = res
            .sensors
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let mut r = vec![(i + 1).to_string()];
                let o = pos.get(i).map_or([f64::NAN; 3], |p| p.org);
                r.extend(o.iter().map(|v| format!("{v:.2}")));
                for (k, v) in s.values().iter().enumerate() {
                    let d = metric_info(cols[k], t).decimals;
                    r.push(format!("{v:.d$}"));
                }
                r
            })
            .collect();
        let numeric: Vec<usize> = (0..headers.len()).collect();
        page.section(
            "sensors",
            "Per-sensor metrics",
            &format!(
                "<p>Sensors are numbered from 1 in matrix row order (as in metrics.tsv).</p><div class=\"scroll\">{}</div>",
                html::table(&headers, &srows, &numeric)
            ),
        );
        // Settings.
        let mut set = self.settings.clone();
        set.push((
            "occupancy".into(),
            res.notes.first().cloned().unwrap_or_default(),
        ));
        set.push((
            "thresholds".into(),
            report::header_lines(&a.illum, res, t)
                .get(2)
                .cloned()
                .unwrap_or_default()
                .trim_start_matches("thresholds: ")
                .to_string(),
        ));
        if let Some(w) = &a.schedule.weather {
            let wx = crate::formats::weather::Weather::read_path(w)?;
            let s = &wx.site;
            set.push(("weather file".into(), w.clone()));
            set.push((
                "site".into(),
                format!(
                    "{}, {}: latitude {:.3}° N, longitude {:.3}° E, time-zone meridian {:.1}° E,                      elevation {:.0} m; {} steps",
                    s.name,
                    s.country,
                    s.latitude_deg_n,
                    s.longitude_deg_e,
                    s.meridian_deg_e,
                    s.elevation_m,
                    wx.steps.len()
                ),
            ));
        }
        set.push((
            "figures".into(),
            format!(
                "palette {}; fixed scales per metric (TAI 0–{} klx·h, percentages 0–100 %, ASE_h 0–{} h);                  north = +Y (Radiance convention)",
                a.figures.palette.name(),
                TAI_SCALE_KLXH,
                ASE_H_SCALE
            ),
        ));
        page.section("settings", "Settings", &html::definitions(&set));
        // Provenance.
        let mut inputs: Vec<String> = Vec::new();
        for f in [
            Some(&a.illum),
            a.direct_sun.as_ref(),
            Some(&pts.to_string()),
            a.schedule.weather.as_ref(),
            a.figures.scene.as_ref(),
        ]
        .into_iter()
        .flatten()
        .chain(&self.inputs)
        {
            if f != "-" && !inputs.contains(f) {
                inputs.push(f.clone());
            }
        }
        let mut tools = self.tools.clone();
        tools.push(format!(
            "rmetrics {} (this report)",
            env!("CARGO_PKG_VERSION")
        ));
        page.section(
            "provenance",
            "Provenance",
            &html::provenance(&inputs, &tools, &self.commands)?,
        );
        // Warnings: values beyond the fixed scales.
        for c in &cols {
            let info = metric_info(c, t);
            let (lo, hi) = a.figures.range.unwrap_or(info.scale);
            let vals = AnnualConfig::column(res, c)?;
            let over = vals.iter().filter(|v| **v > hi).count();
            let under = vals.iter().filter(|v| **v < lo).count();
            if over + under > 0 {
                warnings.push(format!(
                    "{c}: {over} sensors above and {under} below the map scale {lo}–{hi} (drawn in the end colours)"
                ));
            }
        }
        page.section("warnings", "Warnings", &html::warnings(&warnings));
        let text = page.render();
        write_atomically(Path::new(&self.html), |w| {
            w.write_all(text.as_bytes())
                .map_err(|e| Error::io(&self.html, e))
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
    /// Temporal map (day of year x hour) of m-EDI: the room median of every step, or one
    /// sensor's; needs `weather`.
    pub temporal: Option<TemporalOptions>,
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
        if self.temporal.is_some() && stamps.is_none() {
            return Err(Error::Usage(
                "--temporal: needs --weather (the time stamps of the matrix's columns)".into(),
            ));
        }
        let mut medi_rows: Vec<Vec<f32>> = Vec::new();
        let sums = self.write_matrix(&mut reader, stamps.as_deref(), stdout, &mut medi_rows)?;
        if let (Some(t), Some(st)) = (&self.temporal, stamps.as_deref()) {
            let values = match t.sensor {
                Some(k) if k >= 1 && k <= medi_rows.len() => {
                    medi_rows[k - 1].iter().map(|&v| f64::from(v)).collect()
                }
                Some(k) => {
                    return Err(Error::Usage(format!(
                        "--temporal-sensor {k}: {} has sensors 1 to {}",
                        self.input,
                        medi_rows.len()
                    )));
                }
                None => column_medians(&medi_rows),
            };
            let which = t
                .sensor
                .map_or("room median".to_string(), |k| format!("sensor {k}"));
            let fig = TemporalFigure {
                title: format!("Melanopic EDI through the year, {which} (CIE S 026)"),
                subtitle: format!(
                    "{}; box: the daily rule's window {}-{} h (m-EDI >= {} lx)",
                    self.input, self.rule.start, self.rule.end, self.rule.threshold
                ),
                unit: "m-EDI (lx)".into(),
                stamps: st,
                values: &values,
                range: t.range,
                palette: Palette::Viridis,
                occupied: Some((self.rule.start, self.rule.end)),
            };
            fig.check()?;
            plot::write(&fig, &t.path)?;
        }
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
            let days = stamps.is_some();
            let spec = MapSpec {
                title: if days {
                    format!(
                        "Days with m-EDI ≥ {} lx for {} h of {}–{} h",
                        self.rule.threshold, self.rule.min_hours, self.rule.start, self.rule.end
                    )
                } else {
                    "Mean melanopic EDI over lit steps (CIE S 026)".into()
                },
                subtitle: format!("{}: {} sensors", self.input, xy.len()),
                unit: if days {
                    "days (% of days)".into()
                } else {
                    "m-EDI (lx)".into()
                },
                range: if days { (0.0, 100.0) } else { (0.0, 1000.0) },
                fixed: true,
                palette: Palette::Viridis,
                values: false,
                decimals: 1,
            };
            plot::write(&MapFigure::new(&xy, &vals, &spec, &Plan::default())?, png)?;
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
        medi_rows: &mut Vec<Vec<f32>>,
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
            let keep = self.temporal.is_some();
            sums = melanopic::reduce(reader, self.rule.threshold, daily, |_, vals| {
                if keep {
                    // f32 per sensor and step, as the illuminance temporal map keeps them.
                    medi_rows.push(vals.iter().map(|m| m.medi as f32).collect());
                }
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
