//! # The `rrecon` commands as library calls
//!
//! Typed configurations of `rrecon`'s commands ([`Reconstruct`], [`Simulate`]) with the
//! parsers of their option values ([`parse_stations`], [`parse_crop`], [`parse_reveal`],
//! each a one-line `Usage` error naming the option), and one function per command that
//! reads, computes and writes. The command line itself (clap) is the tools layer's
//! (`rdaylight::cli::rrecon`).

use crate::cloud::{Bounds, unit_scale};
use crate::model::fix_t_junctions;
use crate::openings::Selection;
use crate::rooms::{ROOMS, RoomSpec};
use crate::simulate::{ScanOptions, scan, stations_in_text};
use crate::{ReconParams, eval, ply, radout, read_cloud, reconstruct_reporting, review, summary};
use rdaylight_base::error::{Error, IoContext, Result};
use rdaylight_base::io::write_atomically;
use rdaylight_base::progress::{Progress, Stage};
use rdaylight_formats::scene::{self, LoadOptions, Scene};
use std::io::{Read, Write};
use std::path::Path;

/// Numbers separated by commas or blanks; `what` names the option in errors.
pub fn numbers(s: &str, what: &str) -> Result<Vec<f64>> {
    s.split([',', ' '])
        .filter(|w| !w.is_empty())
        .map(|w| {
            w.parse::<f64>()
                .map_err(|_| Error::Usage(format!("{what} '{s}': '{w}' is not a number")))
        })
        .collect()
}

/// `--stations x,y,z;x,y,z`.
pub fn parse_stations(s: &str) -> Result<Vec<[f64; 3]>> {
    s.split(';')
        .map(|p| match numbers(p, "--stations")?[..] {
            [x, y, z] => Ok([x, y, z]),
            _ => Err(Error::Usage(format!("--stations '{p}': expected x,y,z"))),
        })
        .collect()
}

/// `--crop x0,y0,z0,x1,y1,z1`.
pub fn parse_crop(c: &str) -> Result<Bounds> {
    match numbers(c, "--crop")?[..] {
        [x0, y0, z0, x1, y1, z1] => Ok(Bounds {
            lo: [x0, y0, z0],
            hi: [x1, y1, z1],
        }),
        _ => Err(Error::Usage(format!(
            "--crop '{c}': expected x0,y0,z0,x1,y1,z1"
        ))),
    }
}

/// Reveal depth in metres, or measured per window from the points behind the wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reveal {
    /// Measured from the reveal points; 0 for an open window without any (flush glazing),
    /// 0.2 m for a chosen candidate no station saw into.
    Auto,
    Depth(f64),
}

/// `--reveal-depth auto|METRES`.
pub fn parse_reveal(d: &str) -> Result<Reveal> {
    match d {
        "auto" => Ok(Reveal::Auto),
        d => Ok(Reveal::Depth(
            numbers(d, "--reveal-depth")?
                .first()
                .copied()
                .unwrap_or(0.2),
        )),
    }
}

/// Text of scene file `path` (`-`: standard input); an octree, picture or other file that
/// is not scene text is named as such ([`scene::check_is_scene`]).
fn read_text(path: &str) -> Result<String> {
    let mut bytes = Vec::new();
    let shown = if path == "-" {
        std::io::stdin()
            .read_to_end(&mut bytes)
            .at_path("<stdin>")?;
        "<stdin>"
    } else {
        bytes = std::fs::read(path).at_path(path)?;
        path
    };
    scene::check_is_scene(&bytes, shown)?;
    String::from_utf8(bytes).map_err(|e| {
        Error::io(
            shown,
            std::io::Error::new(std::io::ErrorKind::InvalidData, e.utf8_error()),
        )
    })
}

/// A `.rad` file (`-`: standard input) as a scene, and its text.
pub fn load_scene(path: &str) -> Result<(Scene, String)> {
    let text = read_text(path)?;
    let dir = Path::new(path).parent().unwrap_or(Path::new(""));
    let s = scene::parse_str(&text, path, dir, &LoadOptions::from_env())?;
    Ok((s, text))
}

/// Write through `f` to `path` atomically, or to `out` (`None` or `-`).
fn output(
    path: Option<&str>,
    out: &mut dyn Write,
    f: impl FnOnce(&mut dyn Write) -> Result<()>,
) -> Result<()> {
    match path {
        Some(p) if p != "-" => write_atomically(Path::new(p), f),
        _ => {
            let mut w = std::io::BufWriter::new(out);
            f(&mut w)?;
            w.flush().at_path("<stdout>")
        }
    }
}

/// `rrecon simulate`: a terrestrial laser scan of a room.
#[derive(Debug, Clone)]
pub struct Simulate {
    /// Scene file (`-`: standard input).
    pub scene: String,
    /// Stations (`None`: the file's `# rrecon station` comments, else the middle of the
    /// bounding box 1.5 m above its floor).
    pub stations: Option<Vec<[f64; 3]>>,
    /// Angular step, degrees.
    pub resolution: f64,
    /// Range noise (standard deviation), metres.
    pub noise: f64,
    /// Probability of a stray return beyond glass.
    pub stray: f64,
    pub seed: u64,
}

/// Run `rrecon simulate`: the scan as binary PLY on `out`; the scan is a stage of
/// `progress`.
pub fn simulate_run(a: &Simulate, out: &mut dyn Write, progress: &dyn Progress) -> Result<()> {
    let (scene, text) = load_scene(&a.scene)?;
    let mut stations = a
        .stations
        .clone()
        .unwrap_or_else(|| stations_in_text(&text));
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
        stray: a.stray,
        seed: a.seed,
        ..Default::default()
    };
    let stage = Stage::uncounted(progress, "simulating the scan");
    let cloud = scan(&scene, &opts)?;
    drop(stage);
    output(None, out, |w| ply::write(w, &cloud).at_path("<stdout>"))
}

/// Run `rrecon room`: built-in test room `name` (without furniture if `shell`) as `.rad`.
pub fn room_run(name: &str, shell: bool, out: &mut dyn Write) -> Result<()> {
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
    output(None, out, |w| {
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

/// Run `rrecon eval`: the comparison of `recon` with `truth` as JSON.
pub fn eval_run(truth: &str, recon: &str, samples: usize, out: &mut dyn Write) -> Result<()> {
    // Points are held per model with a nearest-surface search each: 10 million (hundreds of
    // MB, minutes) is far beyond the seed's 80,000; 1e12 aborted on allocation (issue #19).
    crate::error::at_most(
        "--samples",
        samples as u64,
        10_000_000,
        "points held in memory per model; the seed uses 80,000",
    )?;
    let mut t = eval::polygons_of_scene(&load_scene(truth)?.0);
    let mut r = eval::polygons_of_scene(&load_scene(recon)?.0);
    // With nothing to sample on either side the distances stay 0, a perfect score for an
    // empty or sphere-only file (issue #19): refuse it instead.
    for (path, polys, role) in [(truth, &t, "truth"), (recon, &r, "reconstruction")] {
        if polys.is_empty() {
            return Err(Error::Usage(format!(
                "{path}: no polygons to sample as the {role} (only polygons are compared; \
                 spheres, cones, rings and 'furniture' are not): give the room's surfaces"
            )));
        }
    }
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
    let doc = Out {
        comparison: c,
        truth_watertight: crate::model::watertight(&t, 1e-6).is_closed(),
        recon_watertight: crate::model::watertight(&r, 1e-6).is_closed(),
    };
    let text = serde_json::to_string_pretty(&doc).map_err(|e| Error::Usage(e.to_string()))?;
    output(None, out, |w| writeln!(w, "{text}").at_path("<stdout>"))
}

/// The reconstruction: input, outputs and the pipeline's parameters.
#[derive(Debug, Clone)]
pub struct Reconstruct {
    /// Point cloud file (`-`: standard input).
    pub input: String,
    /// Output `.rad` (`None` or `-`: `out`).
    pub output: Option<String>,
    pub json: Option<String>,
    /// Directory for the review SVGs.
    pub review: Option<String>,
    pub selection: Selection,
    /// Materials file whose definitions win.
    pub materials: Option<String>,
    /// Unit of the input coordinates (`m`, `cm`, `mm`, `in`, `ft`).
    pub units: String,
    /// Scanner stations in metres, replacing the input's.
    pub stations: Option<Vec<[f64; 3]>>,
    pub params: ReconParams,
}

impl Reconstruct {
    /// The pipeline's parameters from the tool's options (the rest stay at their defaults).
    #[allow(clippy::too_many_arguments)]
    pub fn params(
        crop: Option<Bounds>,
        target_points: usize,
        reveal: Reveal,
        min_support: usize,
        epsilon: f64,
        seed: u64,
        edge_threshold: f64,
        min_area: f64,
    ) -> ReconParams {
        let (reveal_depth, measure_depth) = match reveal {
            Reveal::Auto => (0.2, true),
            Reveal::Depth(d) => (d, false),
        };
        let mut p = ReconParams {
            crop,
            target_points,
            reveal_depth,
            measure_depth,
            ..Default::default()
        };
        p.ransac.min_support = min_support;
        p.ransac.epsilon = epsilon;
        p.ransac.seed = seed;
        p.openings.edge_threshold = edge_threshold;
        p.openings.min_area = min_area;
        p
    }
}

/// One SVG per wall with its numbered candidates, in `dir`.
fn write_review(dir: &str, r: &crate::pipeline::Reconstruction, band: f64) -> Result<()> {
    std::fs::create_dir_all(dir).at_path(dir)?;
    for (fi, f) in r.model.faces.iter().enumerate() {
        if let Some(svg) = review::wall_svg(r, fi, band) {
            let path = Path::new(dir).join(format!("{}.svg", f.name));
            write_atomically(&path, |w| {
                w.write_all(svg.as_bytes())
                    .at_path(&path.display().to_string())
            })?;
        }
    }
    Ok(())
}

/// The note when no windows were cut: the candidates to choose from.
fn candidates_note(sum: &summary::Summary, auto_min_area: f64) -> String {
    let mut note = String::from("rrecon: no windows cut (use --auto or --windows); candidates:");
    for wc in &sum.candidates {
        for c in wc.candidates.iter().filter(|c| c.area >= auto_min_area) {
            note.push_str(&format!(
                " {}:{} ({:.2} m2{})",
                wc.wall,
                c.id,
                c.area,
                if c.auto { ", auto" } else { "" }
            ));
        }
    }
    note
}

/// Run the reconstruction: the `.rad` model to `a.output` or `out`, the review and JSON
/// files, and notes (candidates when none were cut, an open model) on `err`.
/// The steps are stages of `progress`.
pub fn reconstruct_run(
    a: &Reconstruct,
    out: &mut dyn Write,
    err: &mut dyn Write,
    progress: &dyn Progress,
) -> Result<()> {
    let input = a.input.as_str();
    let stage = Stage::uncounted(progress, "reading the scan");
    let mut cloud = read_cloud(input)?;
    drop(stage);
    let name = if input == "-" { "<stdin>" } else { input };
    let s = unit_scale(&a.units)?;
    if s != 1.0 {
        cloud.scale(s);
    }
    if let Some(st) = &a.stations {
        // The input's per-point station numbers still name its stations when as many are
        // given (the same survey, positions corrected); otherwise they name nothing.
        if st.len() != cloud.stations.len() {
            cloud.station_of = None;
        }
        cloud.stations = st.clone();
    }
    cloud.check(name)?;
    let p = &a.params;
    let materials = match &a.materials {
        Some(m) => Some(load_scene(m)?.0),
        None => None,
    };
    let r = reconstruct_reporting(cloud, p, &a.selection, progress)?;
    let mut polys = r.model.polygons();
    fix_t_junctions(&mut polys, 1e-6);
    let scene = radout::to_scene(&polys, materials.as_ref())?;
    if let Some(dir) = &a.review {
        write_review(dir, &r, p.openings.band)?;
    }
    let sum = summary::summarise(&r);
    if let Some(j) = &a.json {
        let text = serde_json::to_string_pretty(&sum).map_err(|e| Error::Usage(e.to_string()))?;
        write_atomically(Path::new(j), |w| w.write_all(text.as_bytes()).at_path(j))?;
    }
    if r.stations_assumed
        && let Some(st) = r.stations.first()
    {
        let _ = writeln!(
            err,
            "rrecon: note: {name} gives no scanner stations; windows were told from occlusion \
             shadows as seen from one assumed at {:.2},{:.2},{:.2} (give --stations)",
            st[0], st[1], st[2]
        );
    }
    if a.selection == Selection::None {
        let _ = writeln!(err, "{}", candidates_note(&sum, p.openings.auto_min_area));
    }
    if !r.watertight.is_closed() {
        let _ = writeln!(
            err,
            "rrecon: warning: the model is not closed ({:?})",
            r.watertight
        );
    }
    output(a.output.as_deref(), out, |w| {
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
