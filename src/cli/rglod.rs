//! # `rglod`'s command line: Geometrical Levels of Detail (the seed's chapter 2)
//!
//! The tools layer's half of `rglod`: clap structs (GNU-style long options; Radiance has no
//! counterpart) and their conversion into [`crate::glod::Options`]; the library finds the
//! objects, their boxes and levels (`rdaylight::glod`), and writes the filtered scene.

use crate::error::{Error, IoContext, Result};
use crate::glod::{self, Analysis, Frame, Grouping, Thresholds};
use crate::scene::{self, LoadOptions, Scene};
use clap::{Args, Parser, Subcommand, ValueEnum};
use std::io::Write;

pub const EXAMPLES: &str = "\
Examples:
    rglod objects room.rad                      one row per object: box, area (m2), level
    rglod objects --json room.rad > objects.json
    rglod objects --by connectivity room.rad    unnamed meshes: touching primitives
    rglod filter -l 2 room.rad > glod2.rad      shell + objects with OBB area >= 2.4 m2
    rglod filter -l 0 room.rad | rinfo -        the permanent shell only
    rdc -I -ab 5 -ad 10000 -lw 1e-5 -faf glod2.rad skydome.rad < sensors.pts > dc2.mtx

Levels (seed section 2.3.1): GLoD0 = permanent shell (walls, floor, ceiling, windows);
GLoD1/2/3 add objects whose smallest oriented bounding box has a surface area of at least
3.0/2.4/0.5 m2 (--thresholds); GLoD4 = everything.";

#[derive(Parser, Debug)]
#[command(
    name = "rglod",
    version,
    propagate_version = true,
    about = "Geometrical Levels of Detail: group a scene into objects, size them by their \
             oriented bounding box, and write the scene at GLoD0-4",
    after_help = EXAMPLES
)]
pub struct Options {
    #[command(subcommand)]
    pub cmd: Cmd,
}

#[derive(Subcommand, Debug)]
pub enum Cmd {
    /// One row per object (TSV; --json): id, primitive count, OBB centre, axes, sizes, area
    /// (m2) and level; the first row counts the permanent shell (level 0).
    Objects {
        /// JSON instead of TSV.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        common: Common,
    },
    /// Write the scene at one level to standard output: the shell, the objects of that level
    /// and below, and the modifiers they still use (an exact subset of the input).
    Filter {
        /// The level, 0 (shell only) to 4 (everything).
        #[arg(short = 'l', long = "level", value_name = "N")]
        level: u8,
        #[command(flatten)]
        common: Common,
    },
    /// A plan view (SVG, north up) of the shell in grey and each object's footprint filled
    /// with its level's colour, with a legend of the thresholds.
    Plan {
        #[command(flatten)]
        common: Common,
    },
    /// The chapter-2 experiment for this room: each level traced once (sky coefficients,
    /// the same seed), TAI per sensor under the weather file's sky (occupied 8-18 h), and per
    /// level the room TAI, PE, MAPE and RMSE against GLoD4 and the trace time (TSV: the
    /// seed's Table 2.4).
    Study {
        /// Weather file (.epw or .wea) for the sky matrix.
        #[arg(short = 'w', long = "weather", value_name = "FILE")]
        weather: String,
        /// Sensor rays (`x y z dx dy dz` per line).
        #[arg(long = "pts", value_name = "FILE")]
        pts: String,
        /// Diffuse bounces (rdc -ab).
        #[arg(long = "ab", value_name = "N", default_value_t = 5)]
        ab: u32,
        /// Samples per sensor (rdc -ad).
        #[arg(long = "ad", value_name = "N", default_value_t = 10000)]
        ad: usize,
        /// Path weight limit (rdc -lw).
        #[arg(value_parser = super::finite, long = "lw", value_name = "W", default_value_t = 1e-5)]
        lw: f64,
        /// Seed, the same for every level.
        #[arg(short = 's', long = "seed", default_value_t = 1)]
        seed: u64,
        /// Worker threads (all cores by default).
        #[arg(short = 'n', value_name = "N")]
        threads: Option<usize>,
        /// Write each level's error map here (the seed's Fig. 2.8): `pe_GLoD{l}.png`, the
        /// per-sensor percentage error of TAI against GLoD4 over the plan.
        #[arg(long, value_name = "DIR")]
        maps: Option<String>,
        #[command(flatten)]
        common: Common,
    },
}

/// Radiance's spellings of the study's sampling options (`-ab 5` for `--ab 5`).
pub fn radiance_spellings(args: impl IntoIterator<Item = String>) -> Vec<String> {
    super::long_spellings(args, &["ab", "ad", "lw"])
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum By {
    /// Identifier up to the first separator (`chair_12.leg_3` -> `chair_12`).
    Prefix,
    /// One object per modifier.
    Modifier,
    /// Primitives sharing vertices within --connect-tol.
    Connectivity,
    /// One object per input file or inline `!command`.
    Source,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameArg {
    /// The coordinate axes.
    Axes,
    /// Turned in plan to the walls (rooms not aligned with x and y).
    Walls,
}

#[derive(Args, Debug)]
pub struct Common {
    /// How primitives form objects.
    #[arg(long, value_enum, default_value = "prefix")]
    pub by: By,
    /// Separator for --by prefix.
    #[arg(long, default_value = ".")]
    pub separator: String,
    /// Distance (m) within which vertices are shared, for --by connectivity.
    #[arg(value_parser = super::finite, long, value_name = "M", default_value_t = 1e-3)]
    pub connect_tol: f64,
    /// Distance (m) within which a polygon lies on an enclosing plane of the room (shell).
    #[arg(value_parser = super::finite, long, value_name = "M", default_value_t = 0.01)]
    pub tolerance: f64,
    /// Axes of the room box whose faces are the enclosing planes.
    #[arg(long, value_enum, default_value = "axes")]
    pub frame: FrameArg,
    /// Identifiers that are always permanent: a glob (`*`, `?`), or a prefix without
    /// wildcards; repeatable.
    #[arg(long, value_name = "GLOB")]
    pub permanent: Vec<String>,
    /// Minimum OBB areas (m2) of GLoD1, GLoD2, GLoD3 (the seed's 3.0, 2.4, 0.5).
    #[arg(long, value_name = "A1,A2,A3", default_value = "3.0,2.4,0.5")]
    pub thresholds: String,
    /// Use this scene's own 75th/50th/25th percentiles of object OBB areas as thresholds
    /// (the seed's derivation, section 2.3.1) instead of --thresholds.
    #[arg(long, conflicts_with = "thresholds")]
    pub percentiles: bool,
    /// Refuse inline `!commands` in scenes (error instead). By default they run, as in
    /// Radiance; also RDAYLIGHT_NO_EXEC=1.
    #[arg(long)]
    pub no_exec: bool,
    /// Scene files, in order (`-` = standard input).
    #[arg(required = true)]
    pub scenes: Vec<String>,
}

/// `--thresholds A1,A2,A3`.
pub fn parse_thresholds(s: &str) -> Result<Thresholds> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| super::finite(x.trim()))
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| {
            Error::Usage(format!(
                "--thresholds {s}: give three areas in m2, e.g. 3.0,2.4,0.5"
            ))
        })?;
    let [glod1, glod2, glod3] = v[..] else {
        return Err(Error::Usage(format!(
            "--thresholds {s}: give three areas in m2, e.g. 3.0,2.4,0.5"
        )));
    };
    let t = Thresholds {
        glod1,
        glod2,
        glod3,
    };
    t.validate()?;
    Ok(t)
}

impl Common {
    /// The library's options.
    pub fn options(&self) -> Result<glod::Options> {
        let grouping = match self.by {
            By::Prefix => Grouping::Prefix(self.separator.clone()),
            By::Modifier => Grouping::Modifier,
            By::Connectivity => Grouping::Connectivity(self.connect_tol),
            By::Source => Grouping::Source,
        };
        let opts = glod::Options {
            grouping,
            frame: match self.frame {
                FrameArg::Axes => Frame::Axes,
                FrameArg::Walls => Frame::Walls,
            },
            tolerance: self.tolerance,
            permanent: self.permanent.clone(),
            thresholds: parse_thresholds(&self.thresholds)?,
        };
        opts.validate()?;
        Ok(opts)
    }

    fn load_options(&self) -> LoadOptions {
        let mut o = LoadOptions::from_env();
        if self.no_exec {
            o.allow_exec = false;
        }
        o
    }

    /// Load the scenes and analyse them (with `--percentiles`, relevelled by the scene's own
    /// area percentiles).
    pub fn analyse(&self) -> Result<(Scene, Analysis)> {
        self.analyse_levels().map(|(s, a, _)| (s, a))
    }

    /// [`Common::analyse`] and the thresholds the levels were assigned with.
    pub fn analyse_levels(&self) -> Result<(Scene, Analysis, glod::Thresholds)> {
        let opts = self.options()?;
        let mut thresholds = opts.thresholds;
        let scene = scene::load(&self.scenes, &self.load_options())?;
        let mut a = glod::analyse(&scene, &opts)?;
        if self.percentiles {
            let areas: Vec<f64> = a.objects.iter().map(|o| o.area).collect();
            let t = glod::percentiles(&areas).ok_or_else(|| {
                Error::Usage(format!(
                    "--percentiles: {} has no non-permanent objects to take percentiles of; \
                     give --thresholds instead",
                    self.scenes.join(" ")
                ))
            })?;
            a.relevel(&t)?;
            thresholds = t;
        }
        Ok((scene, a, thresholds))
    }
}

/// Run `rglod` with parsed options, writing to `out`.
pub fn run(opts: &Options, out: &mut dyn Write) -> Result<()> {
    match &opts.cmd {
        Cmd::Objects { json, common } => {
            let (_, a) = common.analyse()?;
            let text = if *json {
                glod::report::json(&a) + "\n"
            } else {
                glod::report::tsv(&a)
            };
            out.write_all(text.as_bytes()).at_path("<stdout>")
        }
        Cmd::Filter { level, common } => {
            if *level > glod::MAX_LEVEL {
                return Err(Error::Usage(format!(
                    "-l {level}: give a level from 0 (shell only) to 4 (everything)"
                )));
            }
            let (scene, a) = common.analyse()?;
            let kept = glod::filter::filter(&scene, &a, *level)?;
            let n = a.objects.iter().filter(|o| o.level <= *level).count();
            let head = format!(
                "# rglod filter -l {level} {}: GLoD{level}, the shell ({} primitives) and {n} of {} objects\n",
                common.scenes.join(" "),
                a.shell.len(),
                a.objects.len()
            );
            out.write_all(head.as_bytes()).at_path("<stdout>")?;
            kept.write_rad(&mut *out).at_path("<stdout>")?;
            out.write_all(b"\n").at_path("<stdout>")
        }
        Cmd::Plan { common } => {
            let (scene, a, t) = common.analyse_levels()?;
            out.write_all(glod::plan::svg(&scene, &a, &t).as_bytes())
                .at_path("<stdout>")
        }
        Cmd::Study {
            weather,
            pts,
            ab,
            ad,
            lw,
            seed,
            threads,
            maps,
            common,
        } => {
            let cfg = glod::study::StudyConfig {
                sampling: crate::rdc::Sampling {
                    ab: *ab,
                    ad: *ad,
                    lw: *lw,
                    ..crate::rdc::Sampling::default()
                },
                seed: *seed,
                threads: *threads,
                ..glod::study::StudyConfig::default()
            };
            let weather = crate::formats::weather::Weather::read_path(weather)?;
            let sensors = crate::formats::sensors::read_sensor_path(pts)?;
            let (scene, a) = common.analyse()?;
            let progress = super::progress::Bars::stderr("rglod study");
            let results = glod::study::study(&scene, &a, &weather, &sensors, &cfg, &progress)?;
            if let Some(dir) = maps {
                write_maps(dir, &results, &sensors)?;
            }
            out.write_all(glod::study::table(&results).as_bytes())
                .at_path("<stdout>")
        }
    }
}

/// Per-level maps of the per-sensor TAI percentage error against GLoD4 (PNG).
fn write_maps(
    dir: &str,
    results: &[glod::study::LevelResult],
    sensors: &[crate::formats::sensors::SensorRay],
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let Some(top) = results.last() else {
        return Ok(());
    };
    let points: Vec<[f64; 2]> = sensors.iter().map(|s| [s.org[0], s.org[1]]).collect();
    for r in results {
        let pe: Vec<f64> = r
            .tai
            .iter()
            .zip(&top.tai)
            .map(|(&a, &b)| {
                if b > 0.0 {
                    crate::metrics::compare::percentage_error(a, b)
                } else {
                    f64::NAN
                }
            })
            .collect();
        let img = crate::metrics::map::render(
            &points,
            &pe,
            &format!(
                "TAI of GLoD{} against GLoD{} per sensor (seed Fig. 2.8)",
                r.level, top.level
            ),
            "percentage error (%)",
        )?;
        let png = crate::metrics::map::png_bytes(&img)?;
        let path = std::path::Path::new(dir).join(format!("pe_GLoD{}.png", r.level));
        let p = path.display().to_string();
        crate::io::write_atomically(&path, |w| w.write_all(&png).map_err(|e| Error::io(&p, e)))?;
    }
    Ok(())
}
