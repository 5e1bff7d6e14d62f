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

/// What `rglare --help` prints after the usage line (the table of the module documentation).
const HELP: &str = "\
Glare of fisheye and perspective HDR pictures (DGP, DGI, UGR, VCP, CGI, Ev), evalglare 3.x output.
  -d               detailed output (source table + 23 values)
  -V               vertical illuminance only
  -c file          check picture (one input picture only)
  -b f             threshold: > 100 absolute cd/m2, else f x task (or mean) luminance
  -r rad           search radius (default 0.2)
  -y / -x / -Y L   peak extraction on (default) / off / on with limit L
  -s               smoothing
  -t x y r         task area (pixel x, y from the bottom; opening r rad); -T the same
  -C l+|l-|0       low-light correction on / off (default) / off
  -q 0|1|2         background luminance
  -P 0|1           position index model (Guth/Iwata, Kim)
  -w a1..a5 c1..c3 DGP coefficients
  -vf file, -vt? -vh -vv -vd -vu -vp ...   view, replacing the header's
Pictures are files or standard input (several pictures may follow each other in a stream).
Imageless annual glare: rglare annual --help";

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
fn one(args: &Args, name: &str, pic: &Picture) -> Result<(String, Vec<String>)> {
    let view = picture_view(pic, name, args.view.as_ref())?;
    let camera = view.setup()?;
    let p = crate::glare::Pixels::new(pic, camera);
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
        let out = crate::glare::check::check_picture(pic, &p, &e);
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
    if raw.iter().any(|a| a == "--help" || a == "-help") {
        println!("{USAGE}\n\n{HELP}");
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
            pics.par_iter()
                .map(|(name, pic)| one(&args, name, pic))
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
