//! # Local obstruction near particular sensors
//!
//! Furniture, partitions or a column between a few sensors and the window take away part
//! of the light those sensors receive directly (sky seen through the window and sun), while
//! inter-reflected light still arrives. Parameters: the sensor group (all sensors within a
//! radius of a centre sensor) and the fraction of the window's elevation span a panel in
//! front of them hides; the panel is the one `rcalib apply` writes, traced ray by ray for
//! every sensor's direct view. Signature:
//! deficits at a few neighbouring sensors, largest in sun hours, that no global effect
//! explains.

use super::{Effect, golden, smooth_step};
use crate::apply::local_panel;
use crate::fit::{Fitter, without};
use crate::model::{Model, Weights};

/// Group radii tried (metres, horizontal).
pub const RADII: [f64; 4] = [0.0, 0.8, 1.3, 2.0];

/// Multiply the direct-light weights by what the panel `rcalib apply` writes for this
/// effect ([`local_panel`]) leaves: per sensor, the sky cells it sees through a window
/// ([`crate::effects::obstruction::Horizon`]) and the sun, ray by ray. Every sensor
/// behind the panel loses light, not only the group's. The panel's shadow on the floor and
/// the light it reflects are not modelled (small beside the direct light it blocks).
pub fn apply(e: &Effect, m: &Model, w: &mut Weights) {
    let Effect::LocalObstruction { sensors, fraction } = e else {
        return;
    };
    let Ok(panel) = local_panel(&m.room, &m.sensors, sensors, *fraction) else {
        return;
    };
    let Some(win) = m.room.windows.get(panel.window) else {
        return;
    };
    let hz = m.horizon();
    let (ns, np, nt) = (m.nsens(), m.comps.npatch, m.nsteps());
    let left = |org: [f64; 3], d: [f64; 3]| match panel.lowest_crossing(win, org, d) {
        Some(z) => 1.0 - smooth_step(panel.top - z, 0.01),
        None => 1.0,
    };
    let mut wd = w.win_dir.take().unwrap_or_else(|| vec![1.0; ns * np]);
    let mut sd = w.sun_win_dir.take().unwrap_or_else(|| vec![1.0; ns * nt]);
    for (s, sensor) in m.sensors.iter().enumerate() {
        let org = sensor.ray.org;
        for p in 1..np {
            if let Some(v) = hz.direct_mean(s, p, |c| left(org, c)) {
                wd[s * np + p] *= v;
            }
        }
        for (t, sk) in m.skies.iter().enumerate() {
            if sk.sun_altitude_deg > 0.0 {
                sd[s * nt + t] *= left(org, sk.sun_dir);
            }
        }
    }
    w.win_dir = Some(wd);
    w.sun_win_dir = Some(sd);
}

/// Best group and fraction given the other effects.
pub fn fit(f: &Fitter, base: &[Effect]) -> Option<Effect> {
    let base = without(base, "local-obstruction");
    let w0 = f.m.weights(&base);
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
                    f.m2ll_on(
                        &w0,
                        &Effect::LocalObstruction {
                            sensors: group.clone(),
                            fraction: x,
                        },
                    )
                },
                0.0,
                1.0,
                20,
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
