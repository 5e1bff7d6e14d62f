//! Distant `source` primitives: the sun (`light`) and the sky and ground (`glow`), and what a
//! ray that leaves the scene sees.
//!
//! Radiance (`src/rt/source.c`, radiance-notes.md 5.3):
//! - A `source` is a cone of directions around its unit direction `sloc` with full apex
//!   `angle`; its solid angle is `ss2 = 2 pi (1 - cos(angle/2))` (the sun at 0.533 degrees:
//!   6.8e-5 sr). A direction `d` is inside when `2 pi (1 - sloc . d) <= ss2`, so a 180-degree
//!   source contains the horizon and a 360-degree source every direction.
//! - `light` on a `source` is a *direct* source (next-event estimation; -dj 0 aims at its
//!   centre). `glow` on a `source` is skipped as a direct source (`SSKIP`) and only seen by
//!   rays that escape. A source whose material radiance is zero (all channels <= FTINY) is no
//!   source at all: nothing sees it.
//! - `sourcehit` (for a ray that misses every surface and is not aimed at one source) walks
//!   the sources in scene order: the first *non-glow* source whose cone contains the
//!   direction wins; otherwise the **first** glow whose cone contains it. Verified with the
//!   installed RADIANCE 6.0a: a 180-degree glow of radiance 1 defined before a 360-degree glow
//!   of radiance 5, both towards +Z: rtrace reads 1 looking up and 5 looking down. (Older
//!   source.c versions kept the last glow; 6.0a keeps the first.)
//! - A glow's radiance is modulated by its patterns: the sky functions of `gensky`
//!   (`brightfunc skyfunc 2 skybr skybright.cal 0 N A1..`) and `gendaylit`
//!   (`brightfunc skyfunc 2 skybright perezlum.cal 0 10 A1..A10`) are evaluated natively
//!   ([`crate::sky::cie::skybright`], [`crate::sky::perez::perezlum`]) at the escaping ray's
//!   direction (`Dx Dy Dz`); genssky's `specpict` sky by [`crate::sky::specpict`]; any other
//!   function-file pattern (and those two with a transform) by the `.cal` evaluator
//!   ([`crate::calc::pattern`]).

use crate::geometry::Vec3;
use crate::material::Color;

/// A brightness pattern on a distant glow.
#[derive(Debug, Clone, PartialEq)]
pub enum SkyPattern {
    /// No pattern: constant radiance.
    Uniform,
    /// `skybright.cal` `skybr` with gensky's real arguments.
    SkyBright(Vec<f64>),
    /// `perezlum.cal` `skybright` with gendaylit's 10 real arguments.
    PerezLum([f64; 10]),
    /// genssky's `specpict` sky picture (spectral; see [`crate::sky::specpict`]).
    SpecPict(std::sync::Arc<crate::sky::specpict::SpecPictSky>),
    /// Other function-file patterns (`.cal` brightfunc, colorfunc, specfunc, specdata),
    /// evaluated per direction by [`crate::calc`].
    Cal(std::sync::Arc<crate::calc::pattern::CalPatterns>),
}

impl SkyPattern {
    /// The pattern's scalar factor for a unit direction pointing away from the scene.
    pub fn factor(&self, dir: Vec3) -> f64 {
        match self {
            SkyPattern::Uniform => 1.0,
            SkyPattern::SkyBright(a) => crate::sky::cie::skybright(dir.to_array(), a),
            SkyPattern::PerezLum(a) => crate::sky::perez::perezlum(dir.to_array(), a),
            // Spectral: applied per channel by `DistantSource::radiance`.
            SkyPattern::SpecPict(_) | SkyPattern::Cal(_) => 1.0,
        }
    }
}

/// What a distant source is to the tracer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DistantKind {
    /// `light`: a direct source (next-event estimation); rays that took an ambient or
    /// Gaussian-specular sample see it black (`badcomponent`).
    Light,
    /// `glow` with maxrad >= 0: seen by every escaping ray.
    Glow,
    /// `glow` with maxrad < 0: seen only by primary and pure-specular rays ("never
    /// contributes to illumination").
    DarkGlow,
}

/// One `source` primitive with its material resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct DistantSource {
    /// The `source` object's id (`sun`, `sky`, ...).
    pub id: String,
    /// Unit direction towards the source.
    pub dir: Vec3,
    /// Solid angle `2 pi (1 - cos(angle/2))` (Radiance's `ss2`), sr.
    pub omega: f64,
    /// Material radiance in the run's channels.
    pub color: Color,
    pub pattern: SkyPattern,
    pub kind: DistantKind,
    /// Index of the `source` object in the scene (`Scene::objects`): which receiver an
    /// escaping ray reached in rdc's sender/receiver mode.
    pub scene_index: usize,
}

impl DistantSource {
    /// A source in direction `dir` (normalised here) with full apex `angle_deg`.
    pub fn new(
        id: impl Into<String>,
        dir: Vec3,
        angle_deg: f64,
        color: Color,
        pattern: SkyPattern,
        kind: DistantKind,
    ) -> Self {
        let half = (angle_deg.clamp(0.0, 360.0) * 0.5).to_radians();
        DistantSource {
            id: id.into(),
            dir: dir.normalize(),
            omega: 2.0 * std::f64::consts::PI * (1.0 - half.cos()),
            color,
            pattern,
            kind,
            scene_index: 0,
        }
    }

    /// Radiance's cone test from `sourcehit`.
    #[inline]
    pub fn contains(&self, dir: Vec3) -> bool {
        2.0 * std::f64::consts::PI * (1.0 - self.dir.dot(dir)) <= self.omega
    }

    /// Radiance towards the scene along `-dir` (colour x pattern).
    pub fn radiance(&self, dir: Vec3) -> Color {
        match &self.pattern {
            SkyPattern::Uniform => self.color,
            SkyPattern::SpecPict(p) => self.color * p.lookup(dir.to_array()),
            SkyPattern::Cal(p) => {
                self.color * p.eval(&crate::calc::pattern::RayVars::escaping(dir.to_array()))
            }
            _ => self.color.scale(self.pattern.factor(dir)),
        }
    }
}

/// All distant sources in scene order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Sources {
    pub list: Vec<DistantSource>,
}

impl Sources {
    /// The source an unaimed escaping ray in direction `dir` hits (`sourcehit`): the first
    /// non-glow source containing `dir`, else the first glow containing it.
    pub fn hit(&self, dir: Vec3) -> Option<&DistantSource> {
        let mut glow = None;
        for s in &self.list {
            if !s.contains(dir) {
                continue;
            }
            match s.kind {
                DistantKind::Light => return Some(s),
                DistantKind::Glow | DistantKind::DarkGlow => {
                    if glow.is_none() {
                        glow = Some(s);
                    }
                }
            }
        }
        glow
    }

    /// The direct (next-event) sources.
    pub fn lights(&self) -> impl Iterator<Item = &DistantSource> {
        self.list.iter().filter(|s| s.kind == DistantKind::Light)
    }

    /// What an escaping ray sees. `sees_sources`: the path so far is primary or pure
    /// specular only (Radiance's ray types without AMBIENT/SPECULAR bits), so direct sources
    /// are visible; otherwise they are black because next-event estimation counted them.
    pub fn escape(&self, dir: Vec3, sees_sources: bool) -> Option<Color> {
        let s = self.hit(dir)?;
        match s.kind {
            DistantKind::Light if !sees_sources => None,
            DistantKind::DarkGlow if !sees_sources => None,
            _ => Some(s.radiance(dir)),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }
}
