//! # Local obstruction near particular sensors
//!
//! Furniture, partitions or a column between a few sensors and the window take away part
//! of the light those sensors receive directly (sky seen through the window and sun), while
//! inter-reflected light still arrives. Parameters: the sensor group (all sensors within a
//! radius of a centre sensor) and the blocked fraction of their direct light. Signature:
//! deficits at a few neighbouring sensors, largest in sun hours, that no global effect
//! explains.

use super::{Effect, golden};
use crate::calib::fit::{Fitter, without};

/// Group radii tried (metres, horizontal).
pub const RADII: [f64; 4] = [0.0, 0.8, 1.3, 2.0];

/// Best group and fraction given the other effects.
pub fn fit(f: &Fitter, base: &[Effect]) -> Option<Effect> {
    let base = without(base, "local-obstruction");
    let w = f.m.weights(&base);
    let parts = f.m.parts(&w);
    let ns = f.m.nsens();
    let mut seen: Vec<Vec<usize>> = Vec::new();
    let mut best: Option<(Effect, f64)> = None;
    for c in 0..ns {
        for r in RADII {
            let group: Vec<usize> = (0..ns)
                .filter(|&s| f.m.sensor_distance(c, s) <= r + 1e-9)
                .collect();
            if group.len() > ns / 2 || seen.contains(&group) {
                continue;
            }
            seen.push(group.clone());
            let (x, s) = golden(
                &mut |x| {
                    let mut w2 = w.clone();
                    for &g in &group {
                        w2.local[g] *= 1.0 - x;
                    }
                    f.m2ll_parts(&parts, &w2)
                },
                0.0,
                1.0,
                24,
            );
            if best.as_ref().is_none_or(|b| s < b.1) {
                best = Some((
                    Effect::LocalObstruction {
                        sensors: group,
                        fraction: x,
                    },
                    s,
                ));
            }
        }
    }
    best.map(|b| b.0)
}
