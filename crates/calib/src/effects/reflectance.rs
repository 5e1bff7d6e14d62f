//! # Interior reflectances and ground albedo
//!
//! The reflectance of a surface class (walls, ceiling, floor, exterior ground) scaled by
//! `k`: only inter-reflected light changes, through the coefficients' re-weighting records
//! (exact polynomials in every class's reflectance, so scales of several classes combine
//! as they do in the room: [`crate::model::Refl`]). Signature: errors growing with depth from the window
//! (walls, ceiling), ceiling-lit sensors under a bright ground. Fitted in 0.4 .. 1.6 (ground: 0.3 .. 4).

use super::{Effect, golden};
use crate::fit::{Fitter, without};
use crate::room::SurfaceClass;

/// Best scale of `class` given the other effects; `None` when the model has no material of
/// that class.
pub fn fit(f: &Fitter, base: &[Effect], class: SurfaceClass) -> Option<Effect> {
    f.m.refl.as_ref().and_then(|r| r.index(class))?;
    let probe = Effect::Reflectance { class, scale: 1.0 };
    // The ground albedo varies far more (grass 0.1 .. snow 0.8) than interior finishes;
    // light reflected once by the ground is close to linear in it.
    let (lo, hi) = if class == SurfaceClass::Ground {
        (0.3, 4.0)
    } else {
        (0.4, 1.6)
    };
    let w0 = f.m.weights(&without(base, probe.family()));
    let (k, _) = golden(
        &mut |k| f.m2ll_on(&w0, &Effect::Reflectance { class, scale: k }),
        lo,
        hi,
        30,
    );
    Some(Effect::Reflectance { class, scale: k })
}
