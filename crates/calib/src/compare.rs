//! # Compare: where does the model fail?
//!
//! Statistics ([`Stats`], seed Eq. 6.1-6.4 and Pearson r) overall, per sensor and per time
//! step, and the data of the report's figures: measured against simulated readings; the
//! per-sensor bias against the distance from the window wall (the seed's chapter-6 finding:
//! errors grow with depth) and on the floor plan; the per-step bias against sun altitude,
//! Perez sky clearness and time.

use super::model::Model;
use super::stats::Stats;
use serde::Serialize;

/// One sensor's agreement.
#[derive(Debug, Clone, Serialize)]
pub struct SensorRow {
    pub id: String,
    pub x: f64,
    pub y: f64,
    pub z: f64,
    /// Distance from the nearest window wall (m).
    pub depth: f64,
    pub stats: Stats,
}

/// One time step's agreement.
#[derive(Debug, Clone, Serialize)]
pub struct StepRow {
    pub month: u32,
    pub day: u32,
    pub hour: f64,
    pub sun_altitude: f64,
    pub clearness: f64,
    pub dni: f64,
    pub dhi: f64,
    pub stats: Stats,
}

/// Everything `rcalib compare` reports about one model.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    pub label: String,
    pub overall: Stats,
    pub sensors: Vec<SensorRow>,
    pub steps: Vec<StepRow>,
    /// (measured, simulated, sensor index, step index) of every reading.
    pub scatter: Vec<(f64, f64, usize, usize)>,
    /// Window outlines in plan: (x0, y0, x1, y1).
    pub windows: Vec<[f64; 4]>,
    /// The floor's outline in plan, one (x0, y0, x1, y1) per edge.
    pub outline: Vec<[f64; 4]>,
}

/// Compare simulated readings `sim` (in observation order) with the measured ones.
pub fn compare(m: &Model, sim: &[f64], label: &str) -> Comparison {
    let pairs = |f: &dyn Fn(usize, usize) -> bool| -> Vec<(f64, f64)> {
        m.obs
            .iter()
            .zip(sim)
            .filter(|(o, _)| f(o.sensor, o.step))
            .map(|(o, y)| (*y, o.value))
            .collect()
    };
    let sensors = m
        .sensors
        .iter()
        .enumerate()
        .map(|(i, s)| SensorRow {
            id: s.id.clone(),
            x: s.ray.org[0],
            y: s.ray.org[1],
            z: s.ray.org[2],
            depth: m.room.depth(s.ray.org),
            stats: Stats::of(&pairs(&|a, _| a == i)),
        })
        .collect();
    let steps = m
        .skies
        .iter()
        .enumerate()
        .map(|(t, sk)| StepRow {
            month: sk.month,
            day: sk.day,
            hour: sk.hour,
            sun_altitude: sk.sun_altitude_deg,
            clearness: sk.clearness,
            dni: sk.dni,
            dhi: sk.dhi,
            stats: Stats::of(&pairs(&|_, b| b == t)),
        })
        .collect();
    let windows = m
        .room
        .windows
        .iter()
        .map(|w| {
            let cu = super::room::dot(w.centroid, w.tangent);
            let at = |u: f64| {
                [
                    w.centroid[0] + w.tangent[0] * (u - cu),
                    w.centroid[1] + w.tangent[1] * (u - cu),
                ]
            };
            let (a, b) = (at(w.span.0), at(w.span.1));
            [a[0], a[1], b[0], b[1]]
        })
        .collect();
    Comparison {
        label: label.to_string(),
        overall: Stats::of(&pairs(&|_, _| true)),
        sensors,
        steps,
        scatter: m
            .obs
            .iter()
            .zip(sim)
            .map(|(o, y)| (o.value, *y, o.sensor, o.step))
            .collect(),
        windows,
        outline: m.room.outline.clone(),
    }
}
