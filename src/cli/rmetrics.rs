//! # `rmetrics`' command line
//!
//! The tools layer's half of `rmetrics`: the clap structs (GNU-style long options; there is
//! no Radiance counterpart) and their conversion into the library's typed configs
//! (`rdaylight::metrics::config`), which validate, compute and write.

use crate::error::{Error, Result};
use crate::metrics::Thresholds;
use crate::metrics::config::{
    AnnualConfig, CompareConfig, FigureOptions, MelanopicConfig, ReportConfig, ScheduleOptions,
    TEMPORAL_RANGE_LX, TemporalOptions, parse_pair,
};
use crate::metrics::melanopic::DailyRule;
use crate::metrics::plot::Palette;
use crate::metrics::schedule::parse_range;
use clap::{Args, Parser, Subcommand};

pub const EXAMPLE: &str = "\
Example pipeline (two-phase, with Radiance or rdaylight tools):
  gendaymtx -m 1 weather.wea > sky.smx             # one column per weather step (no -u)
  dctimestep dc.mtx sky.smx | rmtxop -fa -c 47.4 119.9 11.6 - > illum.mtx
  rmetrics -w weather.wea --pts sensors.pts --json metrics.json illum.mtx > metrics.tsv
  rmetrics -w weather.wea --pts sensors.pts --scene room.rad --map DA --png da.png \\
      --cdf da_cdf.svg --temporal year.png illum.mtx > /dev/null
  rmetrics report -w weather.wea --pts sensors.pts --scene room.rad --direct-sun sun.mtx \\
      --setting 'rdc=-ab 5 -ad 10000 -lw 1e-5' -o report.html illum.mtx
  # ASE needs direct sun only: sun coefficients (-ab 0) times a sun-only sky (gendaymtx -d)
  rmetrics -w weather.wea --direct-sun sun.mtx illum.mtx
  rmetrics compare benchmark.tsv variant.tsv      # PE, MAPE, RMSE (seed Appendix A)

Time steps: the matrix must have one column per step of the weather file (gendaymtx
without -u); a step at decimal hour h is occupied when START <= h < END (8-18 counts the
hourly stamps 8.5 ... 17.5). Per-sensor TAI is seed Eq. 4.1 in klx.h; the `room` row
(mean of each column) is Eq. 2.2. UDI-n < 100 <= UDI-s < 300 <= UDI-a <= 3000 < UDI-e;
DA counts E >= 300 lx; sDA: share of sensors with DA >= 50 %; ASE: share of sensors with
direct sun > 1000 lx for > 250 h.";

#[derive(Parser)]
#[command(
    name = "rmetrics",
    version,
    propagate_version = true,
    about = "Annual daylight metrics (TAI, UDI, DA, sDA, ASE) from an illuminance matrix \
             (sensors x time steps), maps and model-variant errors",
    after_help = EXAMPLE,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Options {
    #[command(subcommand)]
    pub cmd: Option<Cmd>,
    /// Illuminance matrix: rows = sensors, columns = time steps; NCOMP=1 lux (rmtxop -c
    /// 47.4 119.9 11.6) or NCOMP=3 RGB irradiance (converted, noted in the output); `-` =
    /// standard input.
    #[arg(default_value = "-")]
    pub illum: String,
    #[command(flatten)]
    pub sched: SchedArgs,
    #[command(flatten)]
    pub thresh: ThreshArgs,
    /// Direct-sun-only illuminance matrix (same sensors and steps) for ASE. Without it ASE
    /// is not computed (and asking for it is an error), never reported as zero.
    #[arg(long, value_name = "FILE")]
    pub direct_sun: Option<String>,
    /// Sensor points (rtrace ascii `x y z dx dy dz`, one per matrix row): adds x y z
    /// columns and is required by --map.
    #[arg(long, value_name = "FILE")]
    pub pts: Option<String>,
    /// Write the TSV table here instead of standard output.
    #[arg(short = 'o', long, value_name = "FILE")]
    pub output: Option<String>,
    /// Also write the results as JSON.
    #[arg(long, value_name = "FILE")]
    pub json: Option<String>,
    /// Metric of the map and the distribution (a column name: TAI_klxh, UDI_n, UDI_s,
    /// UDI_a, UDI_e, DA, sDA, ASE_h, ASE).
    #[arg(long, value_name = "METRIC")]
    pub map: Option<String>,
    /// Map file of --map (.png or .svg; needs --pts): 1200 x 900 px, title, metric and
    /// unit, colour bar on the metric's fixed scale, room outline (--scene), sensors, north
    /// arrow (north = +Y) and scale bar.
    #[arg(long, value_name = "FILE", requires = "map")]
    pub png: Option<String>,
    /// Distribution of --map over the floor (.png or .svg): share of sensors reaching at
    /// least each value.
    #[arg(long, value_name = "FILE", requires = "map")]
    pub cdf: Option<String>,
    #[command(flatten)]
    pub fig: FigArgs,
}

#[derive(Args, Clone)]
pub struct ThreshArgs {
    /// UDI thresholds LOW,MID,HIGH in lux (UDI-n < LOW <= UDI-s < MID <= UDI-a <= HIGH <
    /// UDI-e). The seed's three-bin UDI (300/3000) is UDI-n + UDI-s, UDI-a, UDI-e.
    #[arg(long, value_name = "LOW,MID,HIGH", default_value = "100,300,3000")]
    pub udi: String,
    /// Daylight Autonomy threshold in lux (E >= DA counts).
    #[arg(value_parser = super::finite, long, value_name = "LUX", default_value_t = 300.0)]
    pub da: f64,
    /// sDA: a sensor passes when its DA is at least this percentage.
    #[arg(value_parser = super::finite, long, value_name = "PERCENT", default_value_t = 50.0)]
    pub sda: f64,
    /// ASE thresholds LUX,HOURS: direct sun above LUX for more than HOURS occupied hours.
    #[arg(long, value_name = "LUX,HOURS", default_value = "1000,250")]
    pub ase: String,
}

/// Options of every figure.
#[derive(Args, Clone)]
pub struct FigArgs {
    /// Scene (.rad) whose walls and glazing outline the maps (vertical polygons projected
    /// onto the floor plane; glass, dielectric, interface and BSDF materials are windows).
    #[arg(long, value_name = "FILE")]
    pub scene: Option<String>,
    /// Colour scale LO,HI of maps and distributions instead of the metric's fixed scale
    /// (TAI_klxh 0,10000 klx.h; UDI, DA, sDA, ASE 0,100 %; ASE_h 0,1000 h).
    #[arg(long, value_name = "LO,HI", allow_hyphen_values = true)]
    pub range: Option<String>,
    /// Palette: viridis (perceptually uniform, default) or falsecolor (Radiance's
    /// falsecolor default palette).
    #[arg(long, value_name = "NAME", default_value = "viridis")]
    pub palette: String,
    /// Write each sensor's value in its map cell.
    #[arg(long)]
    pub values: bool,
    /// Temporal map (day of year x hour) of illuminance, .png or .svg: the room median of
    /// every step, or --temporal-sensor's; needs --weather or --hours.
    #[arg(long, value_name = "FILE")]
    pub temporal: Option<String>,
    /// Sensor (1-based matrix row) of the temporal map instead of the room median.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub temporal_sensor: Option<u64>,
    /// Colour scale LO,HI of the temporal map in lux (default 0,3000).
    #[arg(long, value_name = "LO,HI", allow_hyphen_values = true)]
    pub temporal_range: Option<String>,
}

impl FigArgs {
    fn to_options(&self) -> Result<(FigureOptions, Option<TemporalOptions>)> {
        let range = self
            .range
            .as_deref()
            .map(|r| parse_pair(r, "--range"))
            .transpose()?;
        let figures = FigureOptions {
            scene: self.scene.clone(),
            range,
            palette: Palette::parse(&self.palette)?,
            values: self.values,
        };
        let temporal = match &self.temporal {
            Some(path) => Some(TemporalOptions {
                path: path.clone(),
                sensor: self.temporal_sensor.map(|s| s as usize),
                range: self
                    .temporal_range
                    .as_deref()
                    .map(|r| parse_pair(r, "--temporal-range"))
                    .transpose()?
                    .unwrap_or(TEMPORAL_RANGE_LX),
            }),
            None => None,
        };
        Ok((figures, temporal))
    }
}

#[derive(Args, Clone)]
pub struct SchedArgs {
    /// Weather file (.wea or .epw) the sky matrix was made from: one column per step.
    #[arg(short = 'w', long, value_name = "FILE")]
    pub weather: Option<String>,
    /// Time stamps instead: one `month day hour` line per column (e.g. with gendaymtx -u).
    #[arg(long, value_name = "FILE", conflicts_with = "weather")]
    pub hours: Option<String>,
    /// Occupied hours START-END in decimal local standard time: START <= hour < END. LEED
    /// and IES LM-83 use 8-18; the seed used 9-17 for TAI (ch. 2) and 8-17 for RMSE (App. A).
    #[arg(long, value_name = "START-END", default_value = "8-18")]
    pub occupied: String,
    /// Count Monday to Friday only (weekday from an EPW's DATA PERIODS, or --jan1).
    #[arg(long)]
    pub weekdays: bool,
    /// Weekday of 1 January (e.g. Monday) for --weekdays.
    #[arg(long, value_name = "DAY")]
    jan1: Option<String>,
    /// Occupancy flags instead of --occupied: one 0 or 1 per column, one per line.
    #[arg(long, value_name = "FILE")]
    pub schedule: Option<String>,
    /// Without time stamps: count every column as an occupied one-hour step.
    #[arg(long)]
    pub all_steps: bool,
}

// One value per run, parsed once: boxing clap's variants would buy nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
pub enum Cmd {
    /// Melanopic quantities from a spectral irradiance matrix (NCOMP > 3, Radiance band
    /// convention, e.g. `rmtx dc18.mtx sky18.smx`): writes one quantity per sensor and
    /// step as an NCOMP=1 matrix (CIE S 026 m-EDI by default; Ev, M/P, melanopic
    /// irradiance, or Radiance's `M`, where m-EDI = 0.9233 M), and optionally a per-sensor
    /// summary and a PNG map of the mean m-EDI (rdaylight::metrics::melanopic).
    Melanopic {
        /// Spectral irradiance matrix; `-` = standard input.
        #[arg(default_value = "-")]
        input: String,
        /// Quantity per sensor and step: medi, ev, mp, emel or radiance-m.
        #[arg(long, default_value = "medi")]
        quantity: crate::metrics::melanopic::Quantity,
        /// Write the matrix here instead of standard output.
        #[arg(short = 'o', long, value_name = "FILE")]
        output: Option<String>,
        /// Per-sensor summary TSV (mean m-EDI, Ev and M/P over lit steps, steps with m-EDI
        /// at or above --threshold).
        #[arg(long, value_name = "FILE")]
        summary: Option<String>,
        /// m-EDI threshold in lx for the summary (Brown et al. 2022 daytime: 250).
        #[arg(value_parser = super::finite, long, value_name = "LUX", default_value_t = crate::metrics::melanopic::DAYTIME_MEDI_LX)]
        threshold: f64,
        /// Sensor points (one per row) for the summary's x y z and for --png.
        #[arg(long, value_name = "FILE")]
        pts: Option<String>,
        /// PNG map of the mean m-EDI per sensor over the plan (needs --pts); with
        /// --weather, of the share of days passing the daily rule instead.
        #[arg(long, value_name = "FILE", requires = "pts")]
        png: Option<String>,
        /// Weather file the sky matrix was made from (one column per step): enables the
        /// daily rule (Brown et al. 2022) in the summary and map.
        #[arg(short = 'w', long, value_name = "FILE")]
        weather: Option<String>,
        /// Daily rule: the morning window START-END (decimal hours) and the hours inside
        /// it that must reach --threshold.
        #[arg(long, value_name = "START-END", default_value = "8-12")]
        morning: String,
        #[arg(value_parser = super::finite, long, value_name = "HOURS", default_value_t = 4.0)]
        min_hours: f64,
        /// Temporal map (day of year x hour) of m-EDI, .png or .svg: the room median of
        /// every step, or --temporal-sensor's; needs --weather.
        #[arg(long, value_name = "FILE", requires = "weather")]
        temporal: Option<String>,
        /// Sensor (1-based matrix row) of the temporal map instead of the room median.
        #[arg(long, value_name = "N", requires = "temporal", value_parser = clap::value_parser!(u64).range(1..=100_000_000))]
        temporal_sensor: Option<u64>,
        /// Colour scale LO,HI of the temporal map in lux of m-EDI (default 0,1000).
        #[arg(long, value_name = "LO,HI", requires = "temporal")]
        temporal_range: Option<String>,
    },
    /// One self-contained HTML report of an annual study: room and per-sensor metrics, a
    /// map of every metric, the temporal map, distributions, settings, provenance (inputs
    /// with SHA-256, tool versions, commands) and warnings.
    Report {
        /// Illuminance matrix; `-` = standard input.
        #[arg(default_value = "-")]
        illum: String,
        #[command(flatten)]
        sched: SchedArgs,
        #[command(flatten)]
        thresh: ThreshArgs,
        /// Direct-sun-only illuminance matrix for ASE.
        #[arg(long, value_name = "FILE")]
        direct_sun: Option<String>,
        /// Sensor points (one per matrix row).
        #[arg(long, value_name = "FILE", required = true)]
        pts: String,
        /// The HTML file.
        #[arg(short = 'o', long, value_name = "FILE", required = true)]
        output: String,
        /// Page title.
        #[arg(long, default_value = "Annual daylight study")]
        title: String,
        /// A setting to list, NAME=VALUE (repeatable, in order), e.g. 'rdc=-ab 5 -ad 10000'.
        #[arg(long, value_name = "NAME=VALUE")]
        setting: Vec<String>,
        /// A command that made the inputs (repeatable, in order).
        #[arg(long, value_name = "TEXT")]
        command: Vec<String>,
        /// Another input file to list with its SHA-256 (repeatable).
        #[arg(long, value_name = "FILE")]
        input: Vec<String>,
        /// A tool version line such as `rdc 0.1.0` (repeatable).
        #[arg(long, value_name = "TEXT")]
        tool: Vec<String>,
        #[command(flatten)]
        fig: FigArgs,
    },
    /// PE, MAPE, RMSE (seed Appendix A) of variants against a benchmark: two or more
    /// rmetrics TSV tables, or two or more illuminance matrices (then with the same time
    /// stamp options as the main command).
    Compare {
        /// Benchmark (TSV table or matrix).
        benchmark: String,
        /// One or more variants of the same kind.
        #[arg(required = true)]
        variants: Vec<String>,
        #[command(flatten)]
        sched: SchedArgs,
    },
}

/// What the command line asks for, as the library's config.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    Annual(AnnualConfig),
    Melanopic(MelanopicConfig),
    Compare(CompareConfig),
    Report(ReportConfig),
}

/// `n` comma-separated numbers (`--udi`, `--ase`).
fn numbers(s: &str, what: &str, n: usize) -> Result<Vec<f64>> {
    let bad = || {
        Error::Usage(format!(
            "{what}: expected {n} comma-separated numbers, found '{s}'"
        ))
    };
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| bad())?;
    if v.len() != n || v.iter().any(|x| !x.is_finite()) {
        return Err(bad());
    }
    Ok(v)
}

impl SchedArgs {
    pub fn to_options(&self) -> ScheduleOptions {
        ScheduleOptions {
            weather: self.weather.clone(),
            hours: self.hours.clone(),
            occupied: self.occupied.clone(),
            weekdays: self.weekdays,
            jan1: self.jan1.clone(),
            flags: self.schedule.clone(),
            all_steps: self.all_steps,
        }
    }
}

impl Options {
    /// The library's config; `command` goes into the melanopic matrix header.
    pub fn to_command(&self, command: Vec<String>) -> Result<Command> {
        match &self.cmd {
            Some(Cmd::Compare {
                benchmark,
                variants,
                sched,
            }) => Ok(Command::Compare(CompareConfig {
                benchmark: benchmark.clone(),
                variants: variants.clone(),
                schedule: sched.to_options(),
            })),
            Some(m @ Cmd::Melanopic { .. }) => melanopic(m, command).map(Command::Melanopic),
            Some(Cmd::Report {
                illum,
                sched,
                thresh,
                direct_sun,
                pts,
                output,
                title,
                setting,
                command,
                input,
                tool,
                fig,
            }) => {
                let (figures, temporal) = fig.to_options()?;
                let temporal = temporal.or_else(|| {
                    (sched.weather.is_some() || sched.hours.is_some()).then(|| TemporalOptions {
                        path: "report.png".into(),
                        sensor: fig.temporal_sensor.map(|s| s as usize),
                        range: TEMPORAL_RANGE_LX,
                    })
                });
                let settings = setting
                    .iter()
                    .map(|s| {
                        s.split_once('=')
                            .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
                            .ok_or_else(|| {
                                Error::Usage(format!("--setting: expected NAME=VALUE, found '{s}'"))
                            })
                    })
                    .collect::<Result<Vec<_>>>()?;
                Ok(Command::Report(ReportConfig {
                    annual: AnnualConfig {
                        illum: illum.clone(),
                        schedule: sched.to_options(),
                        thresholds: thresh.to_thresholds()?,
                        direct_sun: direct_sun.clone(),
                        pts: Some(pts.clone()),
                        output: None,
                        json: None,
                        map: None,
                        png: None,
                        cdf: None,
                        figures,
                        temporal,
                    },
                    html: output.clone(),
                    title: title.clone(),
                    settings,
                    commands: command.clone(),
                    inputs: input.clone(),
                    tools: tool.clone(),
                }))
            }
            None => self.to_annual().map(Command::Annual),
        }
    }

    fn to_annual(&self) -> Result<AnnualConfig> {
        let (figures, temporal) = self.fig.to_options()?;
        Ok(AnnualConfig {
            illum: self.illum.clone(),
            schedule: self.sched.to_options(),
            thresholds: self.thresh.to_thresholds()?,
            direct_sun: self.direct_sun.clone(),
            pts: self.pts.clone(),
            output: self.output.clone(),
            json: self.json.clone(),
            map: self.map.clone(),
            png: self.png.clone(),
            cdf: self.cdf.clone(),
            figures,
            temporal,
        })
    }
}

impl ThreshArgs {
    fn to_thresholds(&self) -> Result<Thresholds> {
        let udi = numbers(&self.udi, "--udi", 3)?;
        let ase = numbers(&self.ase, "--ase", 2)?;
        Ok(Thresholds {
            udi_low: udi[0],
            udi_mid: udi[1],
            udi_high: udi[2],
            da: self.da,
            sda_percent: self.sda,
            ase_lux: ase[0],
            ase_hours: ase[1],
        })
    }
}

fn melanopic(cmd: &Cmd, command: Vec<String>) -> Result<MelanopicConfig> {
    let Cmd::Melanopic {
        input,
        quantity,
        output,
        summary,
        threshold,
        pts,
        png,
        weather,
        morning,
        min_hours,
        temporal,
        temporal_sensor,
        temporal_range,
    } = cmd
    else {
        unreachable!("called with the melanopic subcommand")
    };
    let (start, end) = parse_range(morning).map_err(|_| {
        Error::Usage(format!(
            "--morning: expected START-END in decimal hours such as 8-12, found '{morning}'"
        ))
    })?;
    Ok(MelanopicConfig {
        input: input.clone(),
        quantity: *quantity,
        output: output.clone(),
        summary: summary.clone(),
        pts: pts.clone(),
        png: png.clone(),
        weather: weather.clone(),
        rule: DailyRule {
            threshold: *threshold,
            start,
            end,
            min_hours: *min_hours,
        },
        temporal: match temporal {
            None => None,
            Some(path) => Some(TemporalOptions {
                path: path.clone(),
                sensor: temporal_sensor.map(|s| s as usize),
                range: match temporal_range {
                    Some(r) => parse_pair(r, "--temporal-range")?,
                    None => crate::metrics::config::TEMPORAL_RANGE_MEDI_LX,
                },
            }),
        },
        command,
    })
}
