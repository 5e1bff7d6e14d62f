//! `light`, `glow` and `illum`: emitting materials (`src/rt/source.c`, `doc/ray.1`).
//!
//! All three emit a constant radiance (W/sr/m^2 per channel) from the front side; the back
//! is black (`m_light` with `-bv+`). Which ones are *direct sources* (next-event targets,
//! `marksources`) and what an indirect ray may see of them (`badcomponent`, `distglow`):
//!
//! | material | direct source | indirect (ambient / Gaussian-specular) ray that hits it |
//! |---|---|---|
//! | `light` | yes, unless all channels <= 1e-6 | discarded (black): NEE counted it |
//! | `illum` | yes (same rule) | discarded from the front; from the back it is its alternate |
//! | `glow`, maxrad > 0, not on `source` | yes, for points within maxrad | seen beyond maxrad, discarded within |
//! | `glow`, maxrad = 0 | never | seen (needs `-ab >= 1`) |
//! | `glow`, maxrad < 0 | never | discarded: never illuminates |
//! | `glow` on a `source` primitive | skipped (`SSKIP`) | seen (distance is infinite) |
//!
//! Primary and pure-specular rays always see the emitted radiance of `light` and `glow`
//! (`-dv+`). An `illum` is only a source for shadow rays aimed at it; every other ray that
//! reaches it (primary, pure specular, from the back, shadow rays aimed at a `light`) sees
//! its alternate material, or passes straight through when that is `void` (`passillum`).
//! A shadow ray aimed at a weak source (`glow`/`illum`) that hits an `illum`'s front is
//! blocked (`illumblock`). [`Emitter::emission`] therefore returns black for `illum`;
//! next-event estimation uses [`Emitter::source_radiance`].

use super::sampling::{FTINY, V3, dot};
use super::{Color, Surface};

#[derive(Debug, Clone, PartialEq)]
pub enum EmitterKind {
    Light,
    Glow { max_radius: f64 },
    Illum { alternate: Option<String> },
}

#[derive(Debug, Clone, PartialEq)]
pub struct Emitter {
    /// Radiance in the run's channels.
    pub color: Color,
    pub kind: EmitterKind,
}

impl Emitter {
    /// Radiance a primary or pure-specular ray sees toward `wo`: the colour from the front,
    /// black from the back, black for `illum` (see the module table).
    pub fn emission(&self, wo: V3, s: &Surface) -> Color {
        if matches!(self.kind, EmitterKind::Illum { .. }) {
            return Color::black(self.color.ncomp());
        }
        self.source_radiance(wo, s)
    }

    /// Radiance a shadow ray aimed at this source receives from it (front side only).
    pub fn source_radiance(&self, wo: V3, s: &Surface) -> Color {
        if dot(wo, s.normal) > 0.0 {
            self.color
        } else {
            Color::black(self.color.ncomp())
        }
    }

    /// Whether surfaces with this material become next-event sources;
    /// `on_source_primitive` for Radiance's distant `source` objects.
    pub fn is_direct_source(&self, on_source_primitive: bool) -> bool {
        if self.color.max() <= FTINY {
            return false;
        }
        match self.kind {
            EmitterKind::Light | EmitterKind::Illum { .. } => true,
            EmitterKind::Glow { max_radius } => !on_source_primitive && max_radius > FTINY,
        }
    }

    /// Whether an indirect (ambient or Gaussian-specular) ray that hits this emitter's front
    /// at `distance` keeps the emitted radiance (Radiance's `badcomponent`/`distglow`).
    /// `illum` returns false: such rays see its alternate material instead.
    pub fn counts_for_indirect(&self, distance: f64) -> bool {
        match self.kind {
            EmitterKind::Glow { max_radius } => max_radius >= -FTINY && distance > max_radius,
            _ => false,
        }
    }

    /// The material an `illum` shows to rays that are not aimed at it as a source.
    pub fn alternate(&self) -> Option<&str> {
        match &self.kind {
            EmitterKind::Illum { alternate } => alternate.as_deref(),
            _ => None,
        }
    }
}
