//! One bounding volume hierarchy over a whole scene, with exact `f64` hits.
//!
//! Structure: polygons are triangulated ([`super::triangulate`]); every triangle and every
//! analytic shape (sphere, cone, cylinder, ring) becomes one primitive with an axis-aligned
//! box. `obvhs` builds a compressed 8-wide BVH (CWBVH, Ylitie et al. 2017, from a PLOC BVH2,
//! Meister & Bittner 2018; preset `BvhBuildParams::medium_build`) over the boxes, and its
//! traversal calls back into our own `f64` intersection routines for each candidate.
//!
//! **Precision.** The BVH works in `f32`. Two measures keep that from costing accuracy:
//! 1. *Recentring.* At build time the centre of the scene's bounding box is subtracted from
//!    all geometry (in `f64`), so BVH coordinates are at most half the scene size and a room
//!    1e5 m from the origin is traced exactly like the same room at the origin; hit points are
//!    reported in world coordinates (`ray.org + t·dir`).
//! 2. *Conservative culling.* Every box is padded by `pad = 1e-5·S + 4·ε_f32` (`S` = scene
//!    bounding-box diagonal), far more than the `f32` rounding of box corners (≈6e-8·S) and of
//!    the ray (origin moved to the scene-box entry first, so the `f32` error is relative to
//!    `S`, not to the ray's distance from the scene). obvhs also ignores any node whose exit
//!    distance is below its fixed `EPSILON = 1e-4` (`cwbvh/node.rs`), which would lose every
//!    surface within 0.1 mm of a ray's origin (contact shadows, secondary rays); so the `f32`
//!    ray starts [`BACKOFF`] = 4e-4 before the true interval. The BVH only culls; the closest hit is kept
//!    in `f64` by the callback, so `t` and the object are exactly those of a brute-force loop
//!    over the same primitives.
//!
//! Ties: when two primitives are hit at exactly the same `t` (a ray through the shared edge of
//! two triangles of one polygon), either may be reported; both belong to the same object and
//! plane, so nothing downstream can tell.
//!
//! Self-intersection avoidance for secondary rays is the caller's, via
//! [`super::Hit::spawn`] (offset along the normal, see `ray.rs`), then `tmin = 0`.

use std::time::Duration;

use obvhs::{
    BvhBuildParams,
    aabb::Aabb,
    cwbvh::{CwBvh, builder::build_cwbvh},
    ray::{Ray as BvhRay, RayHit},
};

use super::Shape;
use super::ray::{Hit, Ray};
use super::shapes::{AnalyticGeom, Object, ShapeError, TriGeom};
use super::triangulate::{newell_normal, triangulate};
use super::vec3::Vec3;

/// How far before the wanted interval the `f32` traversal ray starts: 4 × obvhs' node
/// `EPSILON` (1e-4, a distance below which it drops node exits), in scene units.
pub const BACKOFF: f64 = 4e-4;

/// A shape that could not be added, with its position in the input and its object id so the
/// caller can name the `file:line` it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct BuildError {
    /// Index in the slice given to [`Bvh::build`].
    pub index: usize,
    /// The object's id.
    pub id: u32,
    pub error: ShapeError,
}

impl std::fmt::Display for BuildError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "object {} (id {}): {}", self.index, self.id, self.error)
    }
}

impl std::error::Error for BuildError {}

impl BuildError {
    /// The library error at `loc`, the `file:line` the caller knows for object `index`.
    pub fn at(&self, loc: crate::Location) -> crate::Error {
        self.error.at(loc)
    }
}

/// A direction the intersection routines can use: finite and not zero (a zero direction,
/// e.g. from normalising a zero vector, would make a sphere report the origin as a hit).
#[inline(always)]
fn usable(dir: Vec3) -> bool {
    dir.is_finite() && dir.length_squared() > 0.0
}

#[derive(Debug, Clone, Copy)]
enum PrimGeom {
    Tri(TriGeom),
    Analytic(AnalyticGeom),
}

#[derive(Debug, Clone, Copy)]
struct Prim {
    geom: PrimGeom,
    /// Index into `Bvh::objects`.
    obj: u32,
}

impl Prim {
    #[inline(always)]
    fn intersect(&self, org: Vec3, dir: Vec3, tmin: f64, tmax: f64) -> Option<f64> {
        match &self.geom {
            PrimGeom::Tri(t) => t.intersect(org, dir, tmin, tmax),
            PrimGeom::Analytic(a) => a.intersect(org, dir, tmin, tmax),
        }
    }
}

#[derive(Debug, Clone, Copy)]
struct ObjInfo {
    id: u32,
    /// Unit front normal of a polygon (zero for analytic shapes, whose normal varies).
    normal: Vec3,
}

/// Scene acceleration structure: build once, then trace from many threads (`Bvh: Sync`).
pub struct Bvh {
    centre: Vec3,
    /// Padded local bounds of the whole scene.
    lo: Vec3,
    hi: Vec3,
    pad: f64,
    cwbvh: Option<CwBvh>,
    /// Primitives in BVH leaf order (`cwbvh.primitive_indices` already applied).
    prims: Vec<Prim>,
    objects: Vec<ObjInfo>,
    build_time: Duration,
}

impl Bvh {
    /// Build with obvhs' `medium_build` preset (its authors' balance of build and trace cost).
    pub fn build(objects: &[Object]) -> Result<Bvh, BuildError> {
        Self::build_with(objects, BvhBuildParams::medium_build())
    }

    /// Build with explicit obvhs parameters.
    pub fn build_with(objects: &[Object], params: BvhBuildParams) -> Result<Bvh, BuildError> {
        let start = std::time::Instant::now();
        let mut lo = Vec3::splat(f64::INFINITY);
        let mut hi = Vec3::splat(f64::NEG_INFINITY);
        for (index, o) in objects.iter().enumerate() {
            o.shape.validate().map_err(|error| BuildError {
                index,
                id: o.id,
                error,
            })?;
            let (a, b) = o.shape.bounds();
            lo = lo.min(a);
            hi = hi.max(b);
        }
        if objects.is_empty() {
            return Ok(Bvh {
                centre: Vec3::ZERO,
                lo: Vec3::ZERO,
                hi: Vec3::ZERO,
                pad: 0.0,
                cwbvh: None,
                prims: Vec::new(),
                objects: Vec::new(),
                build_time: start.elapsed(),
            });
        }
        let centre = (lo + hi) * 0.5;
        let diag = (hi - lo).length();
        let pad = 1e-5 * diag + 4.0 * f32::EPSILON as f64;

        let mut prims = Vec::with_capacity(objects.len());
        let mut boxes: Vec<Aabb> = Vec::with_capacity(objects.len());
        let mut infos = Vec::with_capacity(objects.len());
        let to_aabb = |a: Vec3, b: Vec3| {
            let (a, b) = (a - Vec3::splat(pad), b + Vec3::splat(pad));
            Aabb::new(a.to_f32().into(), b.to_f32().into())
        };
        for (index, o) in objects.iter().enumerate() {
            let obj = index as u32;
            match &o.shape {
                Shape::Polygon { vertices } => {
                    let v: Vec<Vec3> = vertices.iter().map(|&p| Vec3::from(p) - centre).collect();
                    let tris = triangulate(&v).map_err(|e| BuildError {
                        index,
                        id: o.id,
                        error: ShapeError::Polygon(e),
                    })?;
                    infos.push(ObjInfo {
                        id: o.id,
                        normal: newell_normal(&v).normalize(),
                    });
                    for [a, b, c] in tris {
                        let (a, b, c) = (v[a], v[b], v[c]);
                        prims.push(Prim {
                            geom: PrimGeom::Tri(TriGeom::new(a, b, c)),
                            obj,
                        });
                        boxes.push(to_aabb(a.min(b).min(c), a.max(b).max(c)));
                    }
                }
                shape => {
                    infos.push(ObjInfo {
                        id: o.id,
                        normal: Vec3::ZERO,
                    });
                    let geom = AnalyticGeom::new(shape, centre)
                        .expect("non-polygon shapes always have an analytic form");
                    let (a, b) = shape.bounds();
                    prims.push(Prim {
                        geom: PrimGeom::Analytic(geom),
                        obj,
                    });
                    boxes.push(to_aabb(a - centre, b - centre));
                }
            }
        }
        let cwbvh = build_cwbvh(&boxes, params, &mut Duration::default());
        // Store primitives in leaf order so that traversal indexes them directly.
        let prims = cwbvh
            .primitive_indices
            .iter()
            .map(|&i| prims[i as usize])
            .collect();
        Ok(Bvh {
            centre,
            lo: lo - centre - Vec3::splat(pad),
            hi: hi - centre + Vec3::splat(pad),
            pad,
            cwbvh: Some(cwbvh),
            prims,
            objects: infos,
            build_time: start.elapsed(),
        })
    }

    /// Number of BVH primitives (triangles plus analytic shapes).
    pub fn primitive_count(&self) -> usize {
        self.prims.len()
    }

    /// Wall-clock time the build took (validation, triangulation and BVH construction).
    pub fn build_time(&self) -> Duration {
        self.build_time
    }

    /// The offset subtracted from all geometry internally (centre of the scene bounds).
    pub fn centre(&self) -> Vec3 {
        self.centre
    }

    /// Entry and exit distances of the local ray through the padded scene box, or `None`.
    #[inline]
    fn clip(&self, org: Vec3, dir: Vec3, tmin: f64, tmax: f64) -> Option<(f64, f64)> {
        let (mut t0, mut t1) = (tmin, tmax);
        for ax in 0..3 {
            let inv = 1.0 / dir[ax];
            let (mut a, mut b) = ((self.lo[ax] - org[ax]) * inv, (self.hi[ax] - org[ax]) * inv);
            if a > b {
                std::mem::swap(&mut a, &mut b);
            }
            // NaN (0 · ∞ for an origin on a slab plane with a parallel ray) keeps the interval.
            if a > t0 {
                t0 = a;
            }
            if b < t1 {
                t1 = b;
            }
        }
        (t0 <= t1).then_some((t0, t1))
    }

    /// The `f32` ray obvhs traverses: origin moved to distance `s` (scene entry or `tmin`,
    /// minus [`BACKOFF`]), interval `[0, t_exit − s + pad]`.
    #[inline]
    fn bvh_ray(&self, org: Vec3, dir: Vec3, s: f64, t_exit: f64) -> BvhRay {
        let o = org + dir * s;
        BvhRay::new(
            o.to_f32().into(),
            dir.to_f32().into(),
            0.0,
            ((t_exit - s) + self.pad) as f32,
        )
    }

    /// Closest hit with `tmin < t < tmax`.
    pub fn intersect(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<Hit> {
        let cw = self.cwbvh.as_ref()?;
        let org = ray.org - self.centre;
        let dir = ray.dir;
        if !usable(dir) {
            return None;
        }
        let (enter, exit) = self.clip(org, dir, tmin, tmax)?;
        let s = enter.max(tmin) - BACKOFF;
        let bray = self.bvh_ray(org, dir, s, exit);
        let mut best_t = tmax;
        let mut best = usize::MAX;
        let pad = self.pad as f32;
        let mut rh = RayHit::none();
        cw.ray_traverse(bray, &mut rh, |_, id| {
            // SAFETY-free: `id` indexes primitive_indices, which has prims.len() entries.
            match self.prims[id].intersect(org, dir, tmin, best_t) {
                Some(t) => {
                    best_t = t;
                    best = id;
                    // Culling distance for obvhs: never below the true hit.
                    ((t - s) as f32) * (1.0 + 1e-6) + pad
                }
                None => f32::INFINITY,
            }
        });
        if best == usize::MAX {
            return None;
        }
        Some(self.make_hit(ray, best, best_t))
    }

    fn make_hit(&self, ray: &Ray, prim: usize, t: f64) -> Hit {
        let p = &self.prims[prim];
        let info = self.objects[p.obj as usize];
        let normal = match &p.geom {
            PrimGeom::Tri(_) => info.normal,
            PrimGeom::Analytic(a) => a.normal(ray.org - self.centre + ray.dir * t),
        };
        Hit {
            t,
            point: ray.at(t),
            normal,
            object: info.id,
            front: ray.dir.dot(normal) < 0.0,
        }
    }

    /// True when anything is hit with `0 < t < tmax` (shadow rays; stops at the first hit).
    pub fn occluded(&self, ray: &Ray, tmax: f64) -> bool {
        let Some(cw) = self.cwbvh.as_ref() else {
            return false;
        };
        let org = ray.org - self.centre;
        let dir = ray.dir;
        if !usable(dir) {
            return false;
        }
        let Some((enter, exit)) = self.clip(org, dir, 0.0, tmax) else {
            return false;
        };
        let s = enter.max(0.0) - BACKOFF;
        let bray = self.bvh_ray(org, dir, s, exit);
        !cw.ray_traverse_miss(bray, |_, id| {
            if self.prims[id].intersect(org, dir, 0.0, tmax).is_some() {
                f32::NEG_INFINITY
            } else {
                f32::INFINITY
            }
        })
    }

    /// Closest hit by testing every primitive (no BVH): the oracle for the traversal.
    pub fn intersect_brute_force(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<Hit> {
        let org = ray.org - self.centre;
        let mut best_t = tmax;
        let mut best = None;
        for (i, p) in self.prims.iter().enumerate() {
            if let Some(t) = p.intersect(org, ray.dir, tmin, best_t) {
                best_t = t;
                best = Some(i);
            }
        }
        best.map(|i| self.make_hit(ray, i, best_t))
    }
}
