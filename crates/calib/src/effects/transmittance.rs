//! # Glazing transmittance scale
//!
//! Dirt, ageing and coatings change how much daylight the glazing lets through (the seed's
//! chapter 6 tunes exactly this). The effect scales the glass *transmissivity* `tn` by `k`
//! (what `rcalib apply` writes). Radiance's glass transmits `tn^(1/cos θ_t)` per pass with
//! Fresnel reflections at both faces (`glass.c`; [`crate::material::glass::Glass`]), so the
//! light entering from a direction at incidence θ scales by `T(θ; k tn) / T(θ; tn)`: a
//! little more at grazing incidence (low sun, sky near the horizon) than at normal
//! incidence. Signature: an almost uniform relative bias at every sensor and time.
//! Fitted on a log scale between 0.05 and the scale that makes the transmissivity 1.

use super::{Effect, golden};
use crate::fit::{Fitter, without};
use crate::material::Color;
use crate::material::glass::Glass;
use crate::model::{Model, Weights};
use crate::room::{Room, dot};

fn transmission(tn: f64, index: f64, cos: f64) -> f64 {
    let g = Glass::new(Color::splat(1, tn.clamp(0.0, 1.0)), index);
    f64::from(
        g.coefficients(cos)
            .0
            .as_slice()
            .first()
            .copied()
            .unwrap_or(0.0),
    )
}

/// Relative change of the light arriving from direction `d` through the room's windows
/// when the transmissivity is scaled by `k`.
pub fn ratio(room: &Room, k: f64, d: [f64; 3]) -> f64 {
    let at = |c: f64| {
        let base = transmission(room.glass_tn, room.glass_index, c);
        if base > 0.0 {
            transmission(room.glass_tn * k, room.glass_index, c) / base
        } else {
            k
        }
    };
    let (mut num, mut den) = (0.0, 0.0);
    for w in &room.windows {
        let c = dot(d, w.outward);
        if c > 1e-3 {
            num += w.area * c * at(c);
            den += w.area * c;
        }
    }
    // Light from directions no window faces (ground, behind) arrives through some window at
    // a typical 60 degree incidence.
    if den > 0.0 { num / den } else { at(0.5) }
}

/// Multiply the patch and sun weights by the transmission ratio.
pub fn apply(e: &Effect, m: &Model, w: &mut Weights) {
    let Effect::Transmittance { scale } = *e else {
        return;
    };
    for p in 0..m.comps.npatch {
        w.patch[p] *= ratio(&m.room, scale, m.patches.centre(p));
    }
    for (t, sk) in m.skies.iter().enumerate() {
        if sk.sun_altitude_deg > 0.0 {
            w.sun[t] *= ratio(&m.room, scale, sk.sun_dir);
        }
    }
}

/// Best transmissivity scale given the other effects in `base`.
pub fn fit(f: &Fitter, base: &[Effect]) -> Option<Effect> {
    let w0 = f.m.weights(&without(base, "transmittance"));
    let (x, _) = golden(
        &mut |lt: f64| f.m2ll_on(&w0, &Effect::Transmittance { scale: lt.exp() }),
        0.05f64.ln(),
        // A transmissivity above 1 is not glass (and `apply` caps it there): beyond that
        // the profile is flat and the search would wander to the bound.
        (1.0 / f.m.room.glass_tn.max(0.5)).clamp(1.0, 2.0).ln(),
        40,
    );
    Some(Effect::Transmittance { scale: x.exp() })
}
