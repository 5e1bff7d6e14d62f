//! `rrecon`: laser scan -> watertight, window-bearing room in `.rad` (seed chapter 4).
//! The pipeline is in `rdaylight::recon`; this file parses options, reads and writes.

use clap::{Args, Parser, Subcommand};
use rdaylight::Error;
use rdaylight::error::IoContext;
use rdaylight::io::write_atomically;
use rdaylight::recon::cloud::{Bounds, unit_scale};
use rdaylight::recon::model::fix_t_junctions;
use rdaylight::recon::openings::Selection;
use rdaylight::recon::rooms::{ROOMS, RoomSpec};
use rdaylight::recon::simulate::{ScanOptions, scan, stations_in_text};
use rdaylight::recon::{ReconParams, eval, ply, radout, read_cloud, reconstruct, review, summary};
use rdaylight::scene::{self, LoadOptions, Scene};
use std::io::{Read, Write};
use std::path::Path;

const EXAMPLES: &str = "\
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
#[command(name = "rrecon", after_help = EXAMPLES, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    recon: Recon,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simulate a terrestrial laser scan of a `.rad` room (binary PLY on stdout).
    Simulate(Simulate),
    /// Write a built-in test room (rect, lshape, slanted, arched, cluttered) as `.rad`.
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
struct Simulate {
    /// Scene (`-` = stdin); `# rrecon station x y z` comments give default stations.
    scene: String,
    /// Stations `x,y,z;x,y,z` (default: the file's station comments, else the centre of the
    /// scene's bounding box 1.5 m above its floor).
    #[arg(long)]
    stations: Option<String>,
    /// Angular step, degrees.
    #[arg(long, default_value_t = 0.25)]
    resolution: f64,
    /// Range noise (standard deviation), metres.
    #[arg(long, default_value_t = 0.003)]
    noise: f64,
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

#[derive(Args, Debug)]
struct Recon {
    /// Point cloud: .ply, .las (uncompressed LAS 1.0-1.4), .xyz/.txt/.pts or `-` for stdin
    /// (PLY, LAS or XYZ, sniffed); .e57 (all scans, poses applied). LAZ: decompress first.
    input: Option<String>,
    /// Output `.rad` (default: stdout).
    #[arg(short = 'o', long)]
    output: Option<String>,
    /// JSON summary (planes, areas, WWR, WFR, timings, window candidates).
    #[arg(long)]
    json: Option<String>,
    /// Directory for review pictures (one SVG per wall with numbered candidates).
    #[arg(long)]
    review: Option<String>,
    /// Cut the automatically ranked window candidates.
    #[arg(long)]
    auto: bool,
    /// Cut these candidates: WALL:N[,N...], repeatable (numbers from the review/JSON).
    #[arg(long)]
    windows: Vec<String>,
    /// Materials file whose definitions of floor, ceiling, wall, reveal, glazing win.
    #[arg(long)]
    materials: Option<String>,
    /// Reveal depth (wall thickness to the glass), metres, or `auto`: measured per window
    /// from the points behind the wall (0.2 where there are none).
    #[arg(long, default_value = "auto")]
    reveal_depth: String,
    /// Unit of the input coordinates: m, cm, mm, in, ft.
    #[arg(long, default_value = "m")]
    units: String,
    /// Crop box x0,y0,z0,x1,y1,z1 (metres, after unit conversion).
    #[arg(long)]
    crop: Option<String>,
    /// Points kept after voxel down-sampling (seed: ~100,000).
    #[arg(long, default_value_t = 100_000)]
    target_points: usize,
    /// RANSAC minimum support (seed: 1,000-4,000).
    #[arg(long, default_value_t = 1000)]
    min_support: usize,
    /// RANSAC distance threshold, metres (seed: 0.005).
    #[arg(long, default_value_t = 0.005)]
    epsilon: f64,
    /// Window gap size (empty-circle diameter), metres (seed: 0.08).
    #[arg(long, default_value_t = 0.08)]
    edge_threshold: f64,
    /// Smallest candidate region, m² (seed: 0.001 = 10 cm²).
    #[arg(long, default_value_t = 0.001)]
    min_area: f64,
    /// Random seed (RANSAC).
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

fn numbers(s: &str, what: &str) -> Result<Vec<f64>, Error> {
    s.split([',', ' '])
        .filter(|w| !w.is_empty())
        .map(|w| {
            w.parse::<f64>()
                .map_err(|_| Error::Usage(format!("{what} '{s}': '{w}' is not a number")))
        })
        .collect()
}

fn read_text(path: &str) -> Result<String, Error> {
    if path == "-" {
        let mut s = String::new();
        std::io::stdin().read_to_string(&mut s).at_path("<stdin>")?;
        Ok(s)
    } else {
        std::fs::read_to_string(path).at_path(path)
    }
}

fn load_scene(path: &str) -> Result<(Scene, String), Error> {
    let text = read_text(path)?;
    let dir = Path::new(path).parent().unwrap_or(Path::new(""));
    let s = scene::parse_str(&text, path, dir, &LoadOptions::from_env())?;
    Ok((s, text))
}

fn output(
    path: Option<&str>,
    f: impl FnOnce(&mut dyn Write) -> Result<(), Error>,
) -> Result<(), Error> {
    match path {
        Some(p) if p != "-" => write_atomically(Path::new(p), f),
        _ => {
            let stdout = std::io::stdout();
            let mut w = std::io::BufWriter::new(stdout.lock());
            f(&mut w)?;
            w.flush().at_path("<stdout>")
        }
    }
}

fn simulate(a: &Simulate) -> Result<(), Error> {
    let (scene, text) = load_scene(&a.scene)?;
    let mut stations = match &a.stations {
        Some(s) => s
            .split(';')
            .map(|p| match numbers(p, "--stations")?[..] {
                [x, y, z] => Ok([x, y, z]),
                _ => Err(Error::Usage(format!("--stations '{p}': expected x,y,z"))),
            })
            .collect::<Result<Vec<_>, _>>()?,
        None => stations_in_text(&text),
    };
    if stations.is_empty() {
        let b = scene
            .bounding_box()
            .ok_or_else(|| Error::Usage(format!("{}: no geometry to scan", a.scene)))?;
        stations.push([
            0.5 * (b.min[0] + b.max[0]),
            0.5 * (b.min[1] + b.max[1]),
            b.min[2] + 1.5,
        ]);
    }
    let opts = ScanOptions {
        stations,
        resolution: a.resolution,
        noise: a.noise,
        seed: a.seed,
        ..Default::default()
    };
    let cloud = scan(&scene, &opts)?;
    output(None, |w| ply::write(w, &cloud).at_path("<stdout>"))
}

fn room(name: &str, shell: bool) -> Result<(), Error> {
    let mut spec = RoomSpec::named(name).ok_or_else(|| {
        Error::Usage(format!(
            "unknown room '{name}'; expected one of {}",
            ROOMS.join(", ")
        ))
    })?;
    if shell {
        spec.furniture.clear();
    }
    let scene = spec.scene()?;
    output(None, |w| {
        writeln!(
            w,
            "# rrecon test room '{name}' (ground truth); reveal depth {} m",
            spec.reveal_depth
        )
        .at_path("<stdout>")?;
        for s in &spec.stations {
            writeln!(w, "# rrecon station {} {} {}", s[0], s[1], s[2]).at_path("<stdout>")?;
        }
        scene.write_rad(&mut *w).at_path("<stdout>")?;
        writeln!(w).at_path("<stdout>")
    })
}

fn evaluate(truth: &str, recon: &str, samples: usize) -> Result<(), Error> {
    let mut t = eval::polygons_of_scene(&load_scene(truth)?.0);
    let mut r = eval::polygons_of_scene(&load_scene(recon)?.0);
    fix_t_junctions(&mut t, 1e-6);
    fix_t_junctions(&mut r, 1e-6);
    let c = eval::compare(&t, &r, samples);
    #[derive(serde::Serialize)]
    struct Out {
        #[serde(flatten)]
        comparison: eval::Comparison,
        truth_watertight: bool,
        recon_watertight: bool,
    }
    let out = Out {
        comparison: c,
        truth_watertight: rdaylight::recon::model::watertight(&t, 1e-6).is_closed(),
        recon_watertight: rdaylight::recon::model::watertight(&r, 1e-6).is_closed(),
    };
    let text = serde_json::to_string_pretty(&out).map_err(|e| Error::Usage(e.to_string()))?;
    output(None, |w| writeln!(w, "{text}").at_path("<stdout>"))
}

fn reconstruct_cmd(a: &Recon) -> Result<(), Error> {
    let input = a
        .input
        .as_deref()
        .ok_or_else(|| Error::Usage("no input point cloud; see --help".into()))?;
    let mut cloud = read_cloud(input)?;
    let name = if input == "-" { "<stdin>" } else { input };
    let s = unit_scale(&a.units)?;
    if s != 1.0 {
        cloud.scale(s);
    }
    cloud.check(name)?;
    let crop = match &a.crop {
        Some(c) => match numbers(c, "--crop")?[..] {
            [x0, y0, z0, x1, y1, z1] => Some(Bounds {
                lo: [x0, y0, z0],
                hi: [x1, y1, z1],
            }),
            _ => {
                return Err(Error::Usage(format!(
                    "--crop '{c}': expected x0,y0,z0,x1,y1,z1"
                )));
            }
        },
        None => None,
    };
    let selection = if !a.windows.is_empty() {
        Selection::parse(&a.windows)?
    } else if a.auto {
        Selection::Auto
    } else {
        Selection::None
    };
    let (reveal_depth, measure_depth) = match a.reveal_depth.as_str() {
        "auto" => (0.2, true),
        d => (
            numbers(d, "--reveal-depth")?
                .first()
                .copied()
                .unwrap_or(0.2),
            false,
        ),
    };
    let mut p = ReconParams {
        crop,
        target_points: a.target_points,
        reveal_depth,
        measure_depth,
        ..Default::default()
    };
    p.ransac.min_support = a.min_support;
    p.ransac.epsilon = a.epsilon;
    p.ransac.seed = a.seed;
    p.openings.edge_threshold = a.edge_threshold;
    p.openings.min_area = a.min_area;
    let materials = match &a.materials {
        Some(m) => Some(load_scene(m)?.0),
        None => None,
    };
    let r = reconstruct(cloud, &p, &selection)?;
    let mut polys = r.model.polygons();
    fix_t_junctions(&mut polys, 1e-6);
    let scene = radout::to_scene(&polys, materials.as_ref())?;
    if let Some(dir) = &a.review {
        std::fs::create_dir_all(dir).at_path(dir)?;
        for (fi, f) in r.model.faces.iter().enumerate() {
            if let Some(svg) = review::wall_svg(&r, fi, p.openings.band) {
                let path = Path::new(dir).join(format!("{}.svg", f.name));
                write_atomically(&path, |w| {
                    w.write_all(svg.as_bytes())
                        .at_path(&path.display().to_string())
                })?;
            }
        }
    }
    let sum = summary::summarise(&r);
    if let Some(j) = &a.json {
        let text = serde_json::to_string_pretty(&sum).map_err(|e| Error::Usage(e.to_string()))?;
        write_atomically(Path::new(j), |w| w.write_all(text.as_bytes()).at_path(j))?;
    }
    if selection == Selection::None {
        let mut note =
            String::from("rrecon: no windows cut (use --auto or --windows); candidates:");
        for wc in &sum.candidates {
            for c in wc
                .candidates
                .iter()
                .filter(|c| c.area >= p.openings.auto_min_area)
            {
                note.push_str(&format!(
                    " {}:{} ({:.2} m2{})",
                    wc.wall,
                    c.id,
                    c.area,
                    if c.auto { ", auto" } else { "" }
                ));
            }
        }
        eprintln!("{note}");
    }
    if !r.watertight.is_closed() {
        eprintln!(
            "rrecon: warning: the model is not closed ({:?})",
            r.watertight
        );
    }
    output(a.output.as_deref(), |w| {
        writeln!(
            w,
            "# rrecon {input}: {} faces, {} windows, WWR {:.3}, WFR {:.3}, watertight {}",
            sum.faces.len(),
            sum.windows.len(),
            sum.wwr,
            sum.wfr,
            sum.watertight
        )
        .at_path("<output>")?;
        scene.write_rad(&mut *w).at_path("<output>")?;
        writeln!(w).at_path("<output>")
    })
}

fn main() {
    rdaylight::cli::run("rrecon", || {
        let cli = Cli::parse();
        match &cli.command {
            Some(Command::Simulate(a)) => simulate(a),
            Some(Command::Room { name, shell }) => room(name, *shell),
            Some(Command::Eval {
                truth,
                recon,
                samples,
            }) => evaluate(truth, recon, *samples),
            None => reconstruct_cmd(&cli.recon),
        }
    })
}
