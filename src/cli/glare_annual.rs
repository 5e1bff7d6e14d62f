//! `rglare annual`: the command line of imageless annual glare ([`super::annual`]).
//!
//! ```text
//! rglare annual -w site.epw -vf view.vf [-vta -vp ... -vd ... -vu ... -vh 180 -vv 180]
//!        [--rays 64] [-b 2000] [-l 0.4] [-C l+] [-P 0|1] [--ev rays|sensor] [--eye-ad 16384]
//!        [--occupied 8-18] [--weekdays [--jan1 DAY]] [--schedule flags.txt]
//!        [-o dgp.txt] [rdc options: -ab 3 -ad 512 -lw 1e-3 -m 1 -s seed -n threads] scene.rad ...
//!        [--views views.txt [--shard K/N [--manifest m.json]]]
//! rglare annual --cat shard.0.txt shard.1.txt ... [--manifests m.0.json ...] [-o dgp.txt]
//! ```
//!
//! Everything not listed goes to `rdc` (its letters and meanings); the view options are
//! rpict's. Output (`-o`, default standard output): `#` lines stating the method,
//! threshold, view, occupancy and the summary (glare autonomy, shares above 0.35/0.40/0.45,
//! EN 17037 class), then one line per weather step in file order:
//! `month day hour DGP Ev Ev_sun nsources sun_in_view DGP_dcglare`.
//!
//! Many views: `--views FILE` holds one view per line (rpict view options, e.g. `-vp 3 1.5
//! 1.2 -vd 0 -1 0`, or a `VIEW=`/`rvu`/`rpict` line; blank and `#` lines skipped), each
//! applied on top of the command line's view options (so the shared `-vta -vh 180 -vv 180
//! -vu 0 0 1` are given once). The output is one section per view, in file order, each
//! opened by `# view I of M (0-based; FILE line L)` and then the single-view report. Each
//! view is traced with the same seed on its own, so its section does not depend on the
//! other views: `--shard K/N` computes views `Shard::rows` (0-based K, the split of
//! `rdc --shard`) and writes them framed as a text shard (`# SHARD=`, `# COMMAND=`, the
//! sections, `# END=` with their size and FNV-1a hash; `formats::shard::text_preamble`);
//! `rglare annual --cat` of all N shards checks them and writes the sections one after the
//! other: the unsharded run's bytes. `--manifest` as for `rdc --shard` (rows = views).

use crate::error::{Error, Location, Result};
use crate::formats::shard::{HashingWriter, InputSum, Manifest, Shard, ShardInfo};
use crate::formats::view::{View, is_view_line};
use crate::formats::weather::Weather;
use crate::glare::annual::{self, AnnualOptions, Summary};
use crate::glare::viewrays::ViewRays;
use crate::glare::{PosModel, annual::StepResult};
use clap::Parser;
use rdaylight_metrics::schedule::{ScheduleSpec, parse_range};
use std::io::Write;

const USAGE: &str = "usage: rglare annual -w weather.epw|.wea [view options] [--views FILE [--shard K/N [--manifest FILE]]] [--rays N] [-b thres] [-l limit] [-C l+] [-P 0|1] [--ev rays|sensor] [--eye-ad N] [--occupied A-B] [--weekdays [--jan1 DAY]] [--schedule FILE] [-o out.txt] [rdc options] scene.rad ...; or rglare annual --cat shard.txt ... [--manifests m.json ...] [-o out.txt]";

pub const EXAMPLES: &str = "\
Examples:
  Annual DGP of one seated view over the London year (the main job's weather file):
    rglare annual -w site.epw -vta -vp 3 1.5 1.2 -vd 0 -1 0 -vu 0 0 1 -vh 180 -vv 180 \\
        -ab 3 -ad 512 -lw 1e-3 -o dgp.txt room.rad
  The same for a view file and office hours on weekdays only:
    rglare annual -w site.epw -vf eye.vf --occupied 8-18 --weekdays room.rad > dgp.txt
  Many views as 3 shards (e.g. Slurm array tasks), merged into the unsharded output:
    for k in 0 1 2; do
      rglare annual -w site.epw --views views.txt --shard $k/3 --manifest m.$k.json \\
          -o g.$k.txt room.rad
    done
    rglare annual --cat g.0.txt g.1.txt g.2.txt --manifests m.0.json m.1.json m.2.json \\
        -o glare.txt";

/// `rglare annual`'s options as clap describes them (`--help`, the man page, completions);
/// the parser is [`AnnualArgs::parse`], which passes every option not named here to `rdc`
/// (a test checks that it takes each one named here).
pub fn command() -> clap::Command {
    use clap::{Arg, ArgAction, Command, ValueHint};
    let value = |id: &'static str, name: &'static str, help: &'static str| {
        Arg::new(id).long(id).value_name(name).help(help)
    };
    Command::new("annual")
        .version(env!("CARGO_PKG_VERSION"))
        .about("Imageless annual glare (DGP per weather step) from daylight coefficients")
        .long_about(
            "Imageless DGP per weather step (dcglare's counterpart) from daylight coefficients \
             of a grid of view rays (--rays N per side) and the exact sun disc. The rdc \
             options (-ab -ad -lw -m MF -s seed -n threads) set the sampling; every option not \
             listed here goes to rdc. View options are rpict's (-vf file, -vta -vp x y z -vd \
             dx dy dz -vu ux uy uz -vh 180 -vv 180).\n\n\
             Output (-o, default standard output): '#' lines (method, threshold, view, \
             occupancy, glare autonomy, shares above 0.35/0.40/0.45, EN 17037 class), then \
             per step: month day hour DGP Ev Ev_sun nsources sun_in_view DGP_dcglare.\n\n\
             Many views: --views FILE, one line of view options per view on top of the \
             command line's (e.g. -vp 3 1.5 1.2 -vd 0 -1 0); one section per view. --shard \
             K/N computes the K-th (0-based) of N blocks of views as a checked text shard, \
             --manifest FILE describes it; rglare annual --cat of all N shards (with \
             --manifests) equals the unsharded output byte for byte.",
        )
        .override_usage(
            "rglare annual -w weather.epw|.wea [view options] [--views FILE [--shard K/N \
             [--manifest FILE]]] [options] [rdc options] scene.rad ...\n       \
             rglare annual --cat shard.txt ... [--manifests m.json ...] [-o out.txt]",
        )
        .disable_help_flag(true)
        .disable_version_flag(true)
        .arg(
            Arg::new("help")
                .long("help")
                .action(ArgAction::Help)
                .help("Print help"),
        )
        .arg(
            Arg::new("version")
                .long("version")
                .action(ArgAction::Version)
                .help("Print version"),
        )
        .arg(
            value("weather", "FILE", "Weather file, EPW or .wea (required)")
                .short('w')
                .value_hint(ValueHint::FilePath),
        )
        .arg(
            value(
                "views",
                "FILE",
                "One view per line (rpict view options or a VIEW= line), on top of the \
                 command line's view options; one output section per view",
            )
            .value_hint(ValueHint::FilePath),
        )
        .arg(
            value(
                "temporal",
                "FILE",
                "Temporal map (day of year x hour) of each view's DGP, .png or .svg; with \
                 several views, FILE gets -viewN before its extension",
            )
            .value_hint(ValueHint::FilePath),
        )
        .arg(value(
            "temporal-range",
            "LO,HI",
            "DGP scale of the temporal map (default 0.2,0.6: imperceptible below 0.35, \
             intolerable above 0.45)",
        ))
        .arg(value(
            "shard",
            "K/N",
            "Only the K-th (0-based) of N blocks of views, framed as a checked text shard",
        ))
        .arg(
            value("manifest", "FILE", "With --shard: the shard's manifest (JSON)")
                .value_hint(ValueHint::FilePath),
        )
        .arg(value(
            "rays",
            "N",
            "View rays per side of the grid (default 64, at most 1024)",
        ))
        .arg(value(
            "eye-ad",
            "N",
            "Samples of the eye sensor's coefficients (default 16384)",
        ))
        .arg(
            Arg::new("threshold")
                .short('b')
                .value_name("F")
                .help("Glare source threshold: > 100 absolute cd/m2, else F x Ev/pi (default 2000)"),
        )
        .arg(
            Arg::new("limit")
                .short('l')
                .value_name("DGP")
                .help("DGP limit of glare autonomy (default 0.4)"),
        )
        .arg(
            Arg::new("low-light")
                .short('C')
                .value_name("l+|l-|0")
                .value_parser(["l+", "l-", "0"])
                .hide_possible_values(true)
                .help("evalglare's low-light correction on (l+) or off (l-, 0; default)"),
        )
        .arg(
            Arg::new("position")
                .short('P')
                .value_name("0|1")
                .value_parser(["0", "1"])
                .hide_possible_values(true)
                .help("Position index model: 0 Guth/Iwata (default), 1 Kim"),
        )
        .arg(
            value(
                "ev",
                "rays|sensor",
                "Vertical illuminance from the view rays (default) or the eye sensor",
            )
            .value_parser(["rays", "sensor"])
            .hide_possible_values(true),
        )
        .arg(value(
            "sun-angle",
            "DEG",
            "Apex angle of the sun disc in degrees (default 0.533)",
        ))
        .arg(value(
            "occupied",
            "A-B",
            "Occupied hours, A included and B not (default 8-18)",
        ))
        .arg(
            Arg::new("weekdays")
                .long("weekdays")
                .action(ArgAction::SetTrue)
                .help("Occupied on weekdays only"),
        )
        .arg(value(
            "jan1",
            "DAY",
            "With --weekdays: the weekday of 1 January (e.g. Monday; default from an EPW's DATA PERIODS)",
        ))
        .arg(
            value("schedule", "FILE", "Occupancy flags, one line per weather step")
                .value_hint(ValueHint::FilePath),
        )
        .arg(
            Arg::new("output")
                .short('o')
                .value_name("FILE")
                .value_hint(ValueHint::FilePath)
                .help("Output file, written atomically (default standard output)"),
        )
        .arg(
            Arg::new("cat")
                .long("cat")
                .action(ArgAction::SetTrue)
                .help("Merge the text shards of --shard runs (all N, in order) into the unsharded output"),
        )
        .arg(
            Arg::new("manifests")
                .long("manifests")
                .value_name("JSON")
                .num_args(1..)
                .value_hint(ValueHint::FilePath)
                .help("With --cat: the shards' manifests, in the same order"),
        )
        .arg(
            Arg::new("no-exec")
                .long("no-exec")
                .action(ArgAction::SetTrue)
                .help(
                    "Refuse inline `!commands` in scene files (error instead). By default they \
                     run, as in Radiance; also RDAYLIGHT_NO_EXEC=1",
                ),
        )
        .arg(
            Arg::new("scene")
                .value_name("SCENE")
                .num_args(0..)
                .value_hint(ValueHint::FilePath)
                .help("Scene files (.rad), as for rdc"),
        )
        .after_help(EXAMPLES)
}

/// Parsed `rglare annual` command line.
#[derive(Debug, Clone)]
pub struct AnnualArgs {
    pub view: View,
    pub weather: String,
    pub grid: usize,
    pub eye_ad: usize,
    pub opts: AnnualOptions,
    pub schedule: ScheduleSpec,
    pub out: Option<String>,
    pub rdc: super::rdc::Options,
    /// `--views FILE`: one view per line on top of `view`.
    pub views: Option<String>,
    /// `--temporal FILE`: day x hour map of DGP per view; `--temporal-range`.
    pub temporal: Option<String>,
    pub temporal_range: (f64, f64),
    /// `--shard K/N`: only these views, framed as a text shard.
    pub shard: Option<Shard>,
    /// `--manifest FILE` (with `--shard`).
    pub manifest: Option<String>,
    /// `rglare annual` and the arguments without `--shard`, `--manifest` and `-o` (where
    /// a piece goes, not what it is): the unsharded run's command, for the shard frame and
    /// the manifest.
    pub command: Vec<String>,
    /// Files named by `-vf` on the command line (hashed into manifests).
    pub view_files: Vec<String>,
}

fn value<'a>(args: &'a [String], i: usize, opt: &str) -> Result<&'a str> {
    args.get(i)
        .map(String::as_str)
        .ok_or_else(|| Error::Usage(format!("{opt} needs a value; {USAGE}")))
}

/// Most view rays per side (`--rays`): 1024 x 1024 rays already resolve a 180° view to
/// 0.18°, a third of the sun's disc, and each ray holds a row of sky coefficients.
const MAX_RAYS: usize = 1024;

/// A whole number from 1 to `max` (`--rays`, `--eye-ad`): a count, so neither a fraction
/// nor a value that would run for ever (issue #19: `--eye-ad 1e15`).
fn count(args: &[String], i: usize, opt: &str, max: usize, why: &str) -> Result<usize> {
    let v = number(args, i, opt)?;
    if v < 1.0 || v.fract() != 0.0 {
        return Err(Error::Usage(format!(
            "{opt}: '{}' is not a whole number >= 1",
            args[i]
        )));
    }
    // Saturating: anything beyond u64 is beyond every limit.
    crate::error::at_most(opt, v as u64, max as u64, why)?;
    Ok(v as usize)
}

fn number(args: &[String], i: usize, opt: &str) -> Result<f64> {
    let v = value(args, i, opt)?;
    v.parse::<f64>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| Error::Usage(format!("{opt}: '{v}' is not a number")))
}

impl AnnualArgs {
    /// Parse the arguments after `annual`.
    pub fn parse(raw: &[String]) -> Result<AnnualArgs> {
        let mut view = View::default();
        let rest = view.extract_args(raw)?;
        let mut weather = None;
        let mut grid = 64usize;
        let mut eye_ad = 16384usize;
        let mut opts = AnnualOptions::default();
        let mut schedule = ScheduleSpec {
            occupied: Some((8.0, 18.0)),
            ..ScheduleSpec::default()
        };
        let mut out = None;
        let mut views = None;
        let mut temporal = None;
        let mut temporal_range = DGP_RANGE;
        let mut shard = None;
        let mut manifest = None;
        let mut pass = vec!["rdc".to_string()];
        let mut i = 0;
        while i < rest.len() {
            let a = rest[i].as_str();
            match a {
                "-w" | "--weather" => {
                    i += 1;
                    weather = Some(value(&rest, i, a)?.to_string());
                }
                "--rays" => {
                    i += 1;
                    let why = "a 1024 x 1024 grid resolves a 180 degree view to 0.18 degrees";
                    grid = count(&rest, i, a, MAX_RAYS, why)?;
                }
                "--eye-ad" => {
                    i += 1;
                    let why = "2^24 samples: standard error 1/4096 of one sample's spread";
                    eye_ad = count(&rest, i, a, crate::rdc::config::MAX_AD, why)?;
                }
                "-b" => {
                    i += 1;
                    opts.threshold = number(&rest, i, a)?;
                    if opts.threshold <= 0.0 {
                        return Err(Error::Usage("-b: the threshold must be > 0".into()));
                    }
                }
                "-l" => {
                    i += 1;
                    opts.limit = number(&rest, i, a)?;
                }
                "-C" => {
                    i += 1;
                    opts.low_light = match value(&rest, i, a)? {
                        "l+" => true,
                        "l-" | "0" => false,
                        other => {
                            return Err(Error::Usage(format!(
                                "-C: expected l+, l- or 0, found {other}"
                            )));
                        }
                    };
                }
                "-P" => {
                    i += 1;
                    opts.model = if number(&rest, i, a)? as i64 == 1 {
                        PosModel::Kim
                    } else {
                        PosModel::GuthIwata
                    };
                }
                "--ev" => {
                    i += 1;
                    opts.ev_from_rays = match value(&rest, i, a)? {
                        "rays" => true,
                        "sensor" => false,
                        other => {
                            return Err(Error::Usage(format!(
                                "--ev: expected rays or sensor, found {other}"
                            )));
                        }
                    };
                }
                "--occupied" => {
                    i += 1;
                    schedule.occupied = Some(parse_range(value(&rest, i, a)?)?);
                }
                "--weekdays" => schedule.weekdays = true,
                "--jan1" => {
                    i += 1;
                    schedule.jan1 = Some(value(&rest, i, a)?.to_string());
                }
                "--schedule" => {
                    i += 1;
                    schedule.flags = Some(value(&rest, i, a)?.to_string());
                }
                "-o" => {
                    i += 1;
                    out = Some(value(&rest, i, a)?.to_string());
                }
                "--views" => {
                    i += 1;
                    views = Some(value(&rest, i, a)?.to_string());
                }
                "--temporal" => {
                    i += 1;
                    temporal = Some(value(&rest, i, a)?.to_string());
                }
                "--temporal-range" => {
                    i += 1;
                    temporal_range = crate::metrics::config::parse_pair(value(&rest, i, a)?, a)?;
                }
                "--shard" => {
                    i += 1;
                    shard = Some(Shard::parse(value(&rest, i, a)?, a)?);
                }
                "--manifest" => {
                    i += 1;
                    manifest = Some(value(&rest, i, a)?.to_string());
                }
                "--sun-angle" => {
                    i += 1;
                    opts.sun_angle = number(&rest, i, a)?;
                    pass.push(a.to_string());
                    pass.push(rest[i].clone());
                }
                "--suns" | "-I" | "-I+" | "--direct" | "-x" | "-y" => {
                    return Err(Error::Usage(format!(
                        "{a}: rglare annual chooses the rdc runs itself; give only the scene and sampling options"
                    )));
                }
                _ => pass.push(a.to_string()),
            }
            i += 1;
        }
        let weather =
            weather.ok_or_else(|| Error::Usage(format!("no weather file (-w FILE); {USAGE}")))?;
        if rest.len() == raw.len() && views.is_none() {
            return Err(Error::Usage(format!(
                "no view: give -vf FILE or -vta -vp x y z -vd dx dy dz -vu ux uy uz -vh 180 -vv 180, or --views FILE; {USAGE}"
            )));
        }
        if manifest.is_some() && shard.is_none() {
            return Err(Error::Usage(
                "--manifest describes a shard: it needs --shard K/N (0/1 for a whole run)".into(),
            ));
        }
        let rdc_args: Vec<String> = std::iter::once("rdc".to_string())
            .chain(super::rdc::radiance_args(&pass[1..]))
            .collect();
        // One line, as every usage error (clap's own text is a block).
        let rdc = super::rdc::Options::try_parse_from(rdc_args)
            .map_err(|e| Error::Usage(format!("rdc options: {}", super::usage_error(e))))?;
        if rdc.scene.is_empty() {
            return Err(Error::Usage(format!("no scene files; {USAGE}")));
        }
        schedule.weather = Some(weather.clone());
        let command = ["rglare".to_string(), "annual".to_string()]
            .into_iter()
            .chain(super::without_options(
                raw,
                &["--shard", "--manifest", "-o", "--temporal"],
            ))
            .collect();
        let view_files = raw
            .windows(2)
            .filter(|w| w[0] == "-vf")
            .map(|w| w[1].clone())
            .collect();
        Ok(AnnualArgs {
            view,
            weather,
            grid,
            eye_ad,
            opts,
            schedule,
            out,
            rdc,
            views,
            temporal,
            temporal_range,
            shard,
            manifest,
            command,
            view_files,
        })
    }
}

/// The `#` lines and one line per step.
pub fn report(
    args: &AnnualArgs,
    rays: &ViewRays,
    weather: &Weather,
    results: &[StepResult],
    summary: &Summary,
    rule: &str,
) -> String {
    use std::fmt::Write as _;
    let o = &args.opts;
    let mut s = String::new();
    let thr = if o.threshold > annual::THRESHOLD_FACTOR_LIMIT {
        format!("{} cd/m2 (fixed threshold)", o.threshold)
    } else {
        format!("{} x Ev/pi (factor threshold, dcglare's rule)", o.threshold)
    };
    let samp = Some(args.rdc.sampling());
    let _ = writeln!(
        s,
        "# rglare annual: imageless DGP from daylight coefficients"
    );
    let _ = writeln!(
        s,
        "# method: {} view rays ({}x{} grid), sky MF {}, -ab {} -ad {}; Ev from {}; eye sensor -ad {}; sun disc {} deg exact (DDS)",
        rays.len(),
        rays.n,
        rays.n,
        args.rdc.mf.unwrap_or(1),
        samp.map_or(0, |s| s.ab),
        samp.map_or(0, |s| s.ad),
        if o.ev_from_rays {
            "the view rays"
        } else {
            "the eye sensor"
        },
        args.eye_ad,
        o.sun_angle
    );
    let _ = writeln!(
        s,
        "# glare sources: view rays above {thr}, 8-connected rays merged, plus the sun disc; Guth/Iwata position index; DGP Wienold & Christoffersen 2006, low-light correction {}",
        if o.low_light { "on" } else { "off" }
    );
    let _ = writeln!(s, "# {}", rays.camera.view().header_line());
    let _ = writeln!(
        s,
        "# weather: {} ({} steps)",
        args.weather,
        weather.steps.len()
    );
    let _ = writeln!(s, "# occupied: {rule}; {} steps", summary.occupied);
    let _ = writeln!(
        s,
        "# glare autonomy (DGP < {}): {:.4}",
        summary.limit, summary.autonomy
    );
    let _ = writeln!(
        s,
        "# share of occupied steps with DGP > 0.35: {:.4}  > 0.40: {:.4}  > 0.45: {:.4}",
        summary.above[0], summary.above[1], summary.above[2]
    );
    let _ = writeln!(
        s,
        "# EN 17037 glare protection (limit exceeded in <= 5 % of occupied steps): {}",
        summary.en17037
    );
    let _ = writeln!(
        s,
        "# DGP_dcglare: dcglare's enhanced simplified DGP from the eye sensor alone (sky patches seen directly as sources, sun spread over patches), for comparison"
    );
    let _ = writeln!(
        s,
        "# month day hour DGP Ev Ev_sun nsources sun_in_view DGP_dcglare"
    );
    for (st, r) in weather.steps.iter().zip(results) {
        let _ = writeln!(
            s,
            "{} {} {} {:.4} {:.1} {:.1} {} {} {:.4}",
            st.month,
            st.day,
            st.hour,
            r.dgp,
            r.ev,
            r.ev_sun,
            r.nsources,
            u8::from(r.sun_in_view),
            r.dgp_dcglare
        );
    }
    s
}

/// One view of the run: the view, and its `--views` line (file line number) if any.
struct ViewItem {
    view: View,
    line: Option<usize>,
}

impl AnnualArgs {
    /// The views in order: the command line's, or one per line of `--views` on top of it.
    fn view_items(&self) -> Result<Vec<ViewItem>> {
        let Some(path) = &self.views else {
            return Ok(vec![ViewItem {
                view: self.view,
                line: None,
            }]);
        };
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let mut items = Vec::new();
        for (k, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let loc = Location::line(path, k + 1);
            let mut view = self.view;
            let applied = if is_view_line(line) {
                view.apply_line(line, &loc)?
            } else {
                view.apply_value(line, &loc)?
            };
            if applied == 0 {
                return Err(Error::parse(
                    loc,
                    "no view options on this line: expected e.g. -vp x y z -vd dx dy dz",
                ));
            }
            items.push(ViewItem {
                view,
                line: Some(k + 1),
            });
        }
        if items.is_empty() {
            return Err(Error::parse(
                Location::file(path),
                "no views: expected one line of view options per view",
            ));
        }
        Ok(items)
    }

    /// Every file the run reads, hashed for a shard's manifest.
    fn input_sums(&self) -> Result<Vec<InputSum>> {
        let mut files: Vec<&String> = self.rdc.scene.iter().collect();
        files.push(&self.weather);
        files.extend(&self.views);
        files.extend(&self.view_files);
        files.extend(&self.schedule.flags);
        files.iter().map(|f| InputSum::of_scene_input(f)).collect()
    }
}

/// `rglare annual --cat shard... [--manifests m...] [-o out]`: the unsharded output.
fn merge(raw: &[String]) -> Result<()> {
    let (mut shards, mut manifests, mut out) = (Vec::new(), Vec::new(), None);
    let mut in_manifests = false;
    let mut i = 0;
    while i < raw.len() {
        match raw[i].as_str() {
            "--manifests" => in_manifests = true,
            "-o" => {
                i += 1;
                out = Some(value(raw, i, "-o")?.to_string());
            }
            a if a.starts_with('-') && a.len() > 1 => {
                return Err(Error::Usage(format!(
                    "rglare annual --cat: unknown option {a}; usage: rglare annual --cat \
                     shard.txt ... [--manifests m.json ...] [-o out.txt]"
                )));
            }
            a if in_manifests => manifests.push(a.to_string()),
            a => shards.push(a.to_string()),
        }
        i += 1;
    }
    let write = |w: &mut dyn Write| {
        crate::formats::shard::merge_text_shards(&shards, &manifests, "views", w)
    };
    write_output(out.as_deref(), write)
}

/// Write to file `out` atomically, or to standard output.
fn write_output(out: Option<&str>, f: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
    match out {
        Some(p) if p != "-" => crate::io::write_atomically(std::path::Path::new(p), f),
        _ => {
            let stdout = std::io::stdout();
            let mut o = std::io::BufWriter::new(stdout.lock());
            f(&mut o)?;
            o.flush().map_err(|e| Error::io("<stdout>", e))
        }
    }
}

/// Default DGP scale of the temporal map: glare is imperceptible below 0.35 and
/// intolerable above 0.45 (Wienold 2009's classes), so 0.2-0.6 shows both ends.
const DGP_RANGE: (f64, f64) = (0.2, 0.6);

/// The temporal map's file for view `i` of `n`: `FILE` itself for one view, else `-viewI`
/// before the extension.
fn temporal_path(file: &str, i: usize, n: usize) -> String {
    if n <= 1 {
        return file.to_string();
    }
    let p = std::path::Path::new(file);
    match (p.file_stem(), p.extension()) {
        (Some(stem), Some(ext)) => p
            .with_file_name(format!(
                "{}-view{i}.{}",
                stem.to_string_lossy(),
                ext.to_string_lossy()
            ))
            .display()
            .to_string(),
        _ => format!("{file}-view{i}"),
    }
}

/// Run `rglare annual` with the arguments after `annual`.
pub fn run(raw: &[String]) -> Result<()> {
    if raw.iter().any(|a| a == "--version") {
        println!("rglare {}", env!("CARGO_PKG_VERSION"));
        return Ok(());
    }
    if raw.iter().any(|a| a == "--help" || a == "-help") {
        println!("{}", command().name("rglare annual").render_long_help());
        return Ok(());
    }
    if raw.first().map(String::as_str) == Some("--cat") {
        return merge(&raw[1..]);
    }
    let args = AnnualArgs::parse(raw)?;
    let weather = Weather::read_path(&args.weather)?;
    let sched = args.schedule.build(weather.steps.len(), &args.weather)?;
    let items = args.view_items()?;
    let shown = args.shard.map_or(0..items.len(), |s| s.rows(items.len()));
    let progress = super::progress::Bars::stderr("rglare annual");
    let base = args.rdc.to_config()?;
    let mut load = crate::scene::LoadOptions::from_env();
    load.allow_exec &= !args.rdc.no_exec;
    let scene = crate::scene::load(&args.rdc.scene, &load)?;
    // One view's section; the same bytes whichever other views the run computes.
    let section = |i: usize| -> Result<String> {
        let item = &items[i];
        let rays = ViewRays::new(&item.view, args.grid)?;
        let c = annual::coefficients(&base, &scene, &rays, &args.weather, args.eye_ad, &progress)?;
        let results = annual::evaluate(&c, &rays, &weather, &args.opts, &progress)?;
        let summary = annual::summary(&results, &sched.occupied, args.opts.limit);
        if let Some(file) = &args.temporal {
            let stamps = crate::metrics::schedule::stamps_from_weather(&weather);
            let dgp: Vec<f64> = results.iter().map(|r| r.dgp).collect();
            let fig = crate::metrics::figures::TemporalFigure {
                title: format!("Daylight glare probability through the year, view {i}"),
                subtitle: format!(
                    "{}; DGP >= {} counts against glare autonomy; box: occupied hours",
                    args.weather, args.opts.limit
                ),
                unit: "DGP".into(),
                stamps: &stamps,
                values: &dgp,
                range: args.temporal_range,
                palette: crate::metrics::plot::Palette::Viridis,
                occupied: args.schedule.occupied,
            };
            fig.check()?;
            crate::metrics::plot::write(&fig, &temporal_path(file, i, items.len()))?;
        }
        let mut text = match (&args.views, item.line) {
            (Some(f), Some(l)) => {
                format!("# view {i} of {} (0-based; {f} line {l})\n", items.len())
            }
            _ => String::new(),
        };
        text += &report(&args, &rays, &weather, &results, &summary, &sched.rule);
        Ok(text)
    };
    let body = |w: &mut dyn Write| -> Result<()> {
        for i in shown.clone() {
            let text = section(i)?;
            w.write_all(text.as_bytes())
                .map_err(|e| Error::io(args.out.as_deref().unwrap_or("<stdout>"), e))?;
        }
        Ok(())
    };
    let name = args.out.clone().unwrap_or_else(|| "<stdout>".into());
    write_output(args.out.as_deref(), |w| match args.shard {
        None => body(w),
        Some(shard) => {
            let info = ShardInfo {
                shard,
                first: shown.start,
                total: items.len(),
            };
            let head = crate::formats::shard::text_preamble(&info, &args.command);
            w.write_all(head.as_bytes())
                .map_err(|e| Error::io(&name, e))?;
            let mut hw = HashingWriter::new(&mut *w);
            body(&mut hw)?;
            let tail = hw.trailer();
            w.write_all(tail.as_bytes())
                .map_err(|e| Error::io(&name, e))
        }
    })?;
    if let (Some(path), Some(shard)) = (&args.manifest, args.shard) {
        Manifest {
            tool: "rglare annual".into(),
            version: env!("CARGO_PKG_VERSION").into(),
            command: args.command.clone(),
            shard,
            seed: base.seed,
            first_row: shown.start,
            rows: shown.len(),
            total_rows: items.len(),
            inputs: args.input_sums()?,
            // The text shard's own `# END=` line checks its body.
            output: None,
        }
        .write(path)?;
    }
    Ok(())
}
