//! `glass`: Radiance's thin glass pane (`src/rt/glass.c`, `doc/ray.1`).
//!
//! Arguments: per-channel **transmissivity** `tn` at normal incidence (light not absorbed in
//! one pass through the pane) and an optional refractive index `n` (default 1.52). For a ray
//! at `pdot = cos(theta)` (normal turned toward the ray; orientation does not matter):
//!
//! ```text
//! cos2 = sqrt(1 - (1 - pdot^2)/n^2)            cosine inside the glass
//! t    = tn^(1/cos2)                           one pass at that angle (tn clamped >= 1e-15)
//! r1e  = ((pdot - n cos2)/(pdot + n cos2))^2   single-surface reflectance, s polarisation
//! r1m  = ((1/pdot - n/cos2)/(1/pdot + n/cos2))^2                          p polarisation
//! T    = 1/2 sum_{e,m} (1-r1)^2 t / (1 - r1^2 t^2)                 (all internal reflections)
//! R    = 1/2 sum_{e,m} r1 (1 + (1-2 r1) t^2) / (1 - r1^2 t^2)
//! ```
//!
//! giving one undeviated transmitted ray (weight `T`, also for shadow rays: glass passes
//! sunlight) and one mirror ray (weight `R`). Radiance computes this in RGB and converts the
//! coefficient to spectral bands with `setscolor`; because [`super::to_channels`] copies R, G
//! or B into each band, computing per band gives the same numbers.
//!
//! Transmittance vs transmissivity (`glass.c` header comment, for n = 1.52):
//! `tn = (sqrt(.8402528435 + .0072522239 Tn^2) - .9166530661) / .0036261119 / Tn`, the
//! positive root of `r^2 Tn t^2 + (1-r)^2 t - Tn = 0` with `r = ((n-1)/(n+1))^2 = .04258`
//! (the constants are `(1-r)^4, 4r^2, (1-r)^2, 2r^2`); 88 % transmittance is 0.96
//! transmissivity.

use super::sampling::{FTINY, V3, add, dot, neg, normalize, scale};
use super::{Color, Sample, SampleKind, Surface};

/// Radiance's default refractive index (`glass.c: RINDEX`).
pub const DEFAULT_INDEX: f64 = 1.52;

/// Radiance clamps transmissivities to this so `pow` stays finite (`glass.c`).
const MIN_TN: f64 = 1e-15;

/// A `glass` material.
#[derive(Debug, Clone, PartialEq)]
pub struct Glass {
    /// Normal-incidence transmissivity per channel, as given.
    pub transmissivity: Color,
    pub index: f64,
    /// Colour of the patterns modifying the glass (`r->pcol`, e.g. a `specfile` of the
    /// glazing's spectral transmittance): multiplies the transmission only (`glass.c`).
    pub pattern: Option<Color>,
}

impl Glass {
    pub fn new(transmissivity: Color, index: f64) -> Glass {
        Glass {
            transmissivity,
            index,
            pattern: None,
        }
    }

    /// The same glass under a pattern colour (see [`Glass::pattern`]).
    pub fn with_pattern(mut self, pattern: Option<Color>) -> Glass {
        self.pattern = pattern.filter(|p| p.ncomp() == self.transmissivity.ncomp());
        self
    }

    /// Radiance's `hastrans`: any channel above 1e-15 (`intens`). Opaque "glass" reflects only
    /// and blocks shadow rays.
    pub fn has_transmission(&self) -> bool {
        self.transmissivity.max() > MIN_TN
    }

    /// Transmission and reflection coefficients at `pdot = |cos(incidence)|`.
    pub fn coefficients(&self, pdot: f64) -> (Color, Color) {
        // pdot = 0 would make r1m 0/0; Radiance never shades an exactly grazing hit.
        let pdot = pdot.abs().clamp(1e-12, 1.0);
        let n = self.index;
        let cos2 = ((1.0 - 1.0 / (n * n)) + pdot * pdot / (n * n)).sqrt();
        let hastrans = self.has_transmission();
        let t = self.transmissivity.map(|x| {
            if hastrans {
                x.max(MIN_TN).powf(1.0 / cos2)
            } else {
                x
            }
        });
        let r1e = ((pdot - n * cos2) / (pdot + n * cos2)).powi(2);
        let r1m = ((1.0 / pdot - n / cos2) / (1.0 / pdot + n / cos2)).powi(2);
        let tr = if hastrans {
            t.map(|d| {
                0.5 * (1.0 - r1e).powi(2) * d / (1.0 - r1e * r1e * d * d)
                    + 0.5 * (1.0 - r1m).powi(2) * d / (1.0 - r1m * r1m * d * d)
            })
        } else {
            Color::black(t.ncomp())
        };
        let tr = match self.pattern {
            Some(p) => tr * p,
            None => tr,
        };
        let re = t.map(|d| {
            let d = d * d;
            0.5 * r1e * (1.0 + (1.0 - 2.0 * r1e) * d) / (1.0 - r1e * r1e * d)
                + 0.5 * r1m * (1.0 + (1.0 - 2.0 * r1m) * d) / (1.0 - r1m * r1m * d)
        });
        (tr, re)
    }

    /// Normal turned toward `wo` and `pdot`.
    fn orient(wo: V3, s: &Surface) -> (V3, f64) {
        let d = dot(wo, s.normal);
        if d < 0.0 {
            (neg(s.normal), -d)
        } else {
            (s.normal, d)
        }
    }

    /// The transmitted (undeviated) or reflected ray, chosen with probability proportional
    /// to its coefficient.
    pub fn sample(&self, wo: V3, s: &Surface, u1: f64) -> Option<Sample> {
        let (n, pdot) = Self::orient(wo, s);
        let (t, r) = self.coefficients(pdot);
        let (pt, pr) = (t.mean().max(0.0), r.mean().max(0.0));
        if pt + pr <= 0.0 {
            return None;
        }
        let p_t = pt / (pt + pr);
        if u1 < p_t {
            Some(Sample {
                wi: neg(wo),
                weight: t.scale(1.0 / p_t),
                kind: SampleKind::PureTransmit,
            })
        } else {
            Some(Sample {
                wi: normalize(add(neg(wo), scale(n, 2.0 * pdot))),
                weight: r.scale(1.0 / (1.0 - p_t)),
                kind: SampleKind::PureReflect,
            })
        }
    }

    /// Shadow rays pass with the transmission coefficient (unless the pane is opaque).
    pub fn shadow_transmission(&self, wo: V3, s: &Surface) -> Option<Color> {
        if !self.has_transmission() {
            return None;
        }
        let (_, pdot) = Self::orient(wo, s);
        Some(self.coefficients(pdot.max(FTINY)).0)
    }
}

/// Transmissivity `tn` of a pane with normal-incidence transmittance `tn_total`, Radiance's
/// published formula (n = 1.52 only). Zero for zero.
pub fn transmissivity_from_transmittance(tn_total: f64) -> f64 {
    if tn_total <= 0.0 {
        return 0.0;
    }
    ((0.8402528435 + 0.0072522239 * tn_total * tn_total).sqrt() - 0.9166530661)
        / 0.0036261119
        / tn_total
}

/// Transmissivity of a pane with normal-incidence transmittance `tn_total` and any index:
/// the same root as [`transmissivity_from_transmittance`] with the exact
/// `r = ((n-1)/(n+1))^2`, written as `2 Tn / ((1-r)^2 + sqrt((1-r)^4 + 4 r^2 Tn^2))` so it
/// does not cancel for small `Tn` (the published form loses ~3e-8/Tn to its rounded
/// constants).
pub fn transmissivity_for_index(tn_total: f64, index: f64) -> f64 {
    let r = ((index - 1.0) / (index + 1.0)).powi(2);
    let a = (1.0 - r).powi(2);
    2.0 * tn_total / (a + (a * a + 4.0 * r * r * tn_total * tn_total).sqrt())
}

/// Normal-incidence transmittance of a pane of transmissivity `tn` and index `n` (the
/// inverse of [`transmissivity_from_transmittance`] for n = 1.52):
/// `(1-r)^2 tn / (1 - r^2 tn^2)`, `r = ((n-1)/(n+1))^2`.
pub fn transmittance_from_transmissivity(tn: f64, index: f64) -> f64 {
    let r = ((index - 1.0) / (index + 1.0)).powi(2);
    (1.0 - r).powi(2) * tn / (1.0 - r * r * tn * tn)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn published_example_088_is_096() {
        let t = transmissivity_from_transmittance(0.88);
        assert!((t - 0.96).abs() < 0.002, "{t}");
        let back = transmittance_from_transmissivity(t, DEFAULT_INDEX);
        assert!((back - 0.88).abs() < 1e-6, "{back}");
    }

    #[test]
    fn normal_incidence_polarisations_agree() {
        let g = Glass::new(Color::splat(3, 0.96), DEFAULT_INDEX);
        let (t, _) = g.coefficients(1.0);
        let expect = transmittance_from_transmissivity(0.96, DEFAULT_INDEX);
        for &x in t.as_slice() {
            assert!((x as f64 - expect).abs() < 1e-6);
        }
    }
}
