//! The JSON summary of a reconstruction: planes, faces and their areas, windows,
//! window-to-wall and window-to-floor ratios, watertightness, timings, and the window
//! candidates per wall (what `--windows` refers to).

use super::model::{FaceKind, Watertight};
use super::openings::Candidate;
use super::pipeline::{Reconstruction, Timings};
use super::shell::ShellPlane;
use crate::geometry::polygon_area;

#[derive(Debug, Clone, serde::Serialize)]
pub struct FaceSummary {
    pub name: String,
    pub kind: FaceKind,
    pub area: f64,
    pub normal: [f64; 3],
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct WindowSummary {
    pub name: String,
    pub wall: String,
    pub area: f64,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct WallCandidates {
    pub wall: String,
    pub candidates: Vec<Candidate>,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct Summary {
    pub input_points: usize,
    pub used_points: usize,
    pub spacing: f64,
    pub planes: Vec<ShellPlane>,
    pub faces: Vec<FaceSummary>,
    pub windows: Vec<WindowSummary>,
    pub floor_area: f64,
    pub wall_area: f64,
    pub ceiling_area: f64,
    pub window_area: f64,
    /// Window-to-wall ratio: glazing over gross wall area.
    pub wwr: f64,
    /// Window-to-floor ratio: glazing over floor area.
    pub wfr: f64,
    pub watertight: bool,
    pub edges: Watertight,
    pub cells: usize,
    pub timings: Timings,
    /// Scanner stations used to tell windows from occlusion shadows; `stations_assumed` when
    /// the input gave none.
    pub stations: Vec<[f64; 3]>,
    pub stations_assumed: bool,
    pub candidates: Vec<WallCandidates>,
}

pub fn summarise(r: &Reconstruction) -> Summary {
    let m = &r.model;
    let faces = m
        .faces
        .iter()
        .map(|f| FaceSummary {
            name: f.name.clone(),
            kind: f.kind,
            area: polygon_area(&f.polygon),
            normal: crate::geometry::triangulate::newell_normal(&f.polygon)
                .normalize()
                .to_array(),
        })
        .collect();
    let windows = m
        .openings
        .iter()
        .map(|o| WindowSummary {
            name: o.name.clone(),
            wall: m.faces[o.face].name.clone(),
            area: polygon_area(&o.outline),
        })
        .collect();
    let (floor, wall, ceiling) = (
        m.area(FaceKind::Floor),
        m.area(FaceKind::Wall),
        m.area(FaceKind::Ceiling),
    );
    let win = m.opening_area();
    Summary {
        input_points: r.input_points,
        used_points: r.cloud.len(),
        spacing: r.spacing,
        planes: r.shell.planes.clone(),
        faces,
        windows,
        floor_area: floor,
        wall_area: wall,
        ceiling_area: ceiling,
        window_area: win,
        wwr: if wall > 0.0 { win / wall } else { 0.0 },
        wfr: if floor > 0.0 { win / floor } else { 0.0 },
        watertight: r.watertight.is_closed(),
        edges: r.watertight,
        cells: r.shell.cells,
        timings: r.timings.clone(),
        stations: r.stations.clone(),
        stations_assumed: r.stations_assumed,
        candidates: m
            .faces
            .iter()
            .zip(&r.candidates)
            .filter(|(f, _)| f.kind == FaceKind::Wall)
            .map(|(f, c)| WallCandidates {
                wall: f.name.clone(),
                candidates: c.clone(),
            })
            .collect(),
    }
}
