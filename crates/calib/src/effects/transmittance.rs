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

/// How the per-channel normal transmittances of a coloured glass become one figure: each
/// use needs its own, so the choice is the caller's, written where it is used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Summary {
    /// The luminous (photopic) value `w . T` with Radiance's RGB weights
    /// ([`crate::radiometry::photopic`]): how a glazing's normal transmittance (its visible
    /// light transmittance) is quoted, and the level a neutral stand-in for the glass must
    /// have. The mean of the channels when there are not three.
    Luminous,
    /// The most transmissive channel: a bound (a factor capped at `1 / T` keeps every
    /// channel's transmission at or below 1).
    Max,
}

/// Normal-incidence transmittance of a Radiance `glass` from its arguments, the per-channel
/// *transmissivities* `tn` (`glass.c`: one pass transmits `tn`, Fresnel reflections at both
/// faces and the inter-reflections between them; 0.96 gives the usual 0.88), summarised by
/// `summary`. Each channel goes through the glass first and is summarised after, so a
/// coloured glass's luminous transmittance is the weighted transmittance, not the
/// transmittance of a weighted transmissivity.
pub fn normal_transmittance(transmissivity: &[f64], index: Option<f64>, summary: Summary) -> f64 {
    let t: Vec<f64> = transmissivity
        .iter()
        .map(|&tn| transmission(tn, index.unwrap_or(1.52), 1.0))
        .collect();
    match (summary, t.as_slice()) {
        (Summary::Max, _) => t.iter().copied().fold(0.0, f64::max),
        (Summary::Luminous, &[r, g, b]) => crate::radiometry::photopic([r, g, b]),
        (Summary::Luminous, _) => t.iter().sum::<f64>() / t.len().max(1) as f64,
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Pins the one home of a glass's normal transmittance: transmissivity 0.96 is the
    /// usual 0.88 (Radiance reference manual, `glass`: transmissivity = 1.0895 x
    /// transmittance at n = 1.52, so 0.96 / 1.0895 = 0.881); a neutral glass has the same figure
    /// either way; a coloured one is summarised by its luminous value (photopic weights of
    /// the per-channel transmittances) or bounded by its most transmissive channel.
    #[test]
    fn normal_transmittance_of_neutral_and_coloured_glass() {
        let neutral = normal_transmittance(&[0.96; 3], None, Summary::Luminous);
        assert!((neutral - 0.96 / 1.0895).abs() < 1e-3, "{neutral}");
        let max = normal_transmittance(&[0.96; 3], None, Summary::Max);
        assert!((neutral - max).abs() < 1e-12, "{neutral} {max}");
        let c = [0.9, 0.6, 0.3];
        let t: Vec<f64> = c.iter().map(|&tn| transmission(tn, 1.52, 1.0)).collect();
        let lum = normal_transmittance(&c, None, Summary::Luminous);
        let w = crate::radiometry::RGB_PHOTOPIC;
        assert!((lum - (w[0] * t[0] + w[1] * t[1] + w[2] * t[2])).abs() < 1e-12);
        assert!((normal_transmittance(&c, None, Summary::Max) - t[0]).abs() < 1e-12);
        // Not the mean of the channels (what spectral.rs took before: a coloured glass's
        // quoted transmittance weighs green most).
        let mean = (t[0] + t[1] + t[2]) / 3.0;
        assert!((lum - mean).abs() > 0.02, "{lum} {mean}");
    }
}
