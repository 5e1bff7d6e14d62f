//! Scene -> [`Renderable`]: shapes with resolved materials in one BVH, plus distant sources.
//!
//! What Radiance does, and what we do:
//! - A surface's material is the first material in its modifier chain (`findmaterial`).
//!   A chain that ends in `void` without a material (or a surface modified by `void`) makes
//!   the surface transparent: `raytrace` calls `rayshade`, which finds no material, and the
//!   ray continues unchanged (`raytrans`). Such surfaces change nothing for any ray (primary,
//!   indirect or shadow), so they are left out of the BVH.
//! - Argument fix-ups before building shapes (`src/rt/sphere.c`, `src/common/cone.c`): a
//!   negative sphere radius flips sphere <-> bubble; negative cylinder radius flips
//!   cylinder <-> tube; a cone whose radii are both <= 0 (one < 0) flips cone <-> cup with
//!   negated radii; a cone with equal radii is a cylinder.
//! - `source` primitives become [`DistantSource`]s (see [`super::sources`]).
//!
//! - Function-file patterns (`brightfunc`, `colorfunc`, `specfunc`, `specdata`; the `.cal`
//!   evaluator of [`crate::calc`]): on distant glows (skies) evaluated per escaping ray; on
//!   surfaces per hit (the material is rebuilt with the pattern colour there,
//!   `Renderable::material_at`), or once when their value does not depend on the ray
//!   (then they act like the constant spectral patterns below); on `light` sources only
//!   when constant.
//! - Constant spectral patterns (`spectrum`, `specfile`, Radiance 6) anywhere between a
//!   surface or source and its material, or modifying the material, multiply the material's
//!   colour ([`crate::material::spectrum`]): spectral reflectance of walls, spectral
//!   transmittance of glazing, spectral suns and skies (together with a sky `brightfunc`).
//!
//! Refused with `Error::unsupported` at the object's `file:line` (so nothing is silently
//! rendered wrong): surface types other than those above and `mesh`/`instance` (read
//!   into shared units first: [`super::expand`]); other patterns, textures and
//! mixtures on surfaces (`specpict` and other picture or data patterns, textures, `-i`
//! transform arrays on function-file patterns); materials other than
//! plastic/metal/trans/glass/mirror/glow/BSDF/aBSDF (e.g. `spotlight`; BSDF with a function
//! file or a transform; patterns on BSDF are modelled as `m_bsdf.c` applies them,
//! [`crate::material::bsdf::Bsdf`]); *local* direct sources
//! (`light`, `illum`, `glow` with maxrad > 0 on surfaces: no next-event estimation to
//! surfaces yet); `mirror`/`illum` alternate materials; on distant sources, patterns other
//! than the sky functions, `specpict` and the function-file patterns above, and
//! ray-dependent patterns on `light` (sun) materials.

use super::sources::{DistantKind, DistantSource, SkyPattern, Sources};
use crate::calc::pattern::{CalPatterns, PatternedMaterial, ScenePatterns, is_cal_pattern};
use crate::error::{Error, Result};
use crate::geometry::{Bvh, Placed, ShapeRef, ShapeSource, Vec3};
use crate::material::spectrum::Sampled;
use crate::material::{Color, Emitter, EmitterKind, Material, ShadingOptions};
use crate::radiometry::Channels;
use crate::scene::{Class, CompactScene, OType, Object, Primitive, Scene, SurfaceTable};

/// One traced surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SurfaceInfo {
    /// Index into [`Renderable::materials`].
    pub material: u32,
    /// Radiance's `isflat` (polygons and rings).
    pub flat: bool,
    /// Index of the surface in [`Scene::objects`].
    pub scene_index: u32,
}

/// A scene ready for tracing: build once, share between threads (`Renderable: Sync`).
pub struct Renderable {
    pub(super) bvh: Bvh,
    /// Per BVH object id.
    pub(super) surfaces: Vec<SurfaceInfo>,
    pub(super) materials: Vec<Material>,
    /// Per material: the scene id of the material object it was built from.
    pub(super) material_ids: Vec<String>,
    /// Per material: `Some` when ray-dependent `.cal` patterns modify it (rebuilt per hit,
    /// see [`Renderable::material_at`]).
    pub(super) patterned: Vec<Option<std::sync::Arc<PatternedMaterial>>>,
    pub(super) sources: Sources,
    pub(super) ncomp: usize,
    /// Window panes sampled by next-event estimation ([`super::portals`]).
    pub(super) portals: super::portals::Portals,
    /// The vertices of the top-level glass polygons the portals were found from (a
    /// compiled scene stores them: [`super::compiled`]).
    pub(super) pane_polygons: Vec<Vec<[f64; 3]>>,
}

impl std::fmt::Debug for Renderable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Renderable")
            .field("surfaces", &self.surfaces.len())
            .field("materials", &self.materials.len())
            .field("sources", &self.sources)
            .field("ncomp", &self.ncomp)
            .finish()
    }
}

/// The pattern file's name without directories (`skybright.cal` in `/usr/lib/skybright.cal`).
fn basename(file: &str) -> &str {
    file.rsplit(['/', '\\']).next().unwrap_or(file)
}

fn unsupported(o: &Object, what: impl Into<String>) -> Error {
    Error::unsupported(o.loc.clone(), what)
}

/// Whether object `k` is a constant spectral pattern ([`spectral_color`] handles it):
/// `spectrum`, `specfile`, or a function-file pattern that does not depend on the ray.
fn is_spectral(cal: &ScenePatterns, scene: &Scene, k: usize) -> bool {
    matches!(
        scene.objects[k].kind,
        Primitive::Spectrum { .. } | Primitive::SpecFile { .. }
    ) || (!native_sky(&scene.objects[k]) && cal.is_constant(k))
}

/// The gensky and gendaylit sky functions without a transform, evaluated natively (their
/// `.cal` files need not be installed); with a transform they go to the `.cal` evaluator.
fn native_sky(o: &Object) -> bool {
    match &o.kind {
        Primitive::BrightFunc {
            function,
            file,
            transform,
            ..
        } if transform.is_empty() => matches!(
            (basename(file), function.as_str()),
            ("skybright.cal", "skybr") | ("perezlum.cal", "skybright")
        ),
        _ => false,
    }
}

/// The product of the constant spectral patterns among `patterns` in the run's channels
/// (`None` when there are none).
fn spectral_color(
    cal: &ScenePatterns,
    scene: &Scene,
    patterns: impl IntoIterator<Item = usize>,
    ch: &Channels,
) -> Result<Option<Color>> {
    let mut out: Option<Color> = None;
    for k in patterns {
        let o = &scene.objects[k];
        let s = match &o.kind {
            Primitive::Spectrum { nm_a, nm_b, values } => {
                Sampled::new(*nm_a, *nm_b, values.clone())
            }
            Primitive::SpecFile { file, data } => match data {
                Some(d) => Sampled::from_data(d),
                None => {
                    return Err(Error::parse(
                        o.loc.clone(),
                        format!(
                            "specfile '{}': data file '{file}' not found (looked beside the scene file and on RAYPATH)",
                            o.id
                        ),
                    ));
                }
            },
            _ if is_cal_pattern(o) && !native_sky(o) && cal.is_constant(k) => {
                let c = cal.constant_color(k)?;
                out = Some(match out {
                    Some(p) => p * c,
                    None => c,
                });
                continue;
            }
            _ => continue,
        };
        if !s.values.iter().all(|v| v.is_finite()) {
            return Err(Error::parse(
                o.loc.clone(),
                format!("{} '{}' has a non-finite value", o.type_name(), o.id),
            ));
        }
        let c = s.to_channels(ch);
        out = Some(match out {
            Some(p) => p * c,
            None => c,
        });
    }
    Ok(out)
}

/// The sky pattern of a distant glow from the patterns modifying its material (spectral
/// patterns are taken apart by [`spectral_color`]).
fn sky_pattern(
    cal: &ScenePatterns,
    scene: &Scene,
    src: &Object,
    material: usize,
    ch: &Channels,
) -> Result<SkyPattern> {
    let pats: Vec<usize> = scene
        .patterns_of(material)
        .into_iter()
        .filter(|&k| !is_spectral(cal, scene, k))
        .collect();
    // Function-file patterns other than the two sky functions evaluated natively go to the
    // `.cal` evaluator, all of them together.
    if !pats.is_empty()
        && pats.iter().all(|&k| {
            let o = &scene.objects[k];
            is_cal_pattern(o) && !(pats.len() == 1 && native_sky(o))
        })
    {
        let list = pats
            .iter()
            .map(|&k| cal.get(k))
            .collect::<Result<Vec<_>>>()?;
        return Ok(SkyPattern::Cal(std::sync::Arc::new(CalPatterns {
            list,
            ch: *ch,
        })));
    }
    match pats.as_slice() {
        [] => Ok(SkyPattern::Uniform),
        [p] => {
            let po = &scene.objects[*p];
            match &po.kind {
                Primitive::BrightFunc {
                    function,
                    file,
                    transform,
                    args,
                } => {
                    if !transform.is_empty() {
                        return Err(unsupported(
                            po,
                            format!(
                                "transform '{}' on brightfunc '{}'; expected none",
                                transform.join(" "),
                                po.id
                            ),
                        ));
                    }
                    match (basename(file), function.as_str()) {
                        ("skybright.cal", "skybr") => Ok(SkyPattern::SkyBright(args.clone())),
                        ("perezlum.cal", "skybright") => {
                            let a: [f64; 10] = args.as_slice().try_into().map_err(|_| {
                                Error::parse(
                                    po.loc.clone(),
                                    format!(
                                        "brightfunc '{}' has {} real arguments; perezlum.cal expects 10",
                                        po.id,
                                        args.len()
                                    ),
                                )
                            })?;
                            Ok(SkyPattern::PerezLum(a))
                        }
                        (f, func) => Err(unsupported(
                            po,
                            format!(
                                "brightfunc '{}' ({func} from {f}) on source '{}'; supported: skybr from skybright.cal, skybright from perezlum.cal",
                                po.id, src.id
                            ),
                        )),
                    }
                }
                Primitive::Other {
                    otype: OType::SpecPict,
                    strings,
                    reals,
                } => specpict(po, strings, reals, ch),
                _ => Err(unsupported(
                    po,
                    format!(
                        "{} '{}' on source '{}'; only a sky brightfunc is supported",
                        po.type_name(),
                        po.id,
                        src.id
                    ),
                )),
            }
        }
        [_, p, ..] => {
            let po = &scene.objects[*p];
            Err(unsupported(
                po,
                format!(
                    "second pattern '{}' on source '{}'; at most one sky brightfunc",
                    po.id, src.id
                ),
            ))
        }
    }
}

/// genssky's `specpict` sky (see [`crate::sky::specpict`]): only its own mapping.
fn specpict(po: &Object, strings: &[String], reals: &[f64], ch: &Channels) -> Result<SkyPattern> {
    use crate::scene::find_file;
    use crate::sky::specpict::{GENSSKY_X, GENSSKY_Y, SpecPictSky};
    let clean = |s: &str| -> String {
        s.trim_matches(|c| c == '\'' || c == '"')
            .chars()
            .filter(|c| !c.is_whitespace())
            .collect()
    };
    let ok = match strings {
        [f, _, cal, x, y] => {
            f == "noop" && cal == "." && clean(x) == GENSSKY_X && clean(y) == GENSSKY_Y
        }
        _ => false,
    } && reals.is_empty();
    if !ok {
        return Err(unsupported(
            po,
            format!(
                "specpict '{}' with arguments {strings:?} {reals:?}; supported: genssky's \
                 `noop FILE . '{GENSSKY_X}' '{GENSSKY_Y}'` and no real arguments",
                po.id
            ),
        ));
    }
    let file = &strings[1];
    let path = find_file(file, &po.loc.file).ok_or_else(|| {
        Error::parse(
            po.loc.clone(),
            format!(
                "specpict '{}': picture '{file}' not found (looked beside the scene file, in the working folder and on RAYPATH)",
                po.id
            ),
        )
    })?;
    Ok(SkyPattern::SpecPict(std::sync::Arc::new(
        SpecPictSky::load(&path, ch)?,
    )))
}

#[allow(clippy::too_many_arguments)]
fn distant_source(
    cal: &ScenePatterns,
    scene: &Scene,
    i: usize,
    o: &Object,
    direction: [f64; 3],
    angle: f64,
    ch: &Channels,
    opts: &ShadingOptions,
) -> Result<Option<DistantSource>> {
    // A source needs a non-zero direction.
    let dir = Vec3::from(direction);
    if !(dir.is_finite() && dir.length() > 0.0 && angle.is_finite()) {
        return Err(Error::parse(
            o.loc.clone(),
            format!(
                "source '{}' has direction {direction:?} and angle {angle}; expected a non-zero direction and a finite angle",
                o.id
            ),
        ));
    }
    let Some(m) = scene.material_of(i) else {
        return Ok(None);
    };
    // Patterns between the source and its material.
    let between: Vec<usize> = scene.modifier_chain(i).take_while(|&k| k != m).collect();
    if let Some(&p) = between
        .iter()
        .find(|&&k| scene.objects[k].class() != Class::Material && !is_spectral(cal, scene, k))
    {
        let po = &scene.objects[p];
        return Err(unsupported(
            po,
            format!(
                "pattern '{}' between source '{}' and its material",
                po.id, o.id
            ),
        ));
    }
    let mo = &scene.objects[m];
    let pcol = spectral_color(
        cal,
        scene,
        between.into_iter().chain(scene.patterns_of(m)),
        ch,
    )?;
    let mat = Material::build_patterned(&mo.kind, ch, opts, &mo.loc, &mo.id, pcol)?;
    let Some(Material::Emitter(Emitter { color, kind })) = mat else {
        // Radiance: a source with a non-emitting material is no light source; rays that
        // escape towards it see nothing.
        return Ok(None);
    };
    if color.max() <= 1e-6 {
        return Ok(None);
    }
    let kind = match kind {
        EmitterKind::Light => {
            if scene
                .patterns_of(m)
                .into_iter()
                .any(|k| !is_spectral(cal, scene, k))
            {
                return Err(unsupported(
                    mo,
                    format!("pattern on light source material '{}'", mo.id),
                ));
            }
            DistantKind::Light
        }
        EmitterKind::Glow { max_radius } if max_radius < -1e-6 => DistantKind::DarkGlow,
        EmitterKind::Glow { .. } => DistantKind::Glow,
        EmitterKind::Illum { .. } => {
            return Err(unsupported(
                mo,
                format!("illum '{}' on source '{}'", mo.id, o.id),
            ));
        }
    };
    let pattern = if kind == DistantKind::Light {
        SkyPattern::Uniform
    } else {
        sky_pattern(cal, scene, o, m, ch)?
    };
    Ok(Some(DistantSource::new(
        o.id.clone(),
        dir,
        angle,
        color,
        pattern,
        kind,
    )))
}

/// The shape of a surface with Radiance's radius fix-ups (`otype` and its real arguments as
/// written; `None` for types that are not traced here, the caller reports them).
fn shape_of_args(otype: OType, r: &[f64]) -> Option<ShapeRef<'_>> {
    match otype {
        OType::Polygon => Some(ShapeRef::Polygon(r)),
        _ => analytic_of_args(otype, r),
    }
}

/// [`shape_of_args`] for the analytic types (copied out of `r`, so borrowing nothing).
fn analytic_of_args(otype: OType, r: &[f64]) -> Option<ShapeRef<'static>> {
    let p = |k: usize| [r[k], r[k + 1], r[k + 2]];
    let get = |n: usize| (r.len() >= n).then_some(());
    Some(match otype {
        OType::Sphere | OType::Bubble => {
            get(4)?;
            ShapeRef::Sphere {
                centre: p(0),
                radius: r[3].abs(),
                inward: (otype == OType::Bubble) ^ (r[3] < 0.0),
            }
        }
        OType::Cylinder | OType::Tube => {
            get(7)?;
            ShapeRef::Cylinder {
                p0: p(0),
                p1: p(3),
                r: r[6].abs(),
                inward: (otype == OType::Tube) ^ (r[6] < 0.0),
            }
        }
        OType::Cone | OType::Cup => {
            get(8)?;
            let (r0, r1) = (r[6], r[7]);
            let flip = r0 <= 0.0 && r1 <= 0.0 && (r0 < 0.0 || r1 < 0.0);
            let (r0, r1) = if flip { (-r0, -r1) } else { (r0, r1) };
            let inward = (otype == OType::Cup) ^ flip;
            if r0 == r1 {
                ShapeRef::Cylinder {
                    p0: p(0),
                    p1: p(3),
                    r: r0,
                    inward,
                }
            } else {
                ShapeRef::Cone {
                    p0: p(0),
                    p1: p(3),
                    r0,
                    r1,
                    inward,
                }
            }
        }
        OType::Ring => {
            get(8)?;
            ShapeRef::Ring {
                centre: p(0),
                normal: p(3),
                r_in: r[6],
                r_out: r[7],
            }
        }
        _ => return None,
    })
}

/// [`shape_of_args`] for a typed primitive (a polygon's vertices borrowed, not copied).
fn shape_of(p: &Primitive) -> Option<ShapeRef<'_>> {
    match p {
        Primitive::Polygon { vertices } => Some(ShapeRef::Polygon(vertices.as_flattened())),
        Primitive::Sphere {
            center,
            radius,
            inward,
        } => analytic_of_args(
            if *inward {
                OType::Bubble
            } else {
                OType::Sphere
            },
            &[center[0], center[1], center[2], *radius],
        ),
        Primitive::Cylinder {
            p0,
            p1,
            radius,
            inward,
        } => analytic_of_args(
            if *inward {
                OType::Tube
            } else {
                OType::Cylinder
            },
            &[p0[0], p0[1], p0[2], p1[0], p1[1], p1[2], *radius],
        ),
        Primitive::Cone {
            p0,
            p1,
            r0,
            r1,
            inward,
        } => analytic_of_args(
            if *inward { OType::Cup } else { OType::Cone },
            &[p0[0], p0[1], p0[2], p1[0], p1[1], p1[2], *r0, *r1],
        ),
        Primitive::Ring {
            center,
            normal,
            r0,
            r1,
        } => analytic_of_args(
            OType::Ring,
            &[
                center[0], center[1], center[2], normal[0], normal[1], normal[2], *r0, *r1,
            ],
        ),
        _ => None,
    }
}

/// A surface as errors name it: type, id and `file:line`.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceName {
    pub otype: OType,
    pub id: String,
    pub loc: crate::error::Location,
}

impl SurfaceName {
    fn of(o: &Object) -> SurfaceName {
        SurfaceName {
            otype: o.kind.otype(),
            id: o.id.clone(),
            loc: o.loc.clone(),
        }
    }
}

/// One material as surfaces use it: the material object and the patterns between a surface
/// and it (indices into the scene the tracer compiled, after `mesh`/`instance` expansion),
/// with the first surface that used it (errors name it). Slots are numbered in order of
/// first use, as [`SurfaceInfo::material`] numbers materials.
#[derive(Debug, Clone, PartialEq)]
pub struct Slot {
    pub material: usize,
    pub between: Vec<usize>,
    pub first: SurfaceName,
}

/// What a BVH object is: table surface `k`, or object `k` of the expanded scene.
#[derive(Debug, Clone, Copy)]
enum GeoRef {
    Table(u32),
    Object(u32),
}

/// The BVH's view of the surfaces (shapes read in place, ids = positions).
struct GeoSource<'a> {
    table: &'a SurfaceTable,
    scene: &'a Scene,
    items: &'a [GeoRef],
}

impl GeoSource<'_> {
    fn shape(&self, r: GeoRef) -> ShapeRef<'_> {
        let s = match r {
            GeoRef::Table(k) => {
                let k = k as usize;
                shape_of_args(self.table.otype(k), self.table.reals(k))
            }
            GeoRef::Object(k) => shape_of(&self.scene.objects[k as usize].kind),
        };
        s.expect("surfaces were checked while compiling")
    }

    fn name(&self, r: GeoRef) -> SurfaceName {
        match r {
            GeoRef::Table(k) => {
                let s = self.table.get(k as usize);
                SurfaceName {
                    otype: s.otype,
                    id: s.id.to_string(),
                    loc: s.loc(),
                }
            }
            GeoRef::Object(k) => SurfaceName::of(&self.scene.objects[k as usize]),
        }
    }
}

impl ShapeSource for GeoSource<'_> {
    fn count(&self) -> usize {
        self.items.len()
    }
    fn get(&self, i: usize) -> (ShapeRef<'_>, u32) {
        (self.shape(self.items[i]), i as u32)
    }
}

/// Materials as a run builds them (channels and shading options), slot by slot.
pub(super) struct Shading<'s> {
    scene: &'s Scene,
    cal: ScenePatterns<'s>,
    ch: Channels,
    opts: ShadingOptions,
    materials: Vec<Material>,
    material_ids: Vec<String>,
    patterned: Vec<Option<std::sync::Arc<PatternedMaterial>>>,
}

impl<'s> Shading<'s> {
    pub(super) fn new(scene: &'s Scene, ch: &Channels, opts: &ShadingOptions) -> Self {
        Shading {
            scene,
            cal: ScenePatterns::new(scene, ch),
            ch: *ch,
            opts: *opts,
            materials: Vec::new(),
            material_ids: Vec::new(),
            patterned: Vec::new(),
        }
    }

    /// Build the material of one slot (refusing what is not modelled, naming the slot's
    /// first surface).
    pub(super) fn add(&mut self, m: usize, between: &[usize], surface: &SurfaceName) -> Result<()> {
        let (scene, cal, ch, opts) = (self.scene, &self.cal, &self.ch, &self.opts);
        let unsupported_at = |o: &Object, what: String| Error::unsupported(o.loc.clone(), what);
        // Ray-dependent function-file patterns are evaluated per hit; any other
        // non-constant pattern or texture is refused.
        let mut varying = Vec::new();
        for k in between.iter().copied().chain(scene.patterns_of(m)) {
            if is_spectral(cal, scene, k) {
                continue;
            }
            let po = &scene.objects[k];
            if is_cal_pattern(po) && !native_sky(po) {
                varying.push(cal.get(k)?);
                continue;
            }
            return Err(unsupported_at(
                po,
                format!(
                    "{} '{}' modifying surface '{}' (patterns and textures are not modelled)",
                    po.type_name(),
                    po.id,
                    surface.id
                ),
            ));
        }
        let mo = &scene.objects[m];
        let pcol = spectral_color(
            cal,
            scene,
            between.iter().copied().chain(scene.patterns_of(m)),
            ch,
        )?;
        let mat = Material::build_patterned(&mo.kind, ch, opts, &mo.loc, &mo.id, pcol)?
            .ok_or_else(|| {
                unsupported(
                    mo,
                    format!("material '{}' of type {}", mo.id, mo.type_name()),
                )
            })?;
        match &mat {
            Material::Emitter(e) if e.is_direct_source(false) => {
                return Err(unsupported(
                    mo,
                    format!(
                        "local light source material '{}' ({}) on surface '{}': only distant sources (source primitives) and glow with maxrad <= 0 are traced",
                        mo.id,
                        mo.type_name(),
                        surface.id
                    ),
                ));
            }
            Material::Emitter(e) if e.alternate().is_some() => {
                return Err(unsupported(
                    mo,
                    format!("alternate material of illum '{}'", mo.id),
                ));
            }
            Material::Mirror(mm) if mm.alternate.is_some() => {
                return Err(unsupported(
                    mo,
                    format!("alternate material of mirror '{}'", mo.id),
                ));
            }
            _ => {}
        }
        self.patterned.push((!varying.is_empty()).then(|| {
            std::sync::Arc::new(PatternedMaterial::new(
                mo,
                pcol,
                CalPatterns {
                    list: varying,
                    ch: *ch,
                },
                opts,
                mat.clone(),
            ))
        }));
        self.materials.push(mat);
        self.material_ids.push(mo.id.clone());
        Ok(())
    }

    /// A `source` object `i` of the scene (`index`: its position in the whole scene).
    pub(super) fn source(&self, i: usize, index: usize, sources: &mut Sources) -> Result<()> {
        let o = &self.scene.objects[i];
        if let Primitive::Source { direction, angle } = &o.kind {
            if let Some(mut s) = distant_source(
                &self.cal, self.scene, i, o, *direction, *angle, &self.ch, &self.opts,
            )? {
                s.scene_index = index;
                sources.list.push(s);
            }
        }
        Ok(())
    }

    /// The materials, their scene names and their ray-dependent patterns, in slot order.
    #[allow(clippy::type_complexity)]
    pub(super) fn finish(
        self,
    ) -> (
        Vec<Material>,
        Vec<String>,
        Vec<Option<std::sync::Arc<PatternedMaterial>>>,
    ) {
        (self.materials, self.material_ids, self.patterned)
    }
}

impl Renderable {
    /// Compile a parsed scene for channels `ch` with shading options `opts` (use
    /// [`ShadingOptions::rcontrib`] for coefficients, [`ShadingOptions::rtrace`] for values).
    pub fn compile(scene: &Scene, ch: &Channels, opts: &ShadingOptions) -> Result<Renderable> {
        Self::compile_compact(&CompactScene::from_scene(scene)?, ch, opts)
    }

    /// [`Renderable::compile`] for a scene loaded column-wise
    /// ([`crate::scene::load_compact`]): the same result, with a fraction of the memory.
    pub fn compile_compact(
        scene: &CompactScene,
        ch: &Channels,
        opts: &ShadingOptions,
    ) -> Result<Renderable> {
        Ok(Self::compile_parts(scene, ch, opts, |_, _, _| {})?.0)
    }

    /// Compile, also giving `keep` the material slots, the expanded scene they index
    /// (`mesh` and `instance` surfaces and materials appended) and the files the expansion
    /// read: what a compiled scene file stores besides the renderable
    /// ([`super::compiled`]).
    pub(crate) fn compile_parts(
        compact: &CompactScene,
        ch: &Channels,
        opts: &ShadingOptions,
        keep: impl FnOnce(&Scene, &[Slot], &[std::path::PathBuf]),
    ) -> Result<(Renderable, Vec<Slot>)> {
        // `mesh` and `instance` primitives: their files' surfaces are appended to a copy of
        // the scene as units (`super::expand`), each traced through one shared BVH placed by
        // every primitive that names it; the primitives themselves are skipped below.
        let expanded = super::expand::expand(&compact.rest)?;
        let scene: &Scene = &expanded.scene;
        let table = &compact.surfaces;
        let rest_len = compact.rest.objects.len();
        let total = compact.len();
        // Position in the whole scene of object `k` of the expanded scene (unit objects
        // after every object of the scene, as if appended to it).
        let index_of = |k: usize| match compact.rest_index.get(k) {
            Some(&i) => i as usize,
            None => total + (k - rest_len),
        };
        let mut shading = Shading::new(scene, ch, opts);
        let mut sources = Sources::default();
        // Top-level glass polygons: candidate portals (`super::portals`); more than
        // MAX_PORTALS of them and none is used, so collecting stops one beyond.
        let mut panes: Vec<Vec<[f64; 3]>> = Vec::new();
        let mut surfaces: Vec<SurfaceInfo> = Vec::new();
        let mut slots: Vec<Slot> = Vec::new();
        let mut mat_index: std::collections::HashMap<(usize, Vec<usize>), u32> = Default::default();
        // Per direct modifier: its slot, once known (most surfaces share a few modifiers,
        // so the chain is walked once per modifier, not once per surface).
        const UNSET: u32 = u32::MAX;
        const NO_MATERIAL: u32 = u32::MAX - 1;
        let mut memo: Vec<u32> = vec![UNSET; scene.objects.len()];
        let mut slot_of = |direct: Option<usize>,
                           name: &dyn Fn() -> SurfaceName,
                           shading: &mut Shading|
         -> Result<Option<u32>> {
            let Some(d) = direct else {
                return Ok(None);
            };
            match memo[d] {
                UNSET => {}
                NO_MATERIAL => return Ok(None),
                k => return Ok(Some(k)),
            }
            let chain = || std::iter::once(d).chain(scene.modifier_chain(d));
            let Some(m) = chain().find(|&k| scene.objects[k].class() == Class::Material) else {
                // void: transparent to every ray (see the module documentation)
                memo[d] = NO_MATERIAL;
                return Ok(None);
            };
            let between: Vec<usize> = chain().take_while(|&k| k != m).collect();
            let key = (m, between);
            let k = match mat_index.get(&key) {
                Some(&k) => k,
                None => {
                    let first = name();
                    shading.add(m, &key.1, &first)?;
                    let k = slots.len() as u32;
                    slots.push(Slot {
                        material: m,
                        between: key.1.clone(),
                        first,
                    });
                    mat_index.insert(key, k);
                    k
                }
            };
            memo[d] = k;
            Ok(Some(k))
        };
        // The objects of the scene in order, then each unit's (their shapes go to the
        // unit's own BVH, in file coordinates).
        let mut top: Vec<GeoRef> = Vec::new();
        let mut unit_items: Vec<Vec<GeoRef>> = vec![Vec::new(); expanded.units.len()];
        let mut unit_start: Vec<usize> = vec![0; expanded.units.len()];
        let mut scratch = Vec::new();
        let units = expanded
            .units
            .iter()
            .enumerate()
            .flat_map(|(u, unit)| unit.objects.clone().map(move |k| (Ok(k), Some(u))));
        for (item, unit) in compact.order().map(|x| (x, None)).chain(units) {
            if let Some(u) = unit {
                if unit_items[u].is_empty() {
                    unit_start[u] = surfaces.len();
                }
            }
            let (geo, direct, otype, shape, index) = match item {
                Err(t) => {
                    let direct = table.modifier(t);
                    let otype = table.otype(t);
                    (
                        GeoRef::Table(t as u32),
                        direct,
                        otype,
                        shape_of_args(otype, table.reals(t)),
                        table.index(t),
                    )
                }
                Ok(k) => {
                    let o = &scene.objects[k];
                    match &o.kind {
                        Primitive::Source { .. } => {
                            shading.source(k, index_of(k), &mut sources)?;
                            continue;
                        }
                        kind if !kind.is_surface() => continue,
                        Primitive::Instance { .. } | Primitive::Mesh { .. } => continue,
                        Primitive::Other { .. } => {
                            return Err(unsupported(
                                o,
                                format!(
                                    "primitive type '{}' ('{}'); supported surfaces: polygon, sphere, bubble, cone, cup, cylinder, tube, ring, source, mesh, instance",
                                    o.type_name(),
                                    o.id
                                ),
                            ));
                        }
                        _ => {}
                    }
                    (
                        GeoRef::Object(k as u32),
                        o.modifier.filter(|&m| m < k),
                        o.kind.otype(),
                        shape_of(&o.kind),
                        index_of(k),
                    )
                }
            };
            let geo_src = GeoSource {
                table,
                scene,
                items: &[],
            };
            let name = || geo_src.name(geo);
            let Some(mi) = slot_of(direct, &name, &mut shading)? else {
                continue; // void: transparent to every ray (see the module documentation)
            };
            let shape = shape.ok_or_else(|| {
                let n = name();
                Error::unsupported(
                    n.loc,
                    format!("primitive type '{}' ('{}')", n.otype.name(), n.id),
                )
            })?;
            shape.validate(&mut scratch).map_err(|e| {
                let n = name();
                Error::parse(n.loc, format!("{} '{}': {e}", n.otype.name(), n.id))
            })?;
            if let (None, ShapeRef::Polygon(flat), Material::Glass(_)) =
                (unit, &shape, &shading.materials[mi as usize])
            {
                if panes.len() <= super::portals::MAX_PORTALS {
                    panes.push(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect());
                }
            }
            match unit {
                None => top.push(geo),
                Some(u) => unit_items[u].push(geo),
            }
            surfaces.push(SurfaceInfo {
                material: mi,
                flat: matches!(otype, OType::Polygon | OType::Ring),
                scene_index: index as u32,
            });
        }
        let build_error = |e: crate::geometry::BuildError, items: &[GeoRef]| {
            let n = GeoSource {
                table,
                scene,
                items,
            }
            .name(items[e.index]);
            Error::parse(n.loc, format!("{} '{}': {}", n.otype.name(), n.id, e.error))
        };
        // One shared BVH per unit; every placement refers to it through its transform.
        let mut unit_bvh = Vec::with_capacity(unit_items.len());
        for items in &unit_items {
            let src = GeoSource {
                table,
                scene,
                items,
            };
            unit_bvh.push(std::sync::Arc::new(
                Bvh::build_source(&src, Vec::new(), false).map_err(|e| build_error(e, items))?,
            ));
        }
        let placed = expanded
            .placements
            .iter()
            .filter(|p| !unit_items[p.unit].is_empty())
            .map(|p| Placed {
                bvh: unit_bvh[p.unit].clone(),
                fwd: p.xf.m,
                inv: p.xf.inverse().m,
                sca: p.xf.sca,
                id_offset: unit_start[p.unit] as u32,
            })
            .collect();
        let src = GeoSource {
            table,
            scene,
            items: &top,
        };
        let bvh = Bvh::build_source(&src, placed, false).map_err(|e| build_error(e, &top))?;
        keep(scene, &slots, &expanded.files);
        let r = Renderable::assemble(bvh, surfaces, shading, sources, ch, panes);
        Ok((r, slots))
    }

    /// The renderable of built geometry and shading, with the portals found among the
    /// glass polygons `panes` (vertex lists; kept for compiled scenes).
    pub(super) fn assemble(
        bvh: Bvh,
        surfaces: Vec<SurfaceInfo>,
        shading: Shading,
        sources: Sources,
        ch: &Channels,
        panes: Vec<Vec<[f64; 3]>>,
    ) -> Renderable {
        let (materials, material_ids, patterned) = shading.finish();
        let mut r = Renderable {
            bvh,
            surfaces,
            materials,
            material_ids,
            patterned,
            sources,
            ncomp: ch.ncomp.max(1),
            portals: Default::default(),
            pane_polygons: Vec::new(),
        };
        let list = panes
            .iter()
            .filter_map(|v| super::portals::Portal::new(v))
            .collect();
        r.portals = r.find_portals(list);
        r.pane_polygons = panes;
        r
    }

    /// Number of window panes sampled as portals ([`super::portals`]).
    pub fn portal_count(&self) -> usize {
        self.portals.len()
    }

    /// The material of index `k` at a hit (`dir` the ray direction, `h` the hit): the
    /// compiled material, or for ray-dependent `.cal` patterns, the material with the
    /// pattern colour at this hit.
    pub(super) fn material_at(
        &self,
        k: u32,
        dir: Vec3,
        h: &crate::geometry::Hit,
    ) -> std::borrow::Cow<'_, Material> {
        match self.patterned.get(k as usize).and_then(|p| p.as_deref()) {
            Some(p) => std::borrow::Cow::Owned(p.at(
                dir.to_array(),
                h.normal.to_array(),
                h.point.to_array(),
                h.t,
            )),
            None => std::borrow::Cow::Borrowed(&self.materials[k as usize]),
        }
    }

    /// The distant sources (sun, sky, ground) in scene order.
    pub fn sources(&self) -> &Sources {
        &self.sources
    }

    /// Number of traced surfaces (void-modified ones are left out).
    pub fn surface_count(&self) -> usize {
        self.surfaces.len()
    }

    /// Channels per value.
    pub fn ncomp(&self) -> usize {
        self.ncomp
    }

    /// The BVH (for benchmarks and tools that only cast rays).
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }
}
