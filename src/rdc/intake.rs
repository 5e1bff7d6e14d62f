//! # Scene intake: what the tracer gets from the `.rad` inputs
//!
//! The scene is loaded with [`crate::scene::load`] and split into
//!
//! - the **sky** ([`Sky`]): every `source` primitive (a distant source, notes 5.3) whose
//!   material is `glow` (sky and ground domes, with an optional `brightfunc` pattern) or
//!   `light` (suns);
//! - the **surfaces** (indices into [`Scene::objects`]) for the tracer.
//!
//! Sky patterns evaluated natively (notes 5.4, 5.5):
//!
//! | pattern | file | function | evaluated with |
//! |---|---|---|---|
//! | `brightfunc` | `skybright.cal` | `skybr` | [`crate::sky::cie::skybright`] (gensky) |
//! | `brightfunc` | `perezlum.cal` | `skybright` | [`crate::sky::perez::perezlum`] (gendaylit) |
//!
//! A direction is seen on the distant source that contains it (within half its apex angle
//! of its direction); where several overlap, Radiance's `sourcehit` rule applies: the first
//! `light` in scene order, else the last `glow` (so a sun disc sits in front of the dome). A `glow` with a negative radius never illuminates (notes 5.3):
//! sensors do not see it, view rays do. Patterns with transforms, other `.cal` files and
//! patterns on suns are reported as unsupported, with their location.

use super::tracer::{dot, normalized};
use crate::error::{Error, Location, Result};
use crate::scene::{Class, LoadOptions, Primitive, Scene};

/// Primitive types the intake understands (everything else is reported with its location
/// by [`Scene::check_supported`]). Surfaces and materials are listed for the tracer to come.
pub const SUPPORTED: &[&str] = &[
    "source",
    "glow",
    "light",
    "brightfunc",
    "polygon",
    "sphere",
    "bubble",
    "ring",
    "cone",
    "cup",
    "cylinder",
    "tube",
    "plastic",
    "metal",
    "trans",
    "glass",
    "mirror",
    "illum",
    "spectrum",
    "specfile",
    "specpict",
];

/// A sky pattern evaluated natively.
#[derive(Debug, Clone, PartialEq)]
pub enum SkyFunction {
    /// gensky's `skybright.cal` `skybr` with its real arguments.
    Cie(Vec<f64>),
    /// gendaylit's `perezlum.cal` `skybright` with its 10 arguments.
    Perez([f64; 10]),
}

impl SkyFunction {
    pub fn eval(&self, dir: [f64; 3]) -> f64 {
        match self {
            SkyFunction::Cie(a) => crate::sky::cie::skybright(dir, a),
            SkyFunction::Perez(a) => crate::sky::perez::perezlum(dir, a),
        }
    }
}

/// A distant emitter: a `source` with a `glow` or `light` material.
#[derive(Debug, Clone, PartialEq)]
pub struct DistantSource {
    /// Unit direction toward the source.
    pub dir: [f64; 3],
    /// Cosine of half the apex angle (-1 for a 360-degree source).
    pub cos_half: f64,
    /// Solid angle `2 pi (1 - cos_half)`.
    pub solid_angle: f64,
    /// RGB radiance (W sr^-1 m^-2), before the pattern.
    pub color: [f64; 3],
    pub pattern: Option<SkyFunction>,
    /// `light` (a direct source: a sun) rather than `glow`.
    pub is_light: bool,
    /// False for a `glow` with negative radius: seen by view rays only.
    pub illuminates: bool,
    /// Object id and location, for messages.
    pub id: String,
    pub loc: Location,
}

/// Everything at infinity: sky and ground glows, and suns.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Sky {
    /// `glow` sources.
    pub glows: Vec<DistantSource>,
    /// `light` sources.
    pub suns: Vec<DistantSource>,
}

impl Sky {
    pub fn is_empty(&self) -> bool {
        self.glows.is_empty() && self.suns.is_empty()
    }

    /// RGB radiance seen in direction `dir`. `for_irradiance`: what an ambient (hemisphere)
    /// sample sees: glows that illuminate, and nothing inside a sun (counted directly).
    pub fn radiance(&self, dir: [f64; 3], for_irradiance: bool) -> [f64; 3] {
        // Radiance's `sourcehit` (src/rt/source.c): the first light source whose disc holds
        // the direction wins; glows (skipped as direct sources) are only a fallback, the
        // last one in scene order that holds it.
        let holds = |s: &&DistantSource| dot(dir, s.dir) >= s.cos_half;
        let best = self
            .suns
            .iter()
            .find(holds)
            .or_else(|| self.glows.iter().rev().find(holds));
        match best {
            None => [0.0; 3],
            Some(s) if for_irradiance && (s.is_light || !s.illuminates) => [0.0; 3],
            Some(s) => {
                let f = s.pattern.as_ref().map_or(1.0, |p| p.eval(dir));
                [s.color[0] * f, s.color[1] * f, s.color[2] * f]
            }
        }
    }

    /// `rgb * scale` in `out.len()` channels: RGB as is, any other count only for grey
    /// (checked beforehand by [`Sky::check_channels`]).
    pub fn to_channels(&self, rgb: [f64; 3], scale: f64, out: &mut [f64]) {
        if out.len() == 3 {
            for k in 0..3 {
                out[k] = rgb[k] * scale;
            }
        } else {
            out.iter_mut().for_each(|o| *o = rgb[1] * scale);
        }
    }

    /// Scene colours are RGB; other channel counts are only possible for grey emitters
    /// (RGB-to-spectrum conversion belongs to the material work).
    pub fn check_channels(&self, ncomp: usize) -> Result<()> {
        // Values are traced with trace::compile's sources, whose colours go through
        // material::to_channels (Radiance's setscolor), so any layout works there.
        if ncomp >= 3 {
            return Ok(());
        }
        for s in self.glows.iter().chain(&self.suns) {
            if s.color[0] != s.color[1] || s.color[1] != s.color[2] {
                return Err(Error::unsupported(
                    s.loc.clone(),
                    format!(
                        "coloured source '{}' with {ncomp} channels (-cs): only grey sources \
                         can be converted yet",
                        s.id
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A loaded scene split for the tracer.
#[derive(Debug, Clone, Default)]
pub struct Intake {
    pub scene: Scene,
    pub sky: Sky,
    /// Indices of the surfaces that are not distant sources.
    pub surfaces: Vec<usize>,
}

impl Intake {
    /// The first surface, for "not supported yet" messages: `file:line: polygon 'floor'`.
    pub fn first_surface(&self) -> Option<String> {
        self.surfaces.first().map(|&i| {
            let o = &self.scene.objects[i];
            format!("{}: {} '{}'", o.loc, o.type_name(), o.id)
        })
    }
}

/// Load scene inputs (file paths, `-`, `!command`) and split them.
pub fn load(inputs: &[String], opts: &LoadOptions) -> Result<Intake> {
    let scene = crate::scene::load(inputs, opts)?;
    split(scene)
}

/// Split a scene into sky and surfaces.
pub fn split(scene: Scene) -> Result<Intake> {
    scene.check_supported(SUPPORTED)?;
    let mut sky = Sky::default();
    let mut surfaces = Vec::new();
    for (i, o) in scene.surfaces() {
        let Primitive::Source { direction, angle } = &o.kind else {
            surfaces.push(i);
            continue;
        };
        let Some(m) = scene.material_of(i) else {
            continue; // void source: nothing to see
        };
        let mat = &scene.objects[m];
        let cos_half = (angle.to_radians() * 0.5).cos();
        let (color, is_light, illuminates) = match &mat.kind {
            Primitive::Glow { color, max_radius } => (rgb(color), false, *max_radius >= 0.0),
            Primitive::Light { color } => (rgb(color), true, true),
            _ => {
                return Err(Error::unsupported(
                    o.loc.clone(),
                    format!(
                        "material '{}' ({}) on source '{}': distant sources must be glow or light",
                        mat.id,
                        mat.type_name(),
                        o.id
                    ),
                ));
            }
        };
        let pattern = pattern_of(&scene, m)?;
        if is_light && pattern.is_some() {
            return Err(Error::unsupported(
                mat.loc.clone(),
                format!("pattern on light '{}' (sun patterns)", mat.id),
            ));
        }
        let src = DistantSource {
            dir: normalized(*direction),
            cos_half,
            solid_angle: 2.0 * std::f64::consts::PI * (1.0 - cos_half),
            color,
            pattern,
            is_light,
            illuminates,
            id: o.id.clone(),
            loc: o.loc.clone(),
        };
        if is_light {
            sky.suns.push(src);
        } else {
            sky.glows.push(src);
        }
    }
    Ok(Intake {
        scene,
        sky,
        surfaces,
    })
}

fn rgb(c: &[f64]) -> [f64; 3] {
    [
        c.first().copied().unwrap_or(0.0),
        c.get(1).copied().unwrap_or(0.0),
        c.get(2).copied().unwrap_or(0.0),
    ]
}

/// The sky function modifying material `m`, if any.
fn pattern_of(scene: &Scene, m: usize) -> Result<Option<SkyFunction>> {
    let pats = scene.patterns_of(m);
    let mut found = None;
    for p in pats {
        let o = &scene.objects[p];
        if o.class() == Class::Material {
            break;
        }
        // Spectral patterns colour the source (trace::compile applies them).
        if matches!(
            o.kind,
            Primitive::Spectrum { .. } | Primitive::SpecFile { .. }
        ) || o.type_name() == "specpict"
        {
            continue;
        }
        let Primitive::BrightFunc {
            function,
            file,
            transform,
            args,
        } = &o.kind
        else {
            return Err(Error::unsupported(
                o.loc.clone(),
                format!("{} '{}' on a sky source", o.type_name(), o.id),
            ));
        };
        if found.is_some() {
            return Err(Error::unsupported(
                o.loc.clone(),
                format!("second pattern '{}' on a sky source", o.id),
            ));
        }
        if !transform.is_empty() {
            return Err(Error::unsupported(
                o.loc.clone(),
                format!(
                    "transform '{}' on sky function '{}'",
                    transform.join(" "),
                    o.id
                ),
            ));
        }
        let base = file.rsplit('/').next().unwrap_or(file);
        found = Some(match (base, function.as_str()) {
            ("skybright.cal", "skybr") => SkyFunction::Cie(args.clone()),
            ("perezlum.cal", "skybright") => {
                let a: [f64; 10] = args.as_slice().try_into().map_err(|_| {
                    Error::parse(
                        o.loc.clone(),
                        format!(
                            "perezlum.cal expects 10 real arguments, found {}",
                            args.len()
                        ),
                    )
                })?;
                SkyFunction::Perez(a)
            }
            _ => {
                return Err(Error::unsupported(
                    o.loc.clone(),
                    format!(
                        "sky function '{function}' of '{file}' ('{}'); supported: skybr of \
                         skybright.cal, skybright of perezlum.cal",
                        o.id
                    ),
                ));
            }
        });
    }
    Ok(found)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn parse(text: &str) -> Result<Intake> {
        let opts = LoadOptions {
            allow_exec: false,
            command_env: Vec::new(),
        };
        split(crate::scene::parse_str(
            text,
            "t.rad",
            Path::new(""),
            &opts,
        )?)
    }

    #[test]
    fn gensky_sky_with_glows_and_sun() {
        let i = parse(
            "void light solar 0 0 3 6e6 6e6 6e6\nsolar source sun 0 0 4 0 -0.8 0.6 0.5\n\
             void brightfunc skyfunc 2 skybr skybright.cal 0 3 2 10 2\n\
             skyfunc glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n\
             skyfunc glow groundglow 0 0 4 1 1 1 0\ngroundglow source ground 0 0 4 0 0 -1 180\n",
        )
        .unwrap();
        assert_eq!(i.sky.suns.len(), 1);
        assert_eq!(i.sky.glows.len(), 2);
        assert!(i.surfaces.is_empty());
        // Overcast: zenith 10 * (1 + 2) / 3.
        let z = i.sky.radiance([0.0, 0.0, 1.0], true);
        assert!((z[0] - 10.0).abs() < 1e-3, "{z:?}");
        // The sun's disc is the sun for view rays, nothing for ambient samples.
        let d = normalized([0.0, -0.8, 0.6]);
        assert!(i.sky.radiance(d, false)[0] > 1e6);
        assert_eq!(i.sky.radiance(d, true), [0.0; 3]);
    }

    #[test]
    fn unknown_sky_function_is_reported_with_its_line() {
        let e = parse(
            "void brightfunc f 2 foo bar.cal 0 0\nf glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n",
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("t.rad:1"), "{e}");
        assert!(e.contains("sky function 'foo'"), "{e}");
    }
}
