//! # Exterior obstruction: a horizon sector
//!
//! Buildings or trees opposite the window hide the sky below a horizon profile. The profile
//! is one sector: azimuth `a` (east of north), half width `w`, altitude `h`. A sky patch is
//! blocked in proportion to its part behind the profile (8 x 8 directions per patch,
//! weighted by the windows' projected area towards them), a sun when it stands behind it (edges
//! smoothed over half a degree so the fit sees a continuous profile). The obstruction is
//! taken as black: a facade of reflectance 0.1-0.2 sends back a few percent of the blocked
//! sky's light, which the fitted altitude absorbs. Signature: deficits that depend on which
//! part of the sky each sensor sees and on the sun's azimuth and altitude.

use super::{Effect, golden, smooth_step};
use crate::calib::fit::{Fitter, without};
use crate::calib::model::{Model, Weights};
use crate::calib::room::dot;
use std::f64::consts::PI;

/// Signed angle difference a - b wrapped to (-180, 180] degrees.
pub fn wrap_deg(d: f64) -> f64 {
    let x = (d + 180.0).rem_euclid(360.0) - 180.0;
    if x == -180.0 { 180.0 } else { x }
}

/// Multiply the patch and sun weights by what the sector leaves visible.
pub fn apply(e: &Effect, m: &Model, w: &mut Weights) {
    let Effect::Obstruction {
        azimuth,
        half_width,
        altitude,
    } = *e
    else {
        return;
    };
    let p = &m.patches;
    // Blocked share of each patch from an 8 x 8 grid of directions uniform in solid
    // angle, weighted by how squarely they face a window (light arrives through the
    // windows in proportion to the projected opening): the linear share of the patch's
    // altitude band overestimates the blocking of low, grazing parts of a patch.
    const N: usize = 8;
    for i in 1..p.len() {
        let (mut blocked, mut total) = (0.0, 0.0);
        for a in 0..N {
            for b in 0..N {
                let d = p.sample(i, (a as f64 + 0.5) / N as f64, (b as f64 + 0.5) / N as f64);
                let wgt = m
                    .room
                    .windows
                    .iter()
                    .map(|w| w.area * dot(d, w.outward).max(0.0))
                    .sum::<f64>()
                    .max(1e-9);
                let alt = d[2].clamp(-1.0, 1.0).asin().to_degrees();
                let azi = d[0].atan2(d[1]).to_degrees();
                let inside = half_width >= 180.0 || wrap_deg(azi - azimuth).abs() <= half_width;
                if inside && alt < altitude {
                    blocked += wgt;
                }
                total += wgt;
            }
        }
        w.patch[i] *= 1.0 - blocked / total;
    }
    for (t, sk) in m.skies.iter().enumerate() {
        if sk.sun_altitude_deg <= 0.0 {
            continue;
        }
        let d = wrap_deg(sk.sun_azimuth_deg - azimuth).abs();
        let inside = smooth_step(half_width - d, 0.5);
        let behind = smooth_step(altitude - sk.sun_altitude_deg, 0.5);
        w.sun[t] *= 1.0 - inside * behind;
    }
}

/// Outward azimuths (degrees east of north) of the room's windows.
pub fn window_azimuths(m: &Model) -> Vec<f64> {
    let mut a: Vec<f64> = m
        .room
        .windows
        .iter()
        .map(|w| (w.outward[0].atan2(w.outward[1]) * 180.0 / PI).rem_euclid(360.0))
        .map(|x| (x / 5.0).round() * 5.0)
        .collect();
    a.sort_by(f64::total_cmp);
    a.dedup();
    if a.is_empty() {
        a.push(180.0);
    }
    a
}

/// Best sector given the other effects: centres every 15 degrees within 90 degrees of each
/// window's outward direction, a few half widths, the altitude by golden section; the best
/// is refined on a 5-degree grid.
pub fn fit(f: &Fitter, base: &[Effect]) -> Option<Effect> {
    let base = without(base, "obstruction");
    let eval = |a: f64, hw: f64, h: f64| {
        let mut e = base.clone();
        e.push(Effect::Obstruction {
            azimuth: a,
            half_width: hw,
            altitude: h,
        });
        f.score(&e).m2ll
    };
    let best_h = |a: f64, hw: f64| golden(&mut |h| eval(a, hw, h), 0.0, 70.0, 18);
    let mut best: Option<(f64, f64, f64, f64)> = None;
    for wa in window_azimuths(f.m) {
        for k in -6..=6 {
            let a = (wa + 15.0 * k as f64).rem_euclid(360.0);
            for hw in [15.0, 30.0, 45.0, 60.0, 90.0] {
                let (h, s) = best_h(a, hw);
                if best.is_none_or(|b| s < b.3) {
                    best = Some((a, hw, h, s));
                }
            }
        }
    }
    let (mut a0, mut hw0, mut h0, mut s0) = best?;
    for da in [-10.0, -5.0, 0.0, 5.0, 10.0] {
        for dw in [-10.0, -5.0, 0.0, 5.0, 10.0] {
            let (a, hw) = ((a0 + da).rem_euclid(360.0), (hw0 + dw).max(5.0));
            let (h, s) = best_h(a, hw);
            if s < s0 {
                (a0, hw0, h0, s0) = (a, hw, h, s);
            }
        }
    }
    let _ = s0;
    Some(Effect::Obstruction {
        azimuth: a0,
        half_width: hw0,
        altitude: h0,
    })
}
