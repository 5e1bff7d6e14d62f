//! # `rcalib`'s command line
//!
//! The tools layer's half of `rcalib`: the clap structs (subcommands, Radiance's `-ab`
//! spellings) and their conversion into the library's typed commands
//! ([`crate::calib::run`]), which read, compute and write. `bin/rcalib.rs` parses with
//! these and calls one `run` function.

use crate::calib::cases;
use crate::calib::measurements::Columns;
use crate::calib::room::parse_classes;
use crate::calib::run::{self, Files, Reports, SynthClimate};
use crate::calib::score::DEFAULT_SENSOR_SIGMA;
use crate::calib::session::Options;
use crate::calib::simulate::{Settings, StepSkyModel};
use crate::error::Error;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

pub const EXAMPLES: &str = "\
Examples (the bundled case, examples/calib):
  rcalib compare examples/calib/model.rad --sensors examples/calib/sensors.csv \\
      --weather examples/calib/weather.wea --measured examples/calib/measured.csv \\
      --report before.html
  rcalib explain examples/calib/model.rad --sensors ... --weather ... --measured ... \\
      --report explain.html
  rcalib apply examples/calib/model.rad --sensors examples/calib/sensors.csv \\
      --effect transmittance:0.70 > calibrated.rad
  rcalib compare calibrated.rad --before examples/calib/model.rad --sensors ... \\
      --weather ... --measured ... --report after.html
  rcalib tmscan model.rad --sensors ... --weather ... --measured ...   (seed ch. 6)
  rcalib synth --room deep --climate sunny --effect walls:0.5 --out case/
  rcalib spectral model.rad --sensors ... --weather ... --measured spectral.csv --explain
      (spectral readings: month,day,hour,sensor,410nm,...; seed ch. 6 + glazing tint)

Readings CSV: month,day,hour,sensor,lux (hour in the weather file's convention, e.g.
12.5), or month,day,hour and one column per sensor; sensor_id/id, lx/illuminance/
illuminance_lx/E and kilolux or foot-candle columns (illuminance_klx, E_fc) are read too,
other names with --columns sensor=Channel,lux=Reading; sensors: .pts (ids = line numbers) or CSV id,x,y,z,dx,dy,dz; weather: .wea or
.epw covering the measured time steps (its DNI/DHI are the measured conditions).
Coefficients are cached in --cache (default .rcalib-cache): re-runs trace nothing.";

#[derive(Parser)]
#[command(
    name = "rcalib",
    version,
    propagate_version = true,
    about = "Compare a daylight model with measurements, explain the error by missing \
             physical effects, apply them and watch the error fall",
    after_help = EXAMPLES
)]
pub struct Cli {
    #[command(subcommand)]
    pub cmd: Cmd,
    /// Refuse inline `!commands` in scene files (error instead). By default they run, as in
    /// Radiance; also RDAYLIGHT_NO_EXEC=1.
    #[arg(long, global = true)]
    pub no_exec: bool,
}

#[derive(Subcommand)]
pub enum Cmd {
    /// Simulate the measured time steps and report where the model fails.
    Compare(CompareArgs),
    /// Fit candidate missing effects, rank them and select the significant ones.
    Explain(ExplainArgs),
    /// Write the model with effects added as geometry/materials (to standard output).
    Apply(ApplyArgs),
    /// The seed's chapter-6 procedure: scan window transmittance options by MAE.
    Tmscan(CommonArgs),
    /// Generate a hidden-effect test case (model, truth, sensors, weather, readings).
    Synth(SynthArgs),
    /// Spectral readings: the seed's chapter-6 workflow (window options by 18-channel MAE at
    /// the control sensor, Table 6.4 for Ev, m-EDI, M/P), optionally explain with the tint.
    Spectral(SpectralArgs),
}

#[derive(Args)]
pub struct SpectralArgs {
    /// Scene files of the model (.rad).
    #[arg(required = true)]
    pub scene: Vec<String>,
    /// Sensors: .pts or CSV with ids.
    #[arg(long)]
    pub sensors: String,
    /// Weather of the measurement period (.wea or .epw).
    #[arg(long)]
    pub weather: String,
    /// Spectral readings: month,day,hour,sensor,<one column per channel, e.g. 410nm>.
    #[arg(long)]
    pub measured: String,
    /// Channel response curves: wavelength,<channel>,... (default: each channel is the
    /// simulated band containing its centre wavelength).
    #[arg(long)]
    pub response: Option<String>,
    /// Control sensor id (default: the sensor nearest a window).
    #[arg(long)]
    pub control: Option<String>,
    /// Simulated bands (Radiance -cs).
    #[arg(long = "cs", default_value_t = 18)]
    pub cs: usize,
    /// Simulated wavelength range in nm (Radiance -cw).
    #[arg(value_parser = super::finite, long = "cw", num_args = 2, default_values_t = [380.0, 780.0])]
    pub cw: Vec<f64>,
    /// Also explain: fit the photopic effects and the glazing tint, print `--effect`s.
    #[arg(long)]
    pub explain: bool,
    /// Assumed per-sensor spread for --explain (relative).
    #[arg(value_parser = super::finite, long, default_value_t = DEFAULT_SENSOR_SIGMA)]
    pub sensor_sigma: f64,
    /// Write the selected effects here as `--effect SPEC` arguments for `rcalib apply`
    /// (with --explain; else the selected window option).
    #[arg(long)]
    pub effects_out: Option<PathBuf>,
    /// Write the tables as HTML here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Write the tables (and the explanation) as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    #[command(flatten)]
    pub sim: SimArgs,
}

#[derive(Args, Clone)]
pub struct SimArgs {
    /// Ambient bounces of the coefficient runs (Radiance -ab).
    #[arg(long = "ab", default_value_t = Settings::model().ab)]
    pub ab: u32,
    /// Samples per sensor (Radiance -ad).
    #[arg(long = "ad", default_value_t = Settings::model().ad)]
    pub ad: usize,
    /// Path weight limit (Radiance -lw).
    #[arg(value_parser = super::finite, long = "lw", default_value_t = Settings::model().lw)]
    pub lw: f64,
    /// Sample each sensor until its relative standard error is below this (rdc
    /// --target-se --se-row; 0: exactly -ad samples, as Radiance).
    #[arg(value_parser = super::finite, long = "target-se", default_value_t = Settings::model().target_se.unwrap_or(0.0))]
    pub target_se: f64,
    /// Cap on samples per sensor with --target-se.
    #[arg(long = "max-samples", default_value_t = Settings::model().max_samples)]
    pub max_samples: usize,
    /// Reinhart sky subdivision (gendaymtx -m; 1 = Tregenza).
    #[arg(short = 'm', default_value_t = 1)]
    pub mf: usize,
    /// Random seed of the coefficient runs.
    #[arg(short = 's', long = "seed", default_value_t = 1)]
    pub seed: u64,
    /// Coefficient cache directory.
    #[arg(long, default_value = ".rcalib-cache")]
    pub cache: PathBuf,
    /// Do not read or write the cache.
    #[arg(long)]
    pub no_cache: bool,
    /// Surface classes of materials: material=walls|ceiling|floor|ground,... (default: by
    /// keywords in material names).
    #[arg(long)]
    pub classes: Option<String>,
    /// Sky of each measured step: gendaylit (default; as a point-in-time `gendaylit |
    /// rtrace -I` run sees it, one more traced run) or gendaymtx (the annual pipelines'
    /// sky, 0.5-2 % brighter in a side-lit room).
    #[arg(long, default_value = "gendaylit", value_parser = ["gendaylit", "gendaymtx"])]
    pub sky: String,
}

#[derive(Args, Clone)]
pub struct CommonArgs {
    /// Scene files of the model (.rad).
    #[arg(required = true)]
    pub scene: Vec<String>,
    /// Sensors: .pts or CSV with ids.
    #[arg(long)]
    pub sensors: String,
    /// Weather of the measurement period (.wea or .epw).
    #[arg(long)]
    pub weather: String,
    /// Readings: month,day,hour,sensor,lux (one reading per row) or month,day,hour and one
    /// column per sensor; also sensor_id or id, and lx, illuminance, illuminance_lx, E
    /// (klx or fc in the name: kilolux, foot-candles).
    #[arg(long)]
    pub measured: String,
    /// Names of the readings' columns where they differ: role=name,... with roles month,
    /// day, hour, sensor and lux, klx or fc (the illuminance column and its unit), e.g.
    /// `sensor=Channel,klx=Reading`; `fc=*`: one column per sensor, in foot-candles.
    #[arg(long)]
    pub columns: Option<String>,
    #[command(flatten)]
    pub sim: SimArgs,
}

#[derive(Args)]
pub struct CompareArgs {
    #[command(flatten)]
    pub common: CommonArgs,
    /// Also simulate this model (e.g. the one before apply) and show both side by side.
    #[arg(long)]
    pub before: Vec<String>,
    /// Write the HTML report here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Write the figures' data as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

#[derive(Args)]
pub struct ExplainArgs {
    #[command(flatten)]
    pub common: CommonArgs,
    /// Only these effect families (comma separated; default all).
    #[arg(long)]
    pub effects: Option<String>,
    /// Assumed per-sensor spread (calibration class + model noise), relative.
    #[arg(value_parser = super::finite, long, default_value_t = DEFAULT_SENSOR_SIGMA)]
    pub sensor_sigma: f64,
    /// Write the selected effects here as `--effect SPEC` arguments for `rcalib apply`
    /// (empty when nothing significant is missing).
    #[arg(long)]
    pub effects_out: Option<PathBuf>,
    /// Rounds of refinement: apply the kept effects, re-simulate, and fit them again with
    /// the coefficient model corrected by that re-simulation (0: none; at most 10, each round
    /// is a full re-simulation).
    #[arg(long, default_value_t = cases::REFINE_ROUNDS, value_parser = super::at_most::<10>)]
    pub refine: usize,
    #[arg(long)]
    pub report: Option<PathBuf>,
    #[arg(long)]
    pub json: Option<PathBuf>,
}

#[derive(Args)]
pub struct ApplyArgs {
    /// Scene files of the model (.rad).
    #[arg(required = true)]
    pub scene: Vec<String>,
    /// Sensors (ids for local obstructions and sensor faults).
    #[arg(long)]
    pub sensors: String,
    /// Effect NAME:params (repeatable), as `rcalib explain` prints them:
    /// transmittance:SCALE; walls|ceiling|floor|ground-albedo:SCALE;
    /// obstruction:AZIMUTH,HALF_WIDTH,ALTITUDE (one flat-topped sector, degrees);
    /// skyline:DISTANCE,START,STEP,ALT,ALT,... (a profile: one altitude per STEP-degree
    /// sector from azimuth START, on a circle DISTANCE m around the windows);
    /// overhang:DEPTH[,WINDOW[,ABOVE[,OVERRUN]]] (m; OVERRUN past each side of the
    /// opening, default DEPTH); local-obstruction:X0,Y0,X1,Y1,TOP[,THICK] (a box standing
    /// on the floor along the plan segment, m; THICK default 0.1) or the older
    /// local-obstruction:FRACTION,ID+ID; sensor-fault:ID=F+ID=F; tint:SCALE,SLOPE,CURVATURE
    /// (docs/rcalib-effects.md).
    #[arg(long = "effect", required = true)]
    pub effects: Vec<String>,
    /// With sensor-fault effects: the readings to correct ...
    #[arg(long)]
    pub measured: Option<String>,
    /// Names of the readings' columns (as for compare).
    #[arg(long)]
    pub columns: Option<String>,
    /// ... and where to write the corrected readings.
    #[arg(long)]
    pub corrected: Option<PathBuf>,
    /// Surface classes (as for explain).
    #[arg(long)]
    pub classes: Option<String>,
    /// Write here instead of standard output.
    #[arg(short = 'o')]
    pub output: Option<PathBuf>,
}

#[derive(Args)]
pub struct SynthArgs {
    /// office (6 x 8 m, south window), deep (3.5 x 10 m), two-window (6 x 6 m, S + E).
    #[arg(long, default_value = "office")]
    pub room: String,
    /// london (needs --weather with the London EPW) or sunny (synthetic clear-sky site).
    #[arg(long, default_value = "sunny")]
    pub climate: String,
    /// Weather file for the london climate.
    #[arg(long)]
    pub weather: Option<String>,
    /// Hidden effects NAME:params (none: a control case).
    #[arg(long = "effect")]
    pub effects: Vec<String>,
    /// Measured time steps (at most 8784, a leap year of hours).
    #[arg(long, default_value_t = 30, value_parser = super::at_most::<8784>)]
    pub steps: usize,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
    pub noise_seed: u64,
    /// Output directory (model.rad, truth.rad, sensors.csv, weather.wea, measured.csv).
    #[arg(long)]
    pub out: PathBuf,
    /// Spectral readings: one channel per band of -cs 18 -cw 380 780 (W m-2 nm-1), and a
    /// control sensor inside the first window (as the seed's); effects may include
    /// tint:SCALE,SLOPE,CURVATURE.
    #[arg(long)]
    pub spectral: bool,
    /// With --spectral: keep only these sensors of the room (1-based, comma separated).
    #[arg(long)]
    pub keep: Option<String>,
    /// Simulate the readings with the simulation options below as given. Without it they
    /// come from converged settings (-ab 12 -ad 1024 -lw 2e-5 --target-se 0.005
    /// --max-samples 262144 -s 7), so that their only error is the sensor noise; -m,
    /// --cache and --classes apply either way.
    #[arg(long)]
    pub as_model: bool,
    #[command(flatten)]
    pub sim: SimArgs,
}

/// Radiance spellings (-ab 5) to the long options clap knows (--ab 5).
pub fn radiance_spellings(args: impl Iterator<Item = String>) -> Vec<String> {
    super::long_spellings(args, &["ab", "ad", "lw", "cs", "cw"])
}

fn classes(c: &Option<String>) -> Result<Vec<(String, crate::calib::room::SurfaceClass)>, Error> {
    match c {
        Some(c) => parse_classes(c),
        None => Ok(Vec::new()),
    }
}

impl SimArgs {
    /// The simulation options (`reflectance`: with the reflectance sensitivities).
    pub fn options(&self, reflectance: bool) -> Result<Options, Error> {
        Ok(Options {
            settings: Settings {
                ab: self.ab,
                ad: self.ad,
                lw: self.lw,
                mf: self.mf,
                seed: self.seed,
                target_se: (self.target_se > 0.0).then_some(self.target_se),
                max_samples: self.max_samples,
            },
            cache: (!self.no_cache).then(|| self.cache.clone()),
            classes: classes(&self.classes)?,
            reflectance,
            sky: if self.sky == "gendaymtx" {
                StepSkyModel::Gendaymtx
            } else {
                StepSkyModel::Gendaylit
            },
            progress: super::progress::Bars::reporter("rcalib"),
        })
    }
}

/// `--columns SPEC`, checked.
fn columns(c: &Option<String>) -> Result<Columns, Error> {
    c.as_deref().map_or(Ok(Columns::default()), Columns::parse)
}

impl CommonArgs {
    pub fn files(&self) -> Result<Files, Error> {
        Ok(Files {
            scene: self.scene.clone(),
            sensors: self.sensors.clone(),
            weather: self.weather.clone(),
            measured: self.measured.clone(),
            columns: columns(&self.columns)?,
        })
    }

    pub fn to_tmscan(&self) -> Result<run::Tmscan, Error> {
        Ok(run::Tmscan {
            options: self.sim.options(false)?,
            files: self.files()?,
        })
    }
}

impl CompareArgs {
    pub fn to_run(&self) -> Result<run::Compare, Error> {
        Ok(run::Compare {
            options: self.common.sim.options(false)?,
            files: self.common.files()?,
            before: self.before.clone(),
            reports: Reports {
                html: self.report.clone(),
                json: self.json.clone(),
            },
        })
    }
}

impl ExplainArgs {
    pub fn to_run(&self) -> Result<run::Explain, Error> {
        Ok(run::Explain {
            options: self.common.sim.options(true)?,
            files: self.common.files()?,
            families: self
                .effects
                .as_deref()
                .map(|s| s.split(',').map(|x| x.trim().to_string()).collect())
                .unwrap_or_default(),
            sensor_sigma: self.sensor_sigma,
            refine: self.refine,
            effects_out: self.effects_out.clone(),
            reports: Reports {
                html: self.report.clone(),
                json: self.json.clone(),
            },
        })
    }
}

impl ApplyArgs {
    pub fn to_run(&self) -> Result<run::Apply, Error> {
        Ok(run::Apply {
            scene: self.scene.clone(),
            sensors: self.sensors.clone(),
            effects: self.effects.clone(),
            measured: self.measured.clone(),
            columns: columns(&self.columns)?,
            corrected: self.corrected.clone(),
            classes: classes(&self.classes)?,
            output: self.output.clone(),
        })
    }
}

impl SynthArgs {
    pub fn to_run(&self) -> Result<run::Synth, Error> {
        Ok(run::Synth {
            room: run::parse_room(&self.room)?,
            climate: SynthClimate::parse(&self.climate, self.weather.as_deref())?,
            effects: self.effects.clone(),
            steps: self.steps,
            noise_seed: self.noise_seed,
            out: self.out.clone(),
            spectral: self.spectral,
            keep: self.keep.clone(),
            as_model: self.as_model,
            options: self.sim.options(false)?,
        })
    }
}

impl SpectralArgs {
    pub fn to_run(&self) -> Result<run::Spectral, Error> {
        let (lo, hi) = match self.cw.as_slice() {
            [lo, hi] => (*lo, *hi),
            _ => return Err(Error::Usage("-cw: expected MIN MAX in nm".into())),
        };
        Ok(run::Spectral {
            channels: crate::radiometry::Channels::spectral(self.cs, lo, hi)?,
            files: Files {
                scene: self.scene.clone(),
                sensors: self.sensors.clone(),
                weather: self.weather.clone(),
                measured: self.measured.clone(),
                columns: Columns::default(),
            },
            response: self.response.clone(),
            control: self.control.clone(),
            explain: self.explain,
            sensor_sigma: self.sensor_sigma,
            effects_out: self.effects_out.clone(),
            reports: Reports {
                html: self.report.clone(),
                json: self.json.clone(),
            },
            options: self.sim.options(false)?,
        })
    }
}
