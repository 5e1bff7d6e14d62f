//! `rglare annual`: the command line of imageless annual glare ([`super::annual`]).
//!
//! ```text
//! rglare annual -w site.epw -vf view.vf [-vta -vp ... -vd ... -vu ... -vh 180 -vv 180]
//!        [--rays 64] [-b 2000] [-l 0.4] [-C l+] [-P 0|1] [--ev rays|sensor] [--eye-ad 16384]
//!        [--occupied 8-18] [--weekdays [--jan1 DAY]] [--schedule flags.txt]
//!        [-o dgp.txt] [rdc options: -ab 3 -ad 512 -lw 1e-3 -m 1 -s seed -n threads] scene.rad ...
//! ```
//!
//! Everything not listed goes to `rdc` (its letters and meanings); the view options are
//! rpict's. Output (`-o`, default standard output): `#` lines stating the method,
//! threshold, view, occupancy and the summary (glare autonomy, shares above 0.35/0.40/0.45,
//! EN 17037 class), then one line per weather step in file order:
//! `month day hour DGP Ev Ev_sun nsources sun_in_view DGP_dcglare`.

use crate::error::{Error, Result};
use crate::formats::view::View;
use crate::formats::weather::Weather;
use crate::glare::annual::{self, AnnualOptions, Summary};
use crate::glare::viewrays::ViewRays;
use crate::glare::{PosModel, annual::StepResult};
use clap::Parser;
use rdaylight_metrics::schedule::{ScheduleSpec, parse_range};
use std::io::Write;

const USAGE: &str = "usage: rglare annual -w weather.epw|.wea [view options] [--rays N] [-b thres] [-l limit] [-C l+] [-P 0|1] [--ev rays|sensor] [--eye-ad N] [--occupied A-B] [--weekdays [--jan1 DAY]] [--schedule FILE] [-o out.txt] [rdc options] scene.rad ...";

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
        if rest.len() == raw.len() {
            return Err(Error::Usage(format!(
                "no view: give -vf FILE or -vta -vp x y z -vd dx dy dz -vu ux uy uz -vh 180 -vv 180; {USAGE}"
            )));
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
        Ok(AnnualArgs {
            view,
            weather,
            grid,
            eye_ad,
            opts,
            schedule,
            out,
            rdc,
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

/// Run `rglare annual` with the arguments after `annual`.
pub fn run(raw: &[String]) -> Result<()> {
    if raw.iter().any(|a| a == "--version") {
        println!("rglare {}", env!("CARGO_PKG_VERSION"));
        return Ok(());
    }
    if raw.iter().any(|a| a == "--help" || a == "-help") {
        println!(
            "{USAGE}\n\nImageless DGP per weather step (dcglare's counterpart) from daylight coefficients \
             of a grid of view rays (--rays N per side) and the exact sun disc. The rdc options \
             (-ab -ad -lw -m MF -s seed -n threads) set the sampling. Output: '#' lines (method, \
             threshold, view, occupancy, glare autonomy, shares above 0.35/0.40/0.45, EN 17037 \
             class), then per step: month day hour DGP Ev Ev_sun nsources sun_in_view DGP_dcglare.\n\n\
             --no-exec  refuse inline `!commands` in scene files (error instead). By default they \
             run, as in Radiance; also RDAYLIGHT_NO_EXEC=1."
        );
        return Ok(());
    }
    let args = AnnualArgs::parse(raw)?;
    let weather = Weather::read_path(&args.weather)?;
    let sched = args.schedule.build(weather.steps.len(), &args.weather)?;
    let rays = ViewRays::new(&args.view, args.grid)?;
    let show = crate::io::show_progress();
    let progress = |what: &str| {
        if show {
            eprintln!("rglare annual: {what}");
        }
    };
    let base = args.rdc.to_config()?;
    let mut load = crate::scene::LoadOptions::from_env();
    load.allow_exec &= !args.rdc.no_exec;
    let scene = crate::scene::load(&args.rdc.scene, &load)?;
    let c = annual::coefficients(&base, &scene, &rays, &args.weather, args.eye_ad, &progress)?;
    progress("time steps");
    let results = annual::evaluate(&c, &rays, &weather, &args.opts)?;
    let summary = annual::summary(&results, &sched.occupied, args.opts.limit);
    let text = report(&args, &rays, &weather, &results, &summary, &sched.rule);
    match args.out.as_deref() {
        Some(p) if p != "-" => crate::io::write_atomically(std::path::Path::new(p), |w| {
            w.write_all(text.as_bytes()).map_err(|e| Error::io(p, e))
        }),
        _ => {
            let stdout = std::io::stdout();
            let mut o = stdout.lock();
            o.write_all(text.as_bytes())
                .and_then(|_| o.flush())
                .map_err(|e| Error::io("<stdout>", e))
        }
    }
}
