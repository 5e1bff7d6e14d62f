//! `mirror`: pure specular reflection with a colour (`src/rt/m_mirror.c`, `doc/ray.1`).
//!
//! One-sided: the back of a mirror is black (with Radiance's default `-bv+`). The reflected
//! ray carries the colour. In Radiance a mirror is also a *virtual source* generator (`-dr`
//! reflections of sources; `mirror_vs`), which is the integrator's business, and a mirror
//! with an alternate material shows that material to rays that are not virtual-source
//! rays and come from the back or are not ambient/specular samples (`passOK`).
//! Shadow rays that hit a mirror outside a virtual-source calculation are blocked.

use super::sampling::{V3, dot, reflect};
use super::{Color, Sample, SampleKind, Surface};

#[derive(Debug, Clone, PartialEq)]
pub struct Mirror {
    pub color: Color,
    /// Alternate material name (`void` is stored as `None`).
    pub alternate: Option<String>,
}

impl Mirror {
    /// The mirror direction with weight `color`; `None` from the back (black).
    pub fn sample(&self, wo: V3, s: &Surface) -> Option<Sample> {
        if dot(wo, s.normal) <= 0.0 {
            return None;
        }
        Some(Sample {
            wi: reflect(wo, s.normal),
            weight: self.color,
            kind: SampleKind::PureReflect,
        })
    }
}
