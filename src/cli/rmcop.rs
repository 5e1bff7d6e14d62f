//! # `rmcop`'s command line: Material Classes of Precision (the seed's chapter 3)
//!
//! The tools layer's half of `rmcop`: clap structs and their conversion into
//! [`crate::mcop::StudyConfig`]; the GLoD options are `rglod`'s ([`super::rglod::Common`]),
//! with the object grouping spelled `--objects` because `--by` chooses per-material or
//! per-class draws here. The study itself is `rdaylight::mcop`.

use super::rglod::{By, FrameArg};
use crate::error::{Error, IoContext, Result};
use crate::formats::shard::{InputSum, Manifest, Shard, check_manifests};
use crate::formats::weather::Weather;
use crate::mcop::study::{self, DrawRecord, SHARD_FORMAT, ShardFile};
use crate::mcop::{Grouping, Results, StudyConfig, Truncation, report};
use clap::{Args, Parser, Subcommand, ValueEnum};
use std::io::Write;
use std::path::Path;

pub const EXAMPLES: &str = "\
Examples:
    rmcop study -w site.epw --pts sensors.pts -o mcop room.rad
                      the seed's experiment: GLoD0-4 x MCoP 0.05-0.20, 500 draws per cell
    rmcop study -w site.epw --pts sensors.pts --levels 4 --sigmas 0.1 --draws 2000 --hourly \\
          -o mcop room.rad      one cell, with UDI, DA, sDA and the Eq. A.3 RMSE per draw
    rmcop study ... --shard 3/8 --records draws3.json room.rad     one block of draws
    rmcop merge -o mcop draws*.json                 the statistics of all shards' draws
    rmcop validate -w site.epw --pts sensors.pts --draws 20 room.rad
                      re-weighting against re-simulation with the same drawn materials

What a Radiance user does instead: a loop that edits the materials (500 draws x 4 sigmas x
5 scene versions), runs rcontrib/rfluxmtx and dctimestep for each: 10,000 simulations.";

#[derive(Parser, Debug)]
#[command(
    name = "rmcop",
    version,
    propagate_version = true,
    about = "Material Classes of Precision: how material measurement error moves annual \
             daylight metrics, by re-weighting the paths of one trace per GLoD",
    after_help = EXAMPLES,
    args_override_self = true
)]
pub struct Options {
    #[command(subcommand)]
    pub cmd: Cmd,
}

#[derive(Subcommand, Debug)]
pub enum Cmd {
    /// Trace each GLoD once, draw every material's property from each MCoP, and write the
    /// seed-shaped tables and plots (to -o DIR; the cell table also to standard output).
    Study {
        #[command(flatten)]
        inputs: Inputs,
        /// Directory for the tables and plots.
        #[arg(short = 'o', long = "out", value_name = "DIR")]
        out: Option<String>,
        /// Compute only this block of draws (K/N, 0-based) and write its records to
        /// --records; `rmcop merge` reduces all shards.
        #[arg(long, value_name = "K/N", requires = "records")]
        shard: Option<String>,
        /// Write every draw's results (JSON) here (needed with --shard).
        #[arg(long, value_name = "FILE")]
        records: Option<String>,
    },
    /// Reduce the records of all shards of one study (checked: same inputs, settings and
    /// tool version, every shard present) to the tables and plots of one run.
    Merge {
        /// Directory for the tables and plots.
        #[arg(short = 'o', long = "out", value_name = "DIR", required = true)]
        out: String,
        /// The shards' --records files.
        #[arg(required = true)]
        records: Vec<String>,
    },
    /// Compare re-weighting with brute-force re-simulation of the same drawn materials for
    /// --draws draws per sigma, against the re-simulations' own measured noise.
    Validate {
        #[command(flatten)]
        inputs: Inputs,
        /// Traces of the error-free scene with other seeds, to measure the noise.
        #[arg(long, value_name = "N", default_value_t = 6)]
        noise_runs: usize,
    },
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ByArg {
    /// Every material its own error.
    Material,
    /// One error per surface class (glazing, floor, ceiling, walls, furniture, or --class).
    Class,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TruncateArg {
    /// Draw again until the value is physical (a truncated normal).
    Redraw,
    /// Clamp to the bounds.
    Clip,
}

#[derive(Args, Debug)]
pub struct Inputs {
    /// Weather file (.epw or .wea) for the sky matrix.
    #[arg(short = 'w', long = "weather", value_name = "FILE")]
    pub weather: String,
    /// Sensor rays (`x y z dx dy dz` per line).
    #[arg(long = "pts", value_name = "FILE")]
    pub pts: String,
    /// MCoP sigmas: absolute errors of reflectance and transmittance.
    #[arg(long, value_name = "S,S,..", default_value = "0.05,0.10,0.15,0.20")]
    pub sigmas: String,
    /// Draws per GLoD x MCoP cell (the seed: 500).
    #[arg(long, value_name = "N", default_value_t = 500)]
    pub draws: usize,
    /// GLoDs to study (0-4), comma-separated.
    #[arg(long, value_name = "L,L,..", default_value = "0,1,2,3,4")]
    pub levels: String,
    /// One error per material or per surface class.
    #[arg(long, value_enum, default_value = "material")]
    pub by: ByArg,
    /// Name a surface class by material names: `CLASS=GLOB` (repeatable; for --by class).
    #[arg(long = "class", value_name = "CLASS=GLOB")]
    pub class: Vec<String>,
    /// How draws outside the physical bounds are handled.
    #[arg(long, value_enum, default_value = "redraw")]
    pub truncate: TruncateArg,
    /// Only these materials vary (comma-separated names; default: every reflecting or
    /// transmitting material).
    #[arg(long, value_name = "M,M,..")]
    pub materials: Option<String>,
    /// Also UDI, DA, sDA and the seed's Eq. A.3 RMSE per draw (an hourly product per draw).
    #[arg(long)]
    pub hourly: bool,
    /// Occupied hours START-END (local standard time, START <= hour < END).
    #[arg(long, value_name = "START-END", default_value = "8-18")]
    pub occupied: String,
    /// Diffuse bounces (rdc -ab).
    #[arg(long = "ab", value_name = "N", default_value_t = 5)]
    pub ab: u32,
    /// Samples per sensor (rdc -ad).
    #[arg(long = "ad", value_name = "N", default_value_t = 10000)]
    pub ad: usize,
    /// Path weight limit (rdc -lw).
    #[arg(value_parser = super::finite, long = "lw", value_name = "W", default_value_t = 1e-5)]
    pub lw: f64,
    /// Seed of the traces and the draws.
    #[arg(short = 's', long = "seed", default_value_t = 1)]
    pub seed: u64,
    /// Worker threads (all cores by default).
    #[arg(short = 'n', value_name = "N")]
    pub threads: Option<usize>,
    /// How primitives form objects for the GLoDs (rglod --by).
    #[arg(long = "objects", value_enum, default_value = "prefix")]
    pub objects: By,
    /// Separator for --objects prefix.
    #[arg(long, default_value = ".")]
    pub separator: String,
    /// Identifiers that are always permanent (rglod --permanent; repeatable).
    #[arg(long, value_name = "GLOB")]
    pub permanent: Vec<String>,
    /// Minimum OBB areas (m2) of GLoD1, GLoD2, GLoD3.
    #[arg(long, value_name = "A1,A2,A3", default_value = "3.0,2.4,0.5")]
    pub thresholds: String,
    /// Refuse inline `!commands` in scenes (error instead). By default they run, as in
    /// Radiance; also RDAYLIGHT_NO_EXEC=1.
    #[arg(long)]
    pub no_exec: bool,
    /// Scene files, in order.
    #[arg(required = true)]
    pub scenes: Vec<String>,
}

/// Radiance's spellings of the sampling options (`-ab 5` for `--ab 5`).
pub fn radiance_spellings(args: impl IntoIterator<Item = String>) -> Vec<String> {
    super::long_spellings(args, &["ab", "ad", "lw"])
}

impl Inputs {
    fn glod(&self) -> super::rglod::Common {
        super::rglod::Common {
            by: self.objects,
            separator: self.separator.clone(),
            connect_tol: 1e-3,
            tolerance: 0.01,
            frame: FrameArg::Axes,
            permanent: self.permanent.clone(),
            thresholds: self.thresholds.clone(),
            percentiles: false,
            no_exec: self.no_exec,
            scenes: self.scenes.clone(),
        }
    }

    /// The library's configuration.
    pub fn config(&self, shard: Option<Shard>) -> Result<StudyConfig> {
        let levels = self
            .levels
            .split(',')
            .map(|l| l.trim().parse::<u8>())
            .collect::<std::result::Result<Vec<_>, _>>()
            .map_err(|_| {
                Error::Usage(format!(
                    "--levels {}: give levels 0-4 separated by commas, e.g. 0,2,4",
                    self.levels
                ))
            })?;
        let class_rules = self
            .class
            .iter()
            .map(|c| {
                c.split_once('=')
                    .map(|(a, b)| (a.trim().to_string(), b.trim().to_string()))
                    .filter(|(a, b)| !a.is_empty() && !b.is_empty())
                    .ok_or_else(|| {
                        Error::Usage(format!(
                            "--class {c}: expected CLASS=GLOB, e.g. ground=ground*"
                        ))
                    })
            })
            .collect::<Result<Vec<_>>>()?;
        let cfg = StudyConfig {
            trace: crate::glod::study::StudyConfig {
                sampling: crate::rdc::Sampling {
                    ab: self.ab,
                    ad: self.ad,
                    lw: self.lw,
                    ..crate::rdc::Sampling::default()
                },
                mf: 1,
                seed: self.seed,
                occupied: crate::metrics::schedule::parse_range(&self.occupied)?,
                threads: self.threads,
            },
            sigmas: crate::mcop::classes::parse_sigmas(&self.sigmas)?,
            draws: self.draws,
            levels,
            truncation: match self.truncate {
                TruncateArg::Redraw => Truncation::Redraw,
                TruncateArg::Clip => Truncation::Clip,
            },
            grouping: match self.by {
                ByArg::Material => Grouping::Material,
                ByArg::Class => Grouping::Class,
            },
            class_rules,
            materials: self
                .materials
                .as_ref()
                .map(|m| m.split(',').map(|s| s.trim().to_string()).collect()),
            hourly: self.hourly,
            thresholds: Default::default(),
            shard,
        };
        cfg.validate()?;
        Ok(cfg)
    }

    fn sensors(&self) -> Result<Vec<crate::formats::sensors::SensorRay>> {
        crate::formats::sensors::read_sensor_path(&self.pts)
    }

    /// The inputs' checksums, for a shard's manifest.
    fn sums(&self) -> Result<Vec<InputSum>> {
        let mut v = vec![
            InputSum::of_scene_input(&self.weather)?,
            InputSum::of_scene_input(&self.pts)?,
        ];
        for s in &self.scenes {
            v.push(InputSum::of_scene_input(s)?);
        }
        Ok(v)
    }
}

/// Write the tables and plots of `r` into `dir` (created); returns the cell table.
pub fn write_outputs(r: &Results, dir: &str) -> Result<String> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let cells = report::cells_tsv(r);
    let put = |name: &str, bytes: &[u8]| -> Result<()> {
        let path = Path::new(dir).join(name);
        let p = path.display().to_string();
        crate::io::write_atomically(&path, |w| w.write_all(bytes).map_err(|e| Error::io(&p, e)))
    };
    put("cells.tsv", cells.as_bytes())?;
    put("sensors.tsv", report::sensors_tsv(r).as_bytes())?;
    put("convergence.tsv", report::convergence_tsv(r).as_bytes())?;
    put("materials.tsv", report::materials_tsv(r).as_bytes())?;
    put("results.json", (report::json(r)? + "\n").as_bytes())?;
    Ok(cells)
}

/// The plots need the per-draw room TAI: kept from the records.
fn write_plots(r: &Results, records: &[DrawRecord], dir: &str) -> Result<()> {
    let sigma_index = |s: f64| r.sigmas.iter().position(|&x| x == s);
    let draws_of = |level: u8, sigma: f64| -> Vec<f64> {
        let k = sigma_index(sigma);
        records
            .iter()
            .filter(|d| d.level == level && Some(d.sigma_index) == k)
            .map(|d| d.tai.iter().sum::<f64>() / d.tai.len().max(1) as f64)
            .collect()
    };
    let put = |name: &str, bytes: &[u8]| -> Result<()> {
        let path = Path::new(dir).join(name);
        let p = path.display().to_string();
        crate::io::write_atomically(&path, |w| w.write_all(bytes).map_err(|e| Error::io(&p, e)))
    };
    put("boxplot.svg", report::boxplot_svg(r, &draws_of).as_bytes())?;
    if let Some(&top) = r.levels.last() {
        put(
            "convergence.svg",
            report::convergence_svg(r, top).as_bytes(),
        )?;
        for &s in &r.sigmas {
            // A map needs a regular grid of sensors; a scattered set gets none (said once).
            match report::spread_png(r, top, s) {
                Ok(png) => put(&format!("spread_GLoD{top}_s{s:.2}.png"), &png)?,
                Err(e) => {
                    eprintln!("rmcop: no spread map: {e}");
                    break;
                }
            }
        }
    }
    Ok(())
}

/// The manifest's command: the arguments without --shard/--records and their values.
fn command_line() -> Vec<String> {
    let args: Vec<String> = std::env::args().collect();
    super::without_options(&args, &["--shard", "--records"])
}

/// Run `rmcop` with parsed options, writing the cell table to `out`.
pub fn run(opts: &Options, out: &mut dyn Write) -> Result<()> {
    let progress = super::progress::Bars::stderr("rmcop");
    // Between stages: what the bars do not say.
    let note = |what: &str| {
        if crate::io::show_progress() {
            eprintln!("rmcop: {what}");
        }
    };
    match &opts.cmd {
        Cmd::Study {
            inputs,
            out: dir,
            shard,
            records,
        } => {
            let shard = shard
                .as_deref()
                .map(|s| Shard::parse(s, "--shard"))
                .transpose()?;
            let cfg = inputs.config(shard)?;
            if dir.is_none() && records.is_none() {
                return Err(Error::Usage(
                    "rmcop study: give -o DIR for the tables and plots (or --records FILE)".into(),
                ));
            }
            let weather = Weather::read_path(&inputs.weather)?;
            let sensors = inputs.sensors()?;
            let (scene, analysis) = inputs.glod().analyse()?;
            let prep = study::prepare(&scene, &analysis, &weather, &sensors, &cfg, &progress)?;
            for p in &prep.levels {
                note(&format!(
                    "GLoD{}: traced in {:.1} s, {} materials vary",
                    p.level,
                    p.model.trace_seconds,
                    p.props.len()
                ));
            }
            let recs = study::draws(&prep, &cfg, &progress);
            if let Some(path) = records {
                let rows = shard.map_or(0..cfg.draws, |s| s.rows(cfg.draws));
                let file = ShardFile {
                    format: SHARD_FORMAT.into(),
                    manifest: Manifest {
                        tool: "rmcop".into(),
                        version: env!("CARGO_PKG_VERSION").into(),
                        command: command_line(),
                        shard: shard.unwrap_or(Shard { index: 0, count: 1 }),
                        seed: cfg.trace.seed,
                        first_row: rows.start,
                        rows: rows.len(),
                        total_rows: cfg.draws,
                        inputs: inputs.sums()?,
                        // The records are in this very file.
                        output: None,
                    },
                    records: recs.clone(),
                };
                file.write(path)?;
            }
            if shard.is_some() {
                return Ok(());
            }
            let results = study::reduce(&prep, &cfg, &recs)?;
            let cells = match dir {
                Some(d) => {
                    let c = write_outputs(&results, d)?;
                    write_plots(&results, &recs, d)?;
                    c
                }
                None => report::cells_tsv(&results),
            };
            out.write_all(cells.as_bytes()).at_path("<stdout>")
        }
        Cmd::Merge { out: dir, records } => {
            let mut files = Vec::new();
            for r in records {
                files.push((r.clone(), ShardFile::read(r)?));
            }
            let manifests: Vec<(String, Manifest)> = files
                .iter()
                .map(|(p, f)| (p.clone(), f.manifest.clone()))
                .collect();
            check_manifests(&manifests)?;
            // Re-run the preparation from the recorded command (same inputs: checked by
            // their checksums) to get the error-free models, then reduce every record.
            let command = &files[0].1.manifest.command;
            let reparsed =
                crate::cli::parse_or_exit::<Options>(radiance_spellings(command.clone()))?;
            let Cmd::Study { inputs, .. } = &reparsed.cmd else {
                return Err(Error::Mismatch(format!(
                    "{}: the records were not written by rmcop study",
                    files[0].0
                )));
            };
            let sums = inputs.sums()?;
            if sums != files[0].1.manifest.inputs {
                return Err(Error::Mismatch(format!(
                    "{}: the inputs changed since the shards ran (checksums differ); re-run the shards",
                    files[0].0
                )));
            }
            let cfg = inputs.config(None)?;
            let weather = Weather::read_path(&inputs.weather)?;
            let sensors = inputs.sensors()?;
            let (scene, analysis) = inputs.glod().analyse()?;
            let prep = study::prepare(&scene, &analysis, &weather, &sensors, &cfg, &progress)?;
            let mut recs: Vec<DrawRecord> =
                files.into_iter().flat_map(|(_, f)| f.records).collect();
            recs.sort_by_key(|r| (r.level, r.sigma_index, r.draw));
            let results = study::reduce(&prep, &cfg, &recs)?;
            let cells = write_outputs(&results, dir)?;
            write_plots(&results, &recs, dir)?;
            out.write_all(cells.as_bytes()).at_path("<stdout>")
        }
        Cmd::Validate { inputs, noise_runs } => {
            let cfg = inputs.config(None)?;
            let weather = Weather::read_path(&inputs.weather)?;
            let sensors = inputs.sensors()?;
            let (scene, _) = inputs.glod().analyse()?;
            let v = crate::mcop::validate::validate(
                &scene,
                &weather,
                &sensors,
                &cfg,
                cfg.draws,
                *noise_runs,
                &progress,
            )?;
            out.write_all(crate::mcop::validate::table(&v).as_bytes())
                .at_path("<stdout>")?;
            if v.classes.iter().all(|c| c.passed) {
                Ok(())
            } else {
                Err(Error::Mismatch(
                    "re-weighting and re-simulation disagree beyond the measured noise (see the table)"
                        .into(),
                ))
            }
        }
    }
}
