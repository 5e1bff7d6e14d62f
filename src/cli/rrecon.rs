//! # `rrecon`'s command line
//!
//! The tools layer's half of `rrecon`: the clap structs and their conversion into the
//! library's typed commands ([`crate::recon::run`]), which read, reconstruct and write.

use crate::error::Error;
use crate::recon::openings::Selection;
use crate::recon::run::{self, Reconstruct, parse_crop, parse_reveal, parse_stations};
use clap::{Args, Parser, Subcommand};

pub const EXAMPLES: &str = "\
Examples:
  Scan a known room and reconstruct it, windows chosen automatically:
    rrecon room rect > room.rad
    rrecon simulate room.rad > scan.ply
    rrecon --auto --json recon.json scan.ply > recon.rad
  Semi-automatic: look at the review pictures, then name the candidates:
    rrecon --review review/ scan.ply > shell.rad
    rrecon --windows wall2:1 --windows wall3:1,2 scan.ply > recon.rad
  One pipe, then the geometric errors against the known room:
    rrecon simulate room.rad | rrecon --auto - > recon.rad
    rrecon eval room.rad recon.rad";

/// Reconstruct a room from a laser scan: preprocessing, RANSAC planes, a watertight shell
/// (PolyFit-style selection, solved exactly), windows from holes in the wall points, and a
/// `.rad` model with named surfaces and default materials (opaque 0.5, glazing 0.75).
#[derive(Parser, Debug)]
#[command(name = "rrecon", version, propagate_version = true, after_help = EXAMPLES, args_conflicts_with_subcommands = true)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    #[command(flatten)]
    pub recon: Recon,
    /// Refuse inline `!commands` in scene files (simulate, eval, --materials; error
    /// instead). By default they run, as in Radiance; also RDAYLIGHT_NO_EXEC=1.
    #[arg(long, global = true)]
    pub no_exec: bool,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Simulate a terrestrial laser scan of a `.rad` room (binary PLY on stdout).
    Simulate(Simulate),
    /// Write a built-in test room (rect, lshape, slanted, arched, cluttered, flush, flushl)
    /// as `.rad`.
    Room {
        name: String,
        /// Leave the furniture out (the GLoD0 ground truth).
        #[arg(long)]
        shell: bool,
    },
    /// Compare a reconstruction with the known model: Chamfer, Hausdorff, windows (JSON).
    Eval {
        truth: String,
        recon: String,
        /// Surface samples per model (the seed uses 80,000).
        #[arg(long, default_value_t = 80_000)]
        samples: usize,
    },
}

#[derive(Args, Debug)]
pub struct Simulate {
    /// Scene (`-` = stdin); `# rrecon station x y z` comments give default stations.
    pub scene: String,
    /// Stations `x,y,z;x,y,z` (default: the file's station comments, else the centre of the
    /// scene's bounding box 1.5 m above its floor).
    #[arg(long)]
    pub stations: Option<String>,
    /// Angular step, degrees.
    #[arg(value_parser = super::finite, long, default_value_t = 0.25)]
    pub resolution: f64,
    /// Range noise (standard deviation), metres.
    #[arg(value_parser = super::finite, long, default_value_t = 0.003)]
    pub noise: f64,
    /// Probability that a beam through glass returns a stray point 0.05-5 m beyond it
    /// (dirt, frames, reflections; 0.001 gives a few dozen per window).
    #[arg(value_parser = super::finite, long, default_value_t = 0.0)]
    pub stray: f64,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

#[derive(Args, Debug)]
pub struct Recon {
    /// Point cloud: .ply, .las (uncompressed LAS 1.0-1.4), .xyz/.txt/.pts or `-` for stdin
    /// (PLY, LAS or XYZ, sniffed); .e57 (all scans, poses applied). LAZ: decompress first.
    pub input: Option<String>,
    /// Output `.rad` (default: stdout).
    #[arg(short = 'o', long)]
    pub output: Option<String>,
    /// JSON summary (planes, areas, WWR, WFR, timings, window candidates).
    #[arg(long)]
    pub json: Option<String>,
    /// Directory for review pictures (one SVG per wall with numbered candidates).
    #[arg(long)]
    pub review: Option<String>,
    /// Cut the automatically ranked window candidates.
    #[arg(long)]
    pub auto: bool,
    /// Cut these candidates: WALL:N[,N...], repeatable (numbers from the review/JSON).
    #[arg(long)]
    pub windows: Vec<String>,
    /// Materials file whose definitions of floor, ceiling, wall, reveal, glazing win.
    #[arg(long)]
    pub materials: Option<String>,
    /// Reveal depth (wall thickness to the glass), metres, or `auto`: measured per window
    /// from the reveal points behind the wall; 0 (flush glazing) for a window the stations
    /// saw into without a reveal, 0.2 for a chosen candidate nobody saw.
    #[arg(long, default_value = "auto")]
    pub reveal_depth: String,
    /// Unit of the input coordinates: m, cm, mm, in, ft.
    #[arg(long, default_value = "m")]
    pub units: String,
    /// Scanner stations x,y,z;x,y,z (metres, after --units), which tell windows from the
    /// shadows of clutter. E57 scan poses and PLY `comment station` lines give them; without
    /// either, one station is assumed 1.5 m above the floor point farthest from the walls.
    #[arg(long)]
    pub stations: Option<String>,
    /// Crop box x0,y0,z0,x1,y1,z1 (metres, after unit conversion).
    #[arg(long)]
    pub crop: Option<String>,
    /// Points kept after voxel down-sampling (seed: ~100,000; at most 100 million).
    #[arg(long, default_value_t = 100_000, value_parser = super::at_most::<100_000_000>)]
    pub target_points: usize,
    /// RANSAC minimum support (seed: 1,000-4,000; at most 100 million).
    #[arg(long, default_value_t = 1000, value_parser = super::at_most::<100_000_000>)]
    pub min_support: usize,
    /// RANSAC distance threshold, metres (seed: 0.005).
    #[arg(value_parser = super::finite, long, default_value_t = 0.005)]
    pub epsilon: f64,
    /// Window gap size (empty-circle diameter), metres (seed: 0.08).
    #[arg(value_parser = super::finite, long, default_value_t = 0.08)]
    pub edge_threshold: f64,
    /// Smallest candidate region, m² (seed: 0.001 = 10 cm²).
    #[arg(value_parser = super::finite, long, default_value_t = 0.001)]
    pub min_area: f64,
    /// Random seed (RANSAC).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

impl Simulate {
    pub fn to_run(&self) -> Result<run::Simulate, Error> {
        Ok(run::Simulate {
            scene: self.scene.clone(),
            stations: self.stations.as_deref().map(parse_stations).transpose()?,
            resolution: self.resolution,
            noise: self.noise,
            stray: self.stray,
            seed: self.seed,
        })
    }
}

impl Recon {
    pub fn to_run(&self) -> Result<Reconstruct, Error> {
        let input = self
            .input
            .clone()
            .ok_or_else(|| Error::Usage("no input point cloud; see --help".into()))?;
        let crop = self.crop.as_deref().map(parse_crop).transpose()?;
        let selection = if !self.windows.is_empty() {
            Selection::parse(&self.windows)?
        } else if self.auto {
            Selection::Auto
        } else {
            Selection::None
        };
        let reveal = parse_reveal(&self.reveal_depth)?;
        Ok(Reconstruct {
            input,
            output: self.output.clone(),
            json: self.json.clone(),
            review: self.review.clone(),
            selection,
            materials: self.materials.clone(),
            units: self.units.clone(),
            stations: self.stations.as_deref().map(parse_stations).transpose()?,
            params: Reconstruct::params(
                crop,
                self.target_points,
                reveal,
                self.min_support,
                self.epsilon,
                self.seed,
                self.edge_threshold,
                self.min_area,
            ),
        })
    }
}
