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
use crate::geometry::{Bvh, Object as GeoObject, Placed, Shape, Vec3};
use crate::material::spectrum::Sampled;
use crate::material::{Color, Emitter, EmitterKind, Material, ShadingOptions};
use crate::radiometry::Channels;
use crate::scene::{Class, OType, Object, Primitive, Scene};

/// One traced surface.
#[derive(Debug, Clone, Copy, PartialEq)]
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

/// The shape of a surface primitive with Radiance's radius fix-ups; `None` for types that
/// are not traced here (the caller reports them).
fn shape_of(p: &Primitive) -> Option<Shape> {
    Some(match p {
        Primitive::Polygon { vertices } => Shape::Polygon {
            vertices: vertices.clone(),
        },
        Primitive::Sphere {
            center,
            radius,
            inward,
        } => Shape::Sphere {
            centre: *center,
            radius: radius.abs(),
            inward: *inward ^ (*radius < 0.0),
        },
        Primitive::Cylinder {
            p0,
            p1,
            radius,
            inward,
        } => Shape::Cylinder {
            p0: *p0,
            p1: *p1,
            r: radius.abs(),
            inward: *inward ^ (*radius < 0.0),
        },
        Primitive::Cone {
            p0,
            p1,
            r0,
            r1,
            inward,
        } => {
            let flip = *r0 <= 0.0 && *r1 <= 0.0 && (*r0 < 0.0 || *r1 < 0.0);
            let (r0, r1) = if flip { (-r0, -r1) } else { (*r0, *r1) };
            let inward = *inward ^ flip;
            if r0 == r1 {
                Shape::Cylinder {
                    p0: *p0,
                    p1: *p1,
                    r: r0,
                    inward,
                }
            } else {
                Shape::Cone {
                    p0: *p0,
                    p1: *p1,
                    r0,
                    r1,
                    inward,
                }
            }
        }
        Primitive::Ring {
            center,
            normal,
            r0,
            r1,
        } => Shape::Ring {
            centre: *center,
            normal: *normal,
            r_in: *r0,
            r_out: *r1,
        },
        _ => return None,
    })
}

impl Renderable {
    /// Compile a parsed scene for channels `ch` with shading options `opts` (use
    /// [`ShadingOptions::rcontrib`] for coefficients, [`ShadingOptions::rtrace`] for values).
    pub fn compile(scene: &Scene, ch: &Channels, opts: &ShadingOptions) -> Result<Renderable> {
        // `mesh` and `instance` primitives: their files' surfaces are appended to a copy of
        // the scene as units (`super::expand`), each traced through one shared BVH placed by
        // every primitive that names it; the primitives themselves are skipped below.
        let expanded = super::expand::expand(scene)?;
        let scene: &Scene = &expanded.scene;
        // Objects of the scene first, then each unit's (their shapes go to the unit's own
        // BVH, in file coordinates; `unit_start[u]` is the unit's first surface).
        let first_unit = expanded
            .units
            .first()
            .map_or(scene.objects.len(), |u| u.objects.start);
        let order = (0..first_unit).map(|i| (i, None)).chain(
            expanded
                .units
                .iter()
                .enumerate()
                .flat_map(|(u, unit)| unit.objects.clone().map(move |i| (i, Some(u)))),
        );
        let mut unit_geo: Vec<Vec<GeoObject>> = vec![Vec::new(); expanded.units.len()];
        let mut unit_start: Vec<Option<usize>> = vec![None; expanded.units.len()];
        let mut geo: Vec<GeoObject> = Vec::new();
        let mut surfaces = Vec::new();
        let mut materials: Vec<Material> = Vec::new();
        let mut material_ids: Vec<String> = Vec::new();
        // (Scene index of a material, spectral patterns between surface and material) ->
        // index in `materials`.
        let mut mat_index: std::collections::HashMap<(usize, Vec<usize>), u32> = Default::default();
        let mut patterned: Vec<Option<std::sync::Arc<PatternedMaterial>>> = Vec::new();
        let mut sources = Sources::default();
        // Top-level glass polygons: candidate portals (`super::portals`).
        let mut panes: Vec<super::portals::Portal> = Vec::new();
        let cal = ScenePatterns::new(scene, ch);
        for (i, unit) in order {
            let o = &scene.objects[i];
            if let Some(u) = unit {
                unit_start[u].get_or_insert(surfaces.len());
            }
            match &o.kind {
                Primitive::Source { direction, angle } => {
                    if let Some(mut s) =
                        distant_source(&cal, scene, i, o, *direction, *angle, ch, opts)?
                    {
                        s.scene_index = i;
                        sources.list.push(s);
                    }
                    continue;
                }
                k if !k.is_surface() => continue,
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
            let Some(m) = scene.material_of(i) else {
                continue; // void: transparent to every ray (see the module documentation)
            };
            let between: Vec<usize> = scene.modifier_chain(i).take_while(|&k| k != m).collect();
            // Ray-dependent function-file patterns are evaluated per hit; any other
            // non-constant pattern or texture is refused.
            let mut varying = Vec::new();
            for k in between.iter().copied().chain(scene.patterns_of(m)) {
                if is_spectral(&cal, scene, k) {
                    continue;
                }
                let po = &scene.objects[k];
                if is_cal_pattern(po) && !native_sky(po) {
                    varying.push(cal.get(k)?);
                    continue;
                }
                return Err(unsupported(
                    po,
                    format!(
                        "{} '{}' modifying surface '{}' (patterns and textures are not modelled)",
                        po.type_name(),
                        po.id,
                        o.id
                    ),
                ));
            }
            let key = (m, between);
            let mi = match mat_index.get(&key) {
                Some(&k) => k,
                None => {
                    let mo = &scene.objects[m];
                    let pcol = spectral_color(
                        &cal,
                        scene,
                        key.1.iter().copied().chain(scene.patterns_of(m)),
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
                                    o.id
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
                    let k = materials.len() as u32;
                    patterned.push((!varying.is_empty()).then(|| {
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
                    materials.push(mat);
                    material_ids.push(mo.id.clone());
                    mat_index.insert(key, k);
                    k
                }
            };
            let shape = shape_of(&o.kind).ok_or_else(|| {
                unsupported(
                    o,
                    format!("primitive type '{}' ('{}')", o.type_name(), o.id),
                )
            })?;
            shape.validate().map_err(|e| {
                Error::parse(o.loc.clone(), format!("{} '{}': {e}", o.type_name(), o.id))
            })?;
            let flat = matches!(shape, Shape::Polygon { .. } | Shape::Ring { .. });
            if let (None, Shape::Polygon { vertices }, Material::Glass(_)) =
                (unit, &shape, &materials[mi as usize])
            {
                if panes.len() <= super::portals::MAX_PORTALS {
                    panes.extend(super::portals::Portal::new(vertices));
                }
            }
            match unit {
                None => geo.push(GeoObject {
                    shape,
                    id: surfaces.len() as u32,
                }),
                Some(u) => {
                    let start = unit_start[u].unwrap_or(0);
                    unit_geo[u].push(GeoObject {
                        shape,
                        id: (surfaces.len() - start) as u32,
                    });
                }
            }
            surfaces.push(SurfaceInfo {
                material: mi,
                flat,
                scene_index: i as u32,
            });
        }
        let build_error = |e: crate::geometry::BuildError, start: usize| {
            let o = &scene.objects[surfaces[start + e.index].scene_index as usize];
            Error::parse(
                o.loc.clone(),
                format!("{} '{}': {}", o.type_name(), o.id, e.error),
            )
        };
        // One shared BVH per unit; every placement refers to it through its transform.
        let mut unit_bvh = Vec::with_capacity(unit_geo.len());
        for (u, g) in unit_geo.iter().enumerate() {
            let start = unit_start[u].unwrap_or(0);
            unit_bvh.push(std::sync::Arc::new(
                Bvh::build(g).map_err(|e| build_error(e, start))?,
            ));
        }
        let placed = expanded
            .placements
            .iter()
            .filter(|p| !unit_geo[p.unit].is_empty())
            .map(|p| Placed {
                bvh: unit_bvh[p.unit].clone(),
                fwd: p.xf.m,
                inv: p.xf.inverse().m,
                sca: p.xf.sca,
                id_offset: unit_start[p.unit].unwrap_or(0) as u32,
            })
            .collect();
        let bvh = Bvh::build_placed(&geo, placed).map_err(|e| build_error(e, 0))?;
        let mut r = Renderable {
            bvh,
            surfaces,
            materials,
            material_ids,
            patterned,
            sources,
            ncomp: ch.ncomp.max(1),
            portals: Default::default(),
        };
        r.portals = r.find_portals(panes);
        Ok(r)
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
