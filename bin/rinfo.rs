//! `rinfo`: what is in a file, before a long run needs it (the `getinfo` counterpart).
//!
//! All summaries are in `rdaylight::info`; this file parses options and dispatches.

use clap::Parser;
use rdaylight::error::{Error, IoContext};
use rdaylight::formats::header::Header;
use rdaylight::formats::weather::Weather;
use rdaylight::info::{self, Kind};
use rdaylight::scene::{self, LoadOptions};
use std::io::{BufRead, BufReader, Write};

const EXAMPLES: &str = "\
Examples:
    rinfo view.hdr dc.mtx               headers, as getinfo prints them
    rinfo -d view.hdr sky.mtx           dimensions (getinfo -d)
    rinfo --stats ill.mtx view.hdr      min/mean/max per component / luminance, streamed
    rinfo room.rad grid.pts site.epw    scene, sensor and weather summaries
    rinfo --no-exec untrusted.rad       parse a scene without running its !commands";

/// Headers and summaries of Radiance files: pictures and matrices (header, -d dimensions,
/// --stats), scenes (object counts, bounding box), sensor rays, EPW and .wea weather.
/// The kind of file is judged by its content, not its name.
#[derive(Parser, Debug)]
#[command(name = "rinfo", version, after_help = EXAMPLES)]
struct Cli {
    /// Print dimensions only (getinfo -d): resolution of a picture, size of a matrix.
    #[arg(short = 'd')]
    dimensions: bool,

    /// Per-component minimum, mean and maximum of a matrix, or luminance statistics of a
    /// picture (streamed; decodes every row, so it also checks the data).
    #[arg(long)]
    stats: bool,

    /// Refuse inline `!commands` in scenes (also: RDAYLIGHT_NO_EXEC=1).
    #[arg(long)]
    no_exec: bool,

    /// Files to describe (`-` = standard input).
    #[arg(required = true)]
    files: Vec<String>,
}

fn open(path: &str) -> Result<Box<dyn BufRead>, Error> {
    if path == "-" {
        return Ok(Box::new(BufReader::new(std::io::stdin().lock())));
    }
    Ok(Box::new(BufReader::with_capacity(
        1 << 16,
        std::fs::File::open(path).at_path(path)?,
    )))
}

fn describe(path: &str, cli: &Cli, out: &mut dyn Write) -> Result<(), Error> {
    let mut r = open(path)?;
    let kind = info::detect(r.fill_buf().at_path(path)?);
    let text = match kind {
        Kind::Radiance if cli.dimensions => format!("{path}: {}\n", info::dimensions(r, path)?),
        Kind::Radiance if cli.stats => info::stats(r, path)?,
        Kind::Radiance => {
            let h = Header::read(&mut r, path)?;
            let mut s = format!(
                "{path}:\n\t#?{}\n",
                h.magic.as_deref().unwrap_or("RADIANCE")
            );
            for l in &h.lines {
                s.push('\t');
                s.push_str(l);
                s.push('\n');
            }
            s.push('\n');
            s
        }
        Kind::Weather => {
            let mut bytes = Vec::new();
            r.read_to_end(&mut bytes).at_path(path)?;
            let w = Weather::parse(&rdaylight::formats::weather::decode_text(&bytes), path)?;
            info::describe_weather(&w, path)
        }
        Kind::Sensors => info::describe_sensors(r, path)?,
        Kind::Scene => {
            drop(r);
            let mut opts = LoadOptions::from_env();
            if cli.no_exec {
                opts.allow_exec = false;
            }
            let sc = scene::load(&[path], &opts)?;
            info::describe_scene(&sc, path)
        }
    };
    out.write_all(text.as_bytes()).at_path("<stdout>")
}

fn main() {
    rdaylight::cli::run("rinfo", || {
        let cli = Cli::parse();
        let stdout = std::io::stdout();
        let mut out = stdout.lock();
        for f in &cli.files {
            describe(f, &cli, &mut out)?;
        }
        Ok(())
    })
}
