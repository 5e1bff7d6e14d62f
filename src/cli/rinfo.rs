//! # `rinfo`'s command line: getinfo's `-d`, plus summaries getinfo does not give
//!
//! The tools layer's half of `rinfo`: the clap struct and its conversion into what
//! `rdaylight::info::describe` takes ([`Detail`] and the scene's [`LoadOptions`]).

use crate::info::Detail;
use crate::scene::LoadOptions;
use clap::Parser;

pub const EXAMPLES: &str = "\
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
pub struct Options {
    /// Print dimensions only (getinfo -d): resolution of a picture, size of a matrix.
    #[arg(short = 'd')]
    pub dimensions: bool,

    /// Per-component minimum, mean and maximum of a matrix, or luminance statistics of a
    /// picture (streamed; decodes every row, so it also checks the data).
    #[arg(long)]
    pub stats: bool,

    /// Refuse inline `!commands` in scenes (error instead). By default they run, as in
    /// Radiance; also RDAYLIGHT_NO_EXEC=1.
    #[arg(long)]
    pub no_exec: bool,

    /// Files to describe (`-` = standard input).
    #[arg(required = true)]
    pub files: Vec<String>,
}

impl Options {
    /// What to print for pictures and matrices (`-d` wins over `--stats`).
    pub fn detail(&self) -> Detail {
        if self.dimensions {
            Detail::Dimensions
        } else if self.stats {
            Detail::Stats
        } else {
            Detail::Header
        }
    }

    /// How scenes are loaded (`--no-exec` refuses `!commands`).
    pub fn load_options(&self) -> LoadOptions {
        let mut opts = LoadOptions::from_env();
        if self.no_exec {
            opts.allow_exec = false;
        }
        opts
    }
}
