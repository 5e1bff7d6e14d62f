//! `rglare`'s command line, evalglare-style: `rglare [options] [view options] pic.hdr ...`
//! (standard input when no picture is named). What the binary does lives here so it can be
//! tested without a process.
//!
//! | option | evalglare | meaning |
//! |---|---|---|
//! | `-d` | same | detailed output (source table + 23 values) |
//! | `-V` | same | vertical illuminance only |
//! | `-c file` | same | check picture (one input picture only) |
//! | `-b f` | same | threshold: > 100 absolute cd/m², else f × task (or mean) luminance |
//! | `-r rad` | same | search radius (default 0.2) |
//! | `-y` / `-x` / `-Y L` | same | peak extraction on (default) / off / on with limit L |
//! | `-s` | same | smoothing |
//! | `-t x y r`, `-T x y r` | same | task area (pixel x, y from the bottom as evalglare; opening r rad) |
//! | `-C l+` / `-C l-` / `-C 0` | same | low-light correction on / off (default off) / off |
//! | `-q 0/1/2` | same | background luminance |
//! | `-P 0/1` | same | position index model (Guth/Iwata, Kim) |
//! | `-w a1 a2 a3 a4 a5 c1 c2 c3` | same | DGP coefficients |
//! | `-vf file`, `-vt? -vh -vv -vd -vu -vp …` | same | view, replacing the header's |
//!
//! Several pictures give one result per picture, in input order, evaluated in parallel;
//! a file or standard input may hold a stream of pictures one after another.
//! `rglare annual ...` is imageless annual glare ([`super::annual_cli`]).
//! The detection method and threshold go to stderr (one line per picture), so standard
//! output stays what evalglare prints.

use crate::error::{Error, Result};
use crate::formats::picture::Picture;
use crate::formats::view::View;
use crate::glare::{Background, Options, PosModel, evaluate_pixels, picture_view, report};
use std::io::Write;

/// Output kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Output {
    Default,
    Detailed,
    Ev,
}

/// Parsed command line.
#[derive(Debug, Clone)]
pub struct Args {
    opts: Options,
    output: Output,
    check: Option<String>,
    view: Option<View>,
    files: Vec<String>,
}

const USAGE: &str = "usage: rglare [-d|-V] [-c check.hdr] [-b thres] [-r radius] [-y|-x|-Y limit] [-s] [-t|-T x y r] [-C l+|l-|0] [-q 0|1|2] [-P 0|1] [-w a1 a2 a3 a4 a5 c1 c2 c3] [view options] [picture ...]; or rglare annual ... (rglare annual --help)";

pub const EXAMPLES: &str = "\
Examples:
  Glare of a fisheye picture rendered with rdc (evalglare's output line):
    rdc -vta -vp 3 2 1.2 -vd 0 1 0 -vh 180 -vv 180 -x 512 -y 512 room.rad sky.rad > eye.hdr
    rglare eye.hdr
  Detailed output (source table and 23 values) and a check picture of the sources:
    rglare -d -c check.hdr eye.hdr
  Many pictures in one stream, evaluated in parallel, one line each in input order:
    cat eye1.hdr eye2.hdr eye3.hdr | rglare
  Vertical illuminance only, task area at pixel 256 256 with a 0.5 rad opening:
    rglare -V eye.hdr; rglare -t 256 256 0.5 eye.hdr
  Imageless annual glare of one view over a weather year:
    rglare annual -w site.epw -vf eye.vf -ab 3 -ad 512 -lw 1e-3 room.rad > dgp.txt";

/// `rglare`'s options as clap describes them: what `--help`, the man page and the shell
/// completions show. The parser is [`Args::parse`] (evalglare's letters and rpict's view
/// options, which clap cannot take); a test checks that it knows every letter named here.
pub fn command() -> clap::Command {
    use clap::{Arg, ArgAction, Command};
    let flag = |id: &'static str, short: char, help: &'static str| {
        Arg::new(id)
            .short(short)
            .action(ArgAction::SetTrue)
            .help(help)
    };
    let value = |id: &'static str, short: char, name: &'static str, help: &'static str| {
        Arg::new(id).short(short).value_name(name).help(help)
    };
    Command::new("rglare")
        .version(env!("CARGO_PKG_VERSION"))
        .about(
            "Glare of fisheye and perspective HDR pictures (DGP, DGI, UGR, VCP, CGI, Ev), \
             evalglare 3.x output",
        )
        .long_about(
            "Glare of fisheye and perspective HDR pictures (DGP, DGI, UGR, VCP, CGI, Ev), \
             evalglare 3.x output (the evalglare counterpart).\n\n\
             Pictures are files or standard input; a file or a pipe may hold several \
             pictures one after another. Several pictures give one result per picture, in \
             input order, evaluated in parallel. The detection method and threshold go to \
             standard error, one line per picture, so standard output stays what evalglare \
             prints. View options (rpict's: -vf file, -vt? -vp x y z -vd x y z -vu x y z \
             -vh deg -vv deg) replace the picture header's view.\n\n\
             Imageless annual glare: rglare annual (rglare annual --help).",
        )
        .override_usage(
            "rglare [-d|-V] [-c check.hdr] [-b thres] [-r radius] [-y|-x|-Y limit] [-s] \
             [-t|-T x y r] [-C l+|l-|0] [-q 0|1|2] [-P 0|1] [-w a1 a2 a3 a4 a5 c1 c2 c3] \
             [view options] [picture ...]\n       rglare annual ...",
        )
        .disable_version_flag(true)
        .args_conflicts_with_subcommands(true)
        .arg(
            Arg::new("version")
                .long("version")
                .action(ArgAction::Version)
                .help("Print version"),
        )
        .arg(flag(
            "detailed",
            'd',
            "Detailed output (source table + 23 values)",
        ))
        .arg(flag("ev", 'V', "Vertical illuminance only"))
        .arg(
            value(
                "check",
                'c',
                "FILE",
                "Check picture (one input picture only)",
            )
            .value_hint(clap::ValueHint::FilePath),
        )
        .arg(value(
            "threshold",
            'b',
            "F",
            "Threshold: > 100 absolute cd/m2, else F x task (or mean) luminance",
        ))
        .arg(value("radius", 'r', "RAD", "Search radius (default 0.2)"))
        .arg(flag("peaks", 'y', "Peak extraction on (default)"))
        .arg(flag("no-peaks", 'x', "Peak extraction off"))
        .arg(value(
            "peak-limit",
            'Y',
            "L",
            "Peak extraction on, with limit L",
        ))
        .arg(flag("smooth", 's', "Smoothing"))
        .arg(
            value(
                "task",
                't',
                "X Y R",
                "Task area: pixel X, Y from the bottom (as evalglare), opening R rad",
            )
            .num_args(3)
            .value_names(["X", "Y", "R"]),
        )
        .arg(
            value("task-T", 'T', "X Y R", "Task area, as -t")
                .num_args(3)
                .value_names(["X", "Y", "R"]),
        )
        .arg(
            value(
                "low-light",
                'C',
                "l+|l-|0",
                "Low-light correction on (l+) / off (l-, default) / off (0)",
            )
            .value_parser(["l+", "l-", "0"])
            .hide_possible_values(true),
        )
        .arg(
            value(
                "background",
                'q',
                "0|1|2",
                "Background luminance: 0 cosine-weighted mean, 1 mean without sources, 2 Ev",
            )
            .value_parser(["0", "1", "2"])
            .hide_possible_values(true),
        )
        .arg(
            value(
                "position",
                'P',
                "0|1",
                "Position index model: 0 Guth/Iwata, 1 Kim",
            )
            .value_parser(["0", "1"])
            .hide_possible_values(true),
        )
        .arg(
            value(
                "dgp",
                'w',
                "A1..C3",
                "DGP coefficients a1 a2 a3 a4 a5 c1 c2 c3",
            )
            .num_args(8)
            .value_names(["A1", "A2", "A3", "A4", "A5", "C1", "C2", "C3"]),
        )
        .arg(
            Arg::new("pictures")
                .value_name("PICTURE")
                .num_args(0..)
                .value_hint(clap::ValueHint::FilePath)
                .help("HDR pictures (standard input when none is named)"),
        )
        .after_help(EXAMPLES)
        .subcommand(super::glare_annual::command())
}

fn num(args: &[String], i: usize, opt: &str) -> Result<f64> {
    let v = args
        .get(i)
        .ok_or_else(|| Error::Usage(format!("{opt} needs a value; {USAGE}")))?;
    v.parse::<f64>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| Error::Usage(format!("{opt}: '{v}' is not a number")))
}

impl Args {
    /// Parse the arguments after the program name.
    pub fn parse(raw: &[String]) -> Result<Args> {
        let mut user = View::default();
        let mut got_view = false;
        let mut opts = Options::default();
        let mut output = Output::Default;
        let mut check = None;
        let mut files = Vec::new();
        let mut i = 0;
        while i < raw.len() {
            let a = raw[i].as_str();
            if !a.starts_with('-') || a == "-" {
                files.push(a.to_string());
                i += 1;
                continue;
            }
            if let Some(n) = user.apply_arg(&raw[i..])? {
                got_view = true;
                i += n;
                continue;
            }
            match a {
                "-d" => output = Output::Detailed,
                "-V" => output = Output::Ev,
                "-c" => {
                    i += 1;
                    check = Some(
                        raw.get(i)
                            .ok_or_else(|| Error::Usage(format!("-c needs a file; {USAGE}")))?
                            .clone(),
                    );
                }
                "-b" => {
                    i += 1;
                    opts.detect.threshold = Some(num(raw, i, a)?);
                }
                "-r" => {
                    i += 1;
                    opts.detect.radius = num(raw, i, a)?;
                    if opts.detect.radius <= 0.0 {
                        return Err(Error::Usage("-r: the search radius must be > 0".into()));
                    }
                }
                "-y" => opts.detect.peaks = true,
                "-x" => opts.detect.peaks = false,
                "-Y" => {
                    i += 1;
                    opts.detect.peaks = true;
                    opts.detect.peak_limit = num(raw, i, a)?;
                }
                "-s" => opts.detect.smooth = true,
                "-t" | "-T" => {
                    let x = num(raw, i + 1, a)?;
                    let y = num(raw, i + 2, a)?;
                    let r = num(raw, i + 3, a)?;
                    if x < 0.0 || y < 0.0 {
                        return Err(Error::Usage(format!("{a}: task position outside picture")));
                    }
                    opts.detect.task = Some((x as usize, y as usize, r));
                    i += 3;
                }
                "-C" => {
                    i += 1;
                    match raw.get(i).map(String::as_str) {
                        Some("l+") => opts.low_light = true,
                        Some("l-") | Some("0") => opts.low_light = false,
                        other => {
                            return Err(Error::Usage(format!(
                                "-C: expected l+, l- or 0, found {}",
                                other.unwrap_or("nothing")
                            )));
                        }
                    }
                }
                "-q" => {
                    i += 1;
                    opts.background = match num(raw, i, a)? as i64 {
                        1 => Background::MeanWithoutSources,
                        2 => Background::Ev,
                        _ => Background::Cosine,
                    };
                }
                "-P" => {
                    i += 1;
                    opts.model = if num(raw, i, a)? as i64 == 1 {
                        PosModel::Kim
                    } else {
                        PosModel::GuthIwata
                    };
                }
                "-w" => {
                    let mut v = [0.0; 8];
                    for (k, x) in v.iter_mut().enumerate() {
                        *x = num(raw, i + 1 + k, a)?;
                    }
                    opts.dgp.a = [v[0], v[1], v[2], v[3], v[4]];
                    opts.dgp.c = [v[5], v[6], v[7]];
                    i += 8;
                }
                _ => {
                    return Err(Error::Usage(format!(
                        "unknown or unsupported option '{a}'; {USAGE}"
                    )));
                }
            }
            i += 1;
        }
        if got_view && (user.vh == 0.0 || user.vv == 0.0) {
            return Err(Error::Usage(
                "a view given on the command line needs at least -vt, -vh and -vv".into(),
            ));
        }
        // the per-pixel position statistics are printed only by -d
        opts.position_stats = output == Output::Detailed;
        if check.is_some() && files.len() > 1 {
            return Err(Error::Usage("-c needs exactly one input picture".into()));
        }
        Ok(Args {
            opts,
            output,
            check,
            view: got_view.then_some(user),
            files,
        })
    }
}

/// Every picture of input `name` (`-` = standard input): one file may hold a stream of
/// pictures written one after another (e.g. `rpict ... ; rpict ...` into one pipe), each
/// with its own header; they are named `name#1`, `name#2`... when there are several.
fn open(name: &str) -> Result<Vec<(String, Picture)>> {
    use std::io::BufRead;
    fn all<R: BufRead>(mut r: R, name: &str) -> Result<Vec<(String, Picture)>> {
        let mut pics = Vec::new();
        loop {
            let shown = if pics.is_empty() {
                name.to_string()
            } else {
                format!("{name}#{}", pics.len() + 1)
            };
            pics.push((shown, Picture::read(&mut r, name)?));
            if r.fill_buf().map_err(|e| Error::io(name, e))?.is_empty() {
                break;
            }
        }
        if pics.len() > 1 {
            pics[0].0 = format!("{name}#1");
        }
        Ok(pics)
    }
    if name == "-" {
        let stdin = std::io::stdin();
        all(std::io::BufReader::new(stdin.lock()), "<stdin>")
    } else {
        let f = std::fs::File::open(name).map_err(|e| Error::io(name, e))?;
        all(std::io::BufReader::new(f), name)
    }
}

/// Evaluate one picture and return (stdout text, stderr lines).
fn one(args: &Args, name: &str, mut pic: Picture) -> Result<(String, Vec<String>)> {
    let view = picture_view(&pic, name, args.view.as_ref())?;
    let camera = view.setup()?;
    let p = crate::glare::Pixels::new(&pic, camera);
    // Pixels holds what the evaluation needs; the check picture takes only the header.
    // Freeing the pixel values here keeps them out of the peak memory of the detection.
    pic.data = Vec::new();
    if let Some((x, y, _)) = args.opts.detect.task {
        if x >= p.xres || y >= p.yres {
            return Err(Error::Usage(format!(
                "{name}: task position {x} {y} outside the {}x{} picture",
                p.xres, p.yres
            )));
        }
    }
    if args.output == Output::Ev {
        return Ok((
            report::ev_line(crate::glare::vertical_illuminance(&p)),
            vec![],
        ));
    }
    let e = evaluate_pixels(&p, &args.opts);
    let mut err: Vec<String> = e
        .notices
        .iter()
        .map(|n| format!("rglare: {name}: {n}"))
        .collect();
    err.push(report::method_line(
        name,
        &e,
        args.opts.detect.radius,
        args.opts
            .detect
            .peaks
            .then_some(args.opts.detect.peak_limit),
    ));
    if let Some(c) = &args.check {
        let out = crate::glare::check::check_picture(&pic, &p, &e);
        crate::io::write_atomically(std::path::Path::new(c), |w| out.write(w, true))?;
    }
    let text = match args.output {
        Output::Detailed => report::detailed(&e),
        _ => report::default_line(&e),
    };
    Ok((text, err))
}

/// Run `rglare` with the arguments after the program name.
pub fn run(raw: &[String]) -> Result<()> {
    use rayon::prelude::*;
    if raw.first().map(String::as_str) == Some("annual") {
        return super::glare_annual::run(&raw[1..]);
    }
    // evalglare has no help option; ours prints the usage and the option table, exit 0,
    // as every other tool's --help does.
    if raw
        .iter()
        .any(|a| a == "--help" || a == "-help" || a == "-h")
    {
        println!("{}", command().render_long_help());
        return Ok(());
    }
    if raw.iter().any(|a| a == "--version") {
        println!("rglare {}", env!("CARGO_PKG_VERSION"));
        return Ok(());
    }
    let mut args = Args::parse(raw)?;
    if args.files.is_empty() {
        args.files.push("-".into());
    }
    // files in parallel; a stream's pictures in parallel once it is read
    type Out = (String, Vec<String>);
    let results: Vec<Result<Vec<Out>>> = args
        .files
        .par_iter()
        .map(|f| {
            let pics = open(f)?;
            if args.check.is_some() && pics.len() > 1 {
                return Err(Error::Usage("-c needs exactly one input picture".into()));
            }
            pics.into_par_iter()
                .map(|(name, pic)| one(&args, &name, pic))
                .collect()
        })
        .collect();
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    for r in results {
        for (text, err) in r? {
            for e in err {
                eprintln!("{e}");
            }
            out.write_all(text.as_bytes())
                .map_err(|e| Error::io("<stdout>", e))?;
        }
    }
    out.flush().map_err(|e| Error::io("<stdout>", e))
}
