//! The whole reconstruction: cloud -> preprocessing -> RANSAC planes -> shell -> windows ->
//! model, with timings for the JSON summary.

use super::cloud::{Bounds, PointCloud};
use super::model::{FaceKind, Model, Watertight, fix_t_junctions, watertight};
use super::openings::{self, Candidate, OpeningParams, Selection};
use super::preprocess;
use super::ransac::{self, RansacParams};
use super::shell::{self, Shell, ShellParams};
use super::visibility::{Views, assumed_station};
use crate::error::{Error, Result};
use rdaylight_base::progress::{Progress, QUIET, Stage};
use std::time::Instant;

/// Everything the pipeline can be told.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ReconParams {
    pub crop: Option<Bounds>,
    /// Target point count after voxel down-sampling (seed: ~100,000).
    pub target_points: usize,
    pub sor_k: usize,
    pub sor_std: f64,
    pub normal_k: usize,
    pub ransac: RansacParams,
    pub shell: ShellParams,
    pub openings: OpeningParams,
    /// Reveal (wall thickness) depth, metres; per window from its reveal points when
    /// `measure_depth` is set (this value is then the fallback).
    pub reveal_depth: f64,
    pub measure_depth: bool,
}

impl Default for ReconParams {
    fn default() -> Self {
        ReconParams {
            crop: None,
            target_points: 100_000,
            sor_k: 8,
            sor_std: 3.0,
            normal_k: 16,
            ransac: RansacParams::default(),
            shell: ShellParams::default(),
            openings: OpeningParams::default(),
            reveal_depth: 0.2,
            measure_depth: true,
        }
    }
}

/// Stage timings in seconds.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Timings {
    pub preprocess: f64,
    pub planes: f64,
    pub shell: f64,
    pub windows: f64,
    pub total: f64,
}

/// The result: the processed cloud, the shell, window candidates and the final model.
#[derive(Debug, Clone)]
pub struct Reconstruction {
    pub cloud: PointCloud,
    pub spacing: f64,
    pub shell: Shell,
    /// Candidates per model face (walls only; others empty).
    pub candidates: Vec<Vec<Candidate>>,
    pub model: Model,
    pub watertight: Watertight,
    pub timings: Timings,
    pub input_points: usize,
    /// The scanner stations the window ranking used, and whether they were assumed.
    pub stations: Vec<[f64; 3]>,
    pub stations_assumed: bool,
}

/// Median nearest-neighbour distance of (a sample of) the points.
pub fn spacing(points: &[[f64; 3]]) -> f64 {
    if points.len() < 2 {
        return 0.0;
    }
    let tree = preprocess::kdtree(points);
    let step = (points.len() / 2000).max(1);
    let mut d: Vec<f64> = points
        .iter()
        .step_by(step)
        .map(|p| preprocess::knn(&tree, p, 2).get(1).map_or(0.0, |n| n.0))
        .collect();
    d.sort_by(f64::total_cmp);
    d[d.len() / 2]
}

/// Run the pipeline on a checked cloud; `select` says which window candidates to cut.
pub fn reconstruct(
    cloud: PointCloud,
    p: &ReconParams,
    select: &Selection,
) -> Result<Reconstruction> {
    reconstruct_reporting(cloud, p, select, &QUIET)
}

/// [`reconstruct`], its steps (preprocessing, planes, shell, windows) reported as stages of
/// `progress`.
pub fn reconstruct_reporting(
    mut cloud: PointCloud,
    p: &ReconParams,
    select: &Selection,
    progress: &dyn Progress,
) -> Result<Reconstruction> {
    let t0 = Instant::now();
    let stage = Stage::uncounted(progress, "preprocessing the scan");
    let input_points = cloud.len();
    if let Some(b) = &p.crop {
        preprocess::crop(&mut cloud, b);
    }
    // Before down-sampling, which merges the stations' samples.
    let steps = preprocess::angular_steps(&cloud);
    let voxel = preprocess::voxel_downsample(&mut cloud, p.target_points);
    let strays = preprocess::take_outliers(&mut cloud, p.sor_k, p.sor_std);
    let spacing = voxel.unwrap_or_else(|| spacing(&cloud.points));
    if cloud.len() < 4 * p.ransac.min_support.max(10) {
        return Err(Error::Usage(format!(
            "{} points left after preprocessing; a room needs at least {} (lower --min-support?)",
            cloud.len(),
            4 * p.ransac.min_support
        )));
    }
    preprocess::estimate_normals(&mut cloud, p.normal_k);
    drop(stage);
    let t1 = Instant::now();
    let normals = cloud.normals.clone().unwrap_or_default();
    // The bitmap must bridge the sampling gaps, or one wall falls apart into many components.
    let rp = RansacParams {
        bitmap_resolution: p.ransac.bitmap_resolution.max(1.5 * spacing),
        ..p.ransac.clone()
    };
    let stage = Stage::uncounted(progress, "planes (RANSAC)");
    let planes = ransac::detect(&cloud.points, &normals, &rp);
    drop(stage);
    let t2 = Instant::now();
    let sp = ShellParams {
        coverage_cell: p.shell.coverage_cell.max(2.5 * spacing),
        ..p.shell.clone()
    };
    let stage = Stage::uncounted(progress, "watertight shell (min cut)");
    let prepared = shell::prepare_planes(&planes, &cloud.points, &normals, &sp);
    let shell = shell::select(prepared, &cloud.points, &normals, &sp);
    drop(stage);
    if !shell.model.faces.iter().any(|f| f.kind == FaceKind::Floor) {
        return Err(Error::Usage(format!(
            "no floor found among {} planes; is +z up and the cloud a room?",
            planes.len()
        )));
    }
    let t3 = Instant::now();
    let op = OpeningParams {
        ..p.openings.clone()
    };
    let stage = Stage::uncounted(progress, "windows");
    // Stations: the input's (E57 poses, PLY comments, --stations), else the one a
    // single-scan survey would use (visibility module documentation).
    let (stations, stations_assumed) = if cloud.stations.is_empty() {
        (assumed_station(&shell.model).into_iter().collect(), true)
    } else {
        (cloud.stations.clone(), false)
    };
    // Grid cells of 1.5 point spacings (at least 2 cm): every surface crossing a cell's
    // 3 x 3 x 3 block puts several points in it (visibility::MIN_POINTS).
    let views = Views::new(
        &shell.model,
        &cloud.points,
        &stations,
        op.band,
        (1.5 * spacing).max(0.02),
    );
    let views = if stations_assumed {
        views
    } else {
        views.with_steps(steps, op.edge_threshold)
    };
    let candidates = openings::detect_all(&shell, &cloud, &strays, &views, spacing, &op);
    let mut model = shell.model.clone();
    model.reveal_depth = p.reveal_depth;
    model.openings = openings::choose(&shell, &candidates, select, p.measure_depth)?;
    let mut polys = model.polygons();
    fix_t_junctions(&mut polys, 1e-6);
    let wt = watertight(&polys, 1e-6);
    drop(stage);
    let t4 = Instant::now();
    let s = |a: Instant, b: Instant| (b - a).as_secs_f64();
    Ok(Reconstruction {
        cloud,
        spacing,
        shell,
        candidates,
        model,
        watertight: wt,
        timings: Timings {
            preprocess: s(t0, t1),
            planes: s(t1, t2),
            shell: s(t2, t3),
            windows: s(t3, t4),
            total: s(t0, t4),
        },
        input_points,
        stations,
        stations_assumed,
    })
}
