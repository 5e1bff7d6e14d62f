//! One bounding volume hierarchy over a whole scene, with exact `f64` hits.
//!
//! Structure: polygons are triangulated ([`super::triangulate`]); every triangle and every
//! analytic shape (sphere, cone, cylinder, ring) becomes one primitive with an axis-aligned
//! box. `obvhs` builds a binary PLOC BVH (Meister & Bittner 2018; preset [`PRESET`]) over
//! the boxes, [`super::wide`] turns it into obvhs's compressed 8-wide BVH (CWBVH, Ylitie et
//! al. 2017) on every core, node for node what obvhs's own serial conversion makes, and
//! obvhs's traversal calls back into our own `f64` intersection routines for each candidate.
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
//! **Two levels.** [`Bvh::build_two_level`] also takes [`Placed`] BVHs (instanced geometry,
//! stored once): each is one primitive of the top level whose box is its BVH's box moved by
//! the placement; a ray reaching it is taken into the shared BVH's coordinates by the
//! inverse transform (distances scale by the similarity's factor), and the hit's normal
//! moved back as a vector, as Radiance traces instances (`src/rt/o_instance.c`).
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
    bvh2::reinsertion::ReinsertionOptimizer,
    cwbvh::CwBvh,
    ploc::PlocBuilder,
    ray::{Ray as BvhRay, RayHit},
};

use rayon::prelude::*;

use super::ray::{Hit, Ray};
use super::shapes::{AnalyticGeom, Object, ShapeError, ShapeRef, TriGeom, flat_vertices};
use super::triangulate::{newell_normal, triangulate_into};
use super::vec3::Vec3;

/// The build parameters: obvhs' `fast_build` preset (PLOC search distance 6, 2 % of the
/// nodes re-inserted). Against `medium_build` (distance 14, 5 %) it builds a 1M-triangle
/// scene in about three quarters of the CPU time (1.28 against 1.63 CPU-s, this machine,
/// issue 18) and traces as fast (1.3-1.4e5 paths/s on that scene, 5.4-7.2e5 on the
/// furnished office, both presets, same bytes). Hits are exact whichever the tree (the
/// BVH only culls), so the preset changes speed only, and at most which of two surfaces hit
/// at exactly the same distance is reported (see "Ties" above).
pub const PRESET: BvhBuildParams = BvhBuildParams::fast_build();

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
    /// Index into `Bvh::placed`.
    Placed(u32),
}

/// A shared BVH placed in the scene (an `instance` or `mesh` primitive): the second level
/// of a two-level BVH. The transform is a similarity (rotations, mirrors, one uniform
/// scale), as Radiance's `xf` allows, so distances scale by `sca` and normals move as
/// vectors (`src/rt/o_instance.c`).
#[derive(Clone)]
pub struct Placed {
    pub bvh: std::sync::Arc<Bvh>,
    /// Forward matrix for row vectors: `world = local · m` (translation in row 3).
    pub fwd: [[f64; 4]; 4],
    /// Its inverse.
    pub inv: [[f64; 4]; 4],
    /// The scale of `fwd` (> 0): world distance = local distance × `sca`.
    pub sca: f64,
    /// Added to the shared BVH's object ids in hits.
    pub id_offset: u32,
}

impl std::fmt::Debug for Placed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Placed")
            .field("primitives", &self.bvh.primitive_count())
            .field("sca", &self.sca)
            .field("id_offset", &self.id_offset)
            .finish()
    }
}

fn mat_point(m: &[[f64; 4]; 4], p: Vec3) -> Vec3 {
    Vec3::new(
        p.x * m[0][0] + p.y * m[1][0] + p.z * m[2][0] + m[3][0],
        p.x * m[0][1] + p.y * m[1][1] + p.z * m[2][1] + m[3][1],
        p.x * m[0][2] + p.y * m[1][2] + p.z * m[2][2] + m[3][2],
    )
}

fn mat_vector(m: &[[f64; 4]; 4], v: Vec3) -> Vec3 {
    Vec3::new(
        v.x * m[0][0] + v.y * m[1][0] + v.z * m[2][0],
        v.x * m[0][1] + v.y * m[1][1] + v.z * m[2][1],
        v.x * m[0][2] + v.y * m[1][2] + v.z * m[2][2],
    )
}

impl Placed {
    /// The world ray as the shared BVH sees it (unit direction) and the factor from world
    /// to local distances (`1 / sca`).
    #[inline]
    fn local_ray(&self, org: Vec3, dir: Vec3) -> Ray {
        Ray {
            org: mat_point(&self.inv, org),
            dir: mat_vector(&self.inv, dir) * self.sca,
        }
    }

    /// World bounds: the shared BVH's box corners moved by the transform.
    fn bounds(&self) -> (Vec3, Vec3) {
        let (a, b) = (self.bvh.lo + self.bvh.centre, self.bvh.hi + self.bvh.centre);
        let mut lo = Vec3::splat(f64::INFINITY);
        let mut hi = Vec3::splat(f64::NEG_INFINITY);
        for k in 0..8 {
            let c = Vec3::new(
                if k & 1 == 0 { a.x } else { b.x },
                if k & 2 == 0 { a.y } else { b.y },
                if k & 4 == 0 { a.z } else { b.z },
            );
            let w = mat_point(&self.fwd, c);
            lo = lo.min(w);
            hi = hi.max(w);
        }
        (lo, hi)
    }
}

/// `v[j] = v[from[j]]` for every `j`, in place, when `from` is a permutation (cycle by
/// cycle, each element moved once); otherwise (never for obvhs' trees without spatial
/// splits) through a copy.
fn gather_in_place<T: Copy>(v: &mut Vec<T>, from: &[u32]) {
    let n = v.len();
    let mut seen = vec![false; n];
    let permutation = from.len() == n
        && from.iter().all(|&k| {
            let k = k as usize;
            k < n && !std::mem::replace(&mut seen[k], true)
        });
    if !permutation {
        *v = from
            .iter()
            .filter_map(|&k| v.get(k as usize).copied())
            .collect();
        return;
    }
    let mut done = seen;
    done.fill(false);
    for start in 0..n {
        if done[start] {
            continue;
        }
        let first = v[start];
        let mut j = start;
        loop {
            done[j] = true;
            let k = from[j] as usize;
            if k == start {
                v[j] = first;
                break;
            }
            v[j] = v[k];
            j = k;
        }
    }
}

/// Fewest shapes one thread of the build reads at a time.
const PIECE: usize = 1 << 13;

/// `f` over consecutive ranges covering `0..n`, on every core, the results in order.
fn in_pieces<T: Send>(n: usize, f: impl Fn(std::ops::Range<usize>) -> T + Sync) -> Vec<T> {
    let size = n
        .div_ceil(4 * rayon::current_num_threads())
        .max(PIECE)
        .max(1);
    let starts: Vec<usize> = (0..n).step_by(size).collect();
    starts
        .par_iter()
        .map(|&a| f(a..(a + size).min(n)))
        .collect()
}

/// What a primitive is, before the BVH orders them: a triangle of object `.0` (vertex
/// numbers into its polygon), an analytic object, or a placed BVH.
#[derive(Debug, Clone, Copy)]
enum PrimSrc {
    Tri(u32, [u32; 3]),
    Analytic(u32),
    Placed(u32),
}

/// The surfaces a BVH is built over: `count` of them, surface `i` as a borrowed shape and
/// the id its hits report. Shared between the build's threads.
pub trait ShapeSource: Sync {
    fn count(&self) -> usize;
    fn get(&self, i: usize) -> (ShapeRef<'_>, u32);
}

impl ShapeSource for [Object] {
    fn count(&self) -> usize {
        self.len()
    }
    fn get(&self, i: usize) -> (ShapeRef<'_>, u32) {
        (self[i].shape.as_ref(), self[i].id)
    }
}

#[derive(Debug, Clone, Copy)]
struct Prim {
    geom: PrimGeom,
    /// Index into `Bvh::objects`.
    obj: u32,
}

impl Bvh {
    /// Distance to primitive `p` along the local ray (`org` relative to `centre`).
    #[inline(always)]
    fn prim_hit(&self, p: &Prim, org: Vec3, dir: Vec3, tmin: f64, tmax: f64) -> Option<f64> {
        self.prim_hit_inner(p, org, dir, tmin, tmax).map(|(t, _)| t)
    }

    /// [`Bvh::prim_hit`], with the shared BVH's own hit (object and local normal) when `p`
    /// is placed, so the closest hit need not be searched for a second time.
    #[inline(always)]
    fn prim_hit_inner(
        &self,
        p: &Prim,
        org: Vec3,
        dir: Vec3,
        tmin: f64,
        tmax: f64,
    ) -> Option<(f64, Option<Hit>)> {
        match &p.geom {
            PrimGeom::Tri(t) => t.intersect(org, dir, tmin, tmax).map(|t| (t, None)),
            PrimGeom::Analytic(a) => a.intersect(org, dir, tmin, tmax).map(|t| (t, None)),
            PrimGeom::Placed(k) => {
                let pl = &self.placed[*k as usize];
                let r = pl.local_ray(org + self.centre, dir);
                pl.bvh
                    .intersect(&r, tmin / pl.sca, tmax / pl.sca)
                    .map(|h| (h.t * pl.sca, Some(h)))
                    .filter(|&(t, _)| t > tmin && t < tmax)
            }
        }
    }

    /// Whether primitive `p` blocks the local ray before `tmax` (shadow rays).
    #[inline(always)]
    fn prim_blocks(&self, p: &Prim, org: Vec3, dir: Vec3, tmax: f64) -> bool {
        match &p.geom {
            PrimGeom::Placed(k) => {
                let pl = &self.placed[*k as usize];
                let r = pl.local_ray(org + self.centre, dir);
                pl.bvh.occluded(&r, tmax / pl.sca)
            }
            _ => self.prim_hit(p, org, dir, 0.0, tmax).is_some(),
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
    /// Second-level BVHs (see [`Placed`]).
    placed: Vec<Placed>,
    build_time: Duration,
}

impl Bvh {
    /// Build with the [`PRESET`] parameters.
    pub fn build(objects: &[Object]) -> Result<Bvh, BuildError> {
        Self::build_with(objects, PRESET)
    }

    /// Build a two-level BVH with the [`PRESET`] parameters (see [`Bvh::build_two_level`]).
    pub fn build_placed(objects: &[Object], placed: Vec<Placed>) -> Result<Bvh, BuildError> {
        Self::build_two_level(objects, placed, PRESET)
    }

    /// Build with explicit obvhs parameters.
    pub fn build_with(objects: &[Object], params: BvhBuildParams) -> Result<Bvh, BuildError> {
        Self::build_two_level(objects, Vec::new(), params)
    }

    /// Build over `objects` and placed shared BVHs (a two-level BVH: instanced geometry is
    /// stored once and traversed through each placement's transform).
    pub fn build_two_level(
        objects: &[Object],
        placed: Vec<Placed>,
        params: BvhBuildParams,
    ) -> Result<Bvh, BuildError> {
        Self::build_from(objects, placed, params, true)
    }

    /// Build over any [`ShapeSource`] (the tracer reads its column-wise scene in place),
    /// with the [`PRESET`] parameters. `validate: false` skips [`ShapeRef::validate`] for a
    /// caller that checked every shape already (to name its own `file:line`); a polygon
    /// that does not triangulate is still an error.
    pub fn build_source<S: ShapeSource + ?Sized>(
        objects: &S,
        placed: Vec<Placed>,
        validate: bool,
    ) -> Result<Bvh, BuildError> {
        Self::build_from(objects, placed, PRESET, validate)
    }

    fn build_from<S: ShapeSource + ?Sized>(
        objects: &S,
        placed: Vec<Placed>,
        params: BvhBuildParams,
        validate: bool,
    ) -> Result<Bvh, BuildError> {
        let start = std::time::Instant::now();
        let placed: Vec<Placed> = placed
            .into_iter()
            .filter(|p| p.bvh.cwbvh.is_some())
            .collect();
        let n = objects.count();
        // The shapes are read in pieces on every core, and the pieces' results joined in
        // order: the first error is the one a serial loop meets first, and the minima,
        // maxima, primitives and boxes are the very values it computes (issue 18).
        let pieces = in_pieces(n, |range| {
            let mut scratch: Vec<Vec3> = Vec::new();
            let mut lo = Vec3::splat(f64::INFINITY);
            let mut hi = Vec3::splat(f64::NEG_INFINITY);
            for index in range {
                let (shape, id) = objects.get(index);
                if validate {
                    shape.validate(&mut scratch).map_err(|error| BuildError {
                        index,
                        id,
                        error,
                    })?;
                }
                let (a, b) = shape.bounds();
                lo = lo.min(a);
                hi = hi.max(b);
            }
            Ok((lo, hi))
        });
        let mut lo = Vec3::splat(f64::INFINITY);
        let mut hi = Vec3::splat(f64::NEG_INFINITY);
        for piece in pieces {
            let (a, b) = piece?;
            lo = lo.min(a);
            hi = hi.max(b);
        }
        for p in &placed {
            let (a, b) = p.bounds();
            lo = lo.min(a);
            hi = hi.max(b);
        }
        if n == 0 && placed.is_empty() {
            return Ok(Bvh {
                centre: Vec3::ZERO,
                lo: Vec3::ZERO,
                hi: Vec3::ZERO,
                pad: 0.0,
                cwbvh: None,
                prims: Vec::new(),
                objects: Vec::new(),
                placed: Vec::new(),
                build_time: start.elapsed(),
            });
        }
        let centre = (lo + hi) * 0.5;
        let diag = (hi - lo).length();
        let pad = 1e-5 * diag + 4.0 * f32::EPSILON as f64;

        // Pass 1: what each primitive is (16 bytes) and its box. The primitives themselves
        // (72-byte triangles) are made only in pass 2, in leaf order, so the two never
        // coexist with the builder's own arrays (issue 18: peak memory of 1M triangles).
        let to_aabb = |a: Vec3, b: Vec3| {
            let (a, b) = (a - Vec3::splat(pad), b + Vec3::splat(pad));
            Aabb::new(a.to_f32().into(), b.to_f32().into())
        };
        let pieces = in_pieces(n, |range| {
            let mut srcs: Vec<PrimSrc> = Vec::with_capacity(range.len());
            let mut boxes: Vec<Aabb> = Vec::with_capacity(range.len());
            let mut scratch: Vec<Vec3> = Vec::new();
            let mut tris: Vec<[usize; 3]> = Vec::new();
            for index in range {
                let obj = index as u32;
                let (shape, id) = objects.get(index);
                match shape {
                    ShapeRef::Polygon(flat) => {
                        scratch.clear();
                        scratch.extend(flat_vertices(flat).map(|p| p - centre));
                        let v = &scratch;
                        triangulate_into(v, &mut tris).map_err(|e| BuildError {
                            index,
                            id,
                            error: ShapeError::Polygon(e),
                        })?;
                        for &[a, b, c] in &tris {
                            let (pa, pb, pc) = (v[a], v[b], v[c]);
                            srcs.push(PrimSrc::Tri(obj, [a as u32, b as u32, c as u32]));
                            boxes.push(to_aabb(pa.min(pb).min(pc), pa.max(pb).max(pc)));
                        }
                    }
                    shape => {
                        let (a, b) = shape.bounds();
                        srcs.push(PrimSrc::Analytic(obj));
                        boxes.push(to_aabb(a - centre, b - centre));
                    }
                }
            }
            Ok((srcs, boxes))
        });
        let mut srcs: Vec<PrimSrc> = Vec::with_capacity(n + placed.len());
        let mut boxes: Vec<Aabb> = Vec::with_capacity(n + placed.len());
        for piece in pieces {
            let (s, b) = piece?;
            srcs.extend_from_slice(&s);
            boxes.extend_from_slice(&b);
        }
        for (k, p) in placed.iter().enumerate() {
            let (a, b) = p.bounds();
            srcs.push(PrimSrc::Placed(k as u32));
            boxes.push(to_aabb(a - centre, b - centre));
        }
        // obvhs's `build_cwbvh` step by step: its PLOC build and reinsertion, then our
        // conversion to the wide BVH, on every core, node for node obvhs's serial one
        // (`wide.rs`; issue 18).
        let mut bvh2 = PlocBuilder::with_capacity(boxes.len()).build(
            params.ploc_search_distance,
            &boxes,
            (0..boxes.len() as u32).collect(),
            params.sort_precision,
            params.search_depth_threshold,
        );
        ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
        #[cfg(debug_assertions)]
        bvh2.validate(&boxes, false, params.pre_split);
        let cwbvh = super::wide::bvh2_to_cwbvh(&bvh2, params.max_prims_per_leaf.clamp(1, 3));
        drop(bvh2);
        #[cfg(debug_assertions)]
        cwbvh.validate(&boxes, false);
        drop(boxes);
        // Pass 2: the primitives and each object's normal in input order (reading the
        // shapes sequentially), then the primitives put in leaf order in place, so that
        // traversal indexes them directly. Made in leaf order straight away, each would
        // fetch its polygon from a random place (a cache miss per array); gathered into a
        // second array, they would take 80 MB more for 1M triangles.
        let vertex = |flat: &[f64], k: u32| {
            let k = 3 * k as usize;
            Vec3::new(flat[k], flat[k + 1], flat[k + 2]) - centre
        };
        let prim_of = |src: &PrimSrc| match *src {
            PrimSrc::Tri(obj, [a, b, c]) => {
                let ShapeRef::Polygon(flat) = objects.get(obj as usize).0 else {
                    unreachable!("triangles come from polygons")
                };
                Prim {
                    geom: PrimGeom::Tri(TriGeom::new(
                        vertex(flat, a),
                        vertex(flat, b),
                        vertex(flat, c),
                    )),
                    obj,
                }
            }
            PrimSrc::Analytic(obj) => Prim {
                geom: PrimGeom::Analytic(
                    AnalyticGeom::new(objects.get(obj as usize).0, centre)
                        .expect("non-polygon shapes always have an analytic form"),
                ),
                obj,
            },
            PrimSrc::Placed(k) => Prim {
                geom: PrimGeom::Placed(k),
                obj: u32::MAX,
            },
        };
        // A polygon's normal from all its vertices (its triangles share it); none for
        // analytic shapes, whose normal varies.
        let info_of = |scratch: &mut Vec<Vec3>, obj: usize| {
            let (shape, id) = objects.get(obj);
            let normal = match shape {
                ShapeRef::Polygon(flat) => {
                    scratch.clear();
                    scratch.extend(flat_vertices(flat).map(|p| p - centre));
                    newell_normal(scratch).normalize()
                }
                _ => Vec3::ZERO,
            };
            ObjInfo { id, normal }
        };
        let mut prims: Vec<Prim> = Vec::with_capacity(srcs.len());
        let mut infos: Vec<ObjInfo> = Vec::with_capacity(n);
        rayon::join(
            || {
                srcs.par_iter()
                    .with_min_len(PIECE)
                    .map(prim_of)
                    .collect_into_vec(&mut prims)
            },
            || {
                (0..n)
                    .into_par_iter()
                    .with_min_len(PIECE)
                    .map_init(Vec::new, info_of)
                    .collect_into_vec(&mut infos)
            },
        );
        drop(srcs);
        gather_in_place(&mut prims, &cwbvh.primitive_indices);
        // Traversal hands out leaf positions, which now index `prims` directly.
        let mut cwbvh = cwbvh;
        cwbvh.primitive_indices = Vec::new();
        Ok(Bvh {
            centre,
            lo: lo - centre - Vec3::splat(pad),
            hi: hi - centre + Vec3::splat(pad),
            pad,
            cwbvh: Some(cwbvh),
            prims,
            objects: infos,
            placed,
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
        let mut best_inner = None;
        let pad = self.pad as f32;
        let mut rh = RayHit::none();
        cw.ray_traverse(bray, &mut rh, |_, id| {
            // SAFETY-free: `id` indexes primitive_indices, which has prims.len() entries.
            match self.prim_hit_inner(&self.prims[id], org, dir, tmin, best_t) {
                Some((t, inner)) => {
                    best_t = t;
                    best = id;
                    best_inner = inner;
                    // Culling distance for obvhs: never below the true hit.
                    ((t - s) as f32) * (1.0 + 1e-6) + pad
                }
                None => f32::INFINITY,
            }
        });
        if best == usize::MAX {
            return None;
        }
        Some(self.make_hit(ray, best, best_t, best_inner))
    }

    /// The hit on primitive `prim` at `t`; `inner` is the shared BVH's own hit when the
    /// primitive is placed.
    fn make_hit(&self, ray: &Ray, prim: usize, t: f64, inner: Option<Hit>) -> Hit {
        let p = &self.prims[prim];
        let (normal, object) = match &p.geom {
            PrimGeom::Tri(_) => {
                let info = self.objects[p.obj as usize];
                (info.normal, info.id)
            }
            PrimGeom::Analytic(a) => {
                let info = self.objects[p.obj as usize];
                (a.normal(ray.org - self.centre + ray.dir * t), info.id)
            }
            PrimGeom::Placed(k) => {
                let pl = &self.placed[*k as usize];
                match inner {
                    Some(h) => (
                        mat_vector(&pl.fwd, h.normal).normalize(),
                        h.object + pl.id_offset,
                    ),
                    None => (Vec3::new(0.0, 0.0, 1.0), pl.id_offset),
                }
            }
        };
        Hit {
            t,
            point: ray.at(t),
            normal,
            object,
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
            if self.prim_blocks(&self.prims[id], org, dir, tmax) {
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
            if let Some((t, inner)) = self.prim_hit_inner(p, org, ray.dir, tmin, best_t) {
                best_t = t;
                best = Some((i, inner));
            }
        }
        best.map(|(i, inner)| self.make_hit(ray, i, best_t, inner))
    }
}

/// Compiled scene files (`rdc --compile`): a BVH written as built and read back exactly, so
/// tracing from the file gives the same bytes as tracing the scene. Layout:
/// `docs/scene-binary-formats.md`, "Compiled scenes".
mod binary {
    use super::*;
    use crate::formats::scene::compiled::{Decoder, Encoder};
    use obvhs::cwbvh::node::CwBvhNode;

    const TRI: u8 = 0;
    const SPHERE: u8 = 1;
    const CONE: u8 = 2;
    const RING: u8 = 3;
    const PLACED: u8 = 4;

    fn v3(e: &mut Encoder, v: Vec3) {
        e.f64(v.x);
        e.f64(v.y);
        e.f64(v.z);
    }

    /// Three doubles from the first 24 bytes of `b` (24 or more).
    #[inline(always)]
    fn get_v3(b: &[u8]) -> Vec3 {
        let b: &[u8; 24] = b[..24].try_into().expect("24 bytes");
        let f = |k: usize| {
            f64::from_le_bytes([
                b[k],
                b[k + 1],
                b[k + 2],
                b[k + 3],
                b[k + 4],
                b[k + 5],
                b[k + 6],
                b[k + 7],
            ])
        };
        Vec3::new(f(0), f(8), f(16))
    }

    fn read_v3(d: &mut Decoder, what: &str) -> Result<Vec3, crate::Error> {
        Ok(get_v3(d.bytes(24, what)?))
    }

    fn read_m4(d: &mut Decoder, what: &str) -> Result<[[f64; 4]; 4], crate::Error> {
        let v = d.f64s(16, what)?;
        Ok(std::array::from_fn(|i| {
            std::array::from_fn(|j| v[4 * i + j])
        }))
    }

    impl Bvh {
        /// Write this BVH with the shared BVHs it places (each once).
        pub fn encode(&self, e: &mut Encoder) {
            let mut units: Vec<&std::sync::Arc<Bvh>> = Vec::new();
            let unit_of: Vec<usize> = self
                .placed
                .iter()
                .map(
                    |p| match units.iter().position(|u| std::sync::Arc::ptr_eq(u, &p.bvh)) {
                        Some(k) => k,
                        None => {
                            units.push(&p.bvh);
                            units.len() - 1
                        }
                    },
                )
                .collect();
            e.len(units.len());
            for u in &units {
                u.encode_one(e);
            }
            self.encode_one(e);
            e.len(self.placed.len());
            for (p, &u) in self.placed.iter().zip(&unit_of) {
                e.u32(u as u32);
                for row in p.fwd.iter().chain(&p.inv) {
                    e.f64s(row);
                }
                e.f64(p.sca);
                e.u32(p.id_offset);
            }
        }

        /// One BVH without its placements.
        fn encode_one(&self, e: &mut Encoder) {
            v3(e, self.centre);
            v3(e, self.lo);
            v3(e, self.hi);
            e.f64(self.pad);
            match &self.cwbvh {
                None => e.u8(0),
                Some(cw) => {
                    e.u8(1);
                    e.len(cw.nodes.len());
                    for n in &cw.nodes {
                        for c in n.p.to_array() {
                            e.f32(c);
                        }
                        e.bytes(&n.e);
                        e.u8(n.imask);
                        e.u32(n.child_base_idx);
                        e.u32(n.primitive_base_idx);
                        for a in [
                            &n.child_meta,
                            &n.child_min_x,
                            &n.child_max_x,
                            &n.child_min_y,
                            &n.child_max_y,
                            &n.child_min_z,
                            &n.child_max_z,
                        ] {
                            e.bytes(a);
                        }
                    }
                    for c in cw.total_aabb.min.to_array() {
                        e.f32(c);
                    }
                    for c in cw.total_aabb.max.to_array() {
                        e.f32(c);
                    }
                    e.u8(u8::from(cw.uses_spatial_splits));
                }
            }
            e.len(self.prims.len());
            for p in &self.prims {
                match &p.geom {
                    PrimGeom::Tri(t) => {
                        e.u8(TRI);
                        e.u32(p.obj);
                        v3(e, t.v0);
                        v3(e, t.e1);
                        v3(e, t.e2);
                    }
                    PrimGeom::Analytic(AnalyticGeom::Sphere { c, r, inward }) => {
                        e.u8(SPHERE);
                        e.u32(p.obj);
                        v3(e, *c);
                        e.f64(*r);
                        e.u8(u8::from(*inward));
                    }
                    PrimGeom::Analytic(AnalyticGeom::Cone {
                        p0,
                        a,
                        len,
                        r0,
                        k,
                        inward,
                    }) => {
                        e.u8(CONE);
                        e.u32(p.obj);
                        v3(e, *p0);
                        v3(e, *a);
                        e.f64s(&[*len, *r0, *k]);
                        e.u8(u8::from(*inward));
                    }
                    PrimGeom::Analytic(AnalyticGeom::Ring { c, n, rin2, rout2 }) => {
                        e.u8(RING);
                        e.u32(p.obj);
                        v3(e, *c);
                        v3(e, *n);
                        e.f64s(&[*rin2, *rout2]);
                    }
                    PrimGeom::Placed(k) => {
                        e.u8(PLACED);
                        e.u32(*k);
                    }
                }
            }
            e.len(self.objects.len());
            for o in &self.objects {
                e.u32(o.id);
                v3(e, o.normal);
            }
        }

        /// Read what [`Bvh::encode`] wrote, checking every index (nodes, primitives,
        /// objects, placements) so that tracing it can neither fail nor loop; object ids
        /// must be below `nsurfaces` (hits index the tracer's surfaces with them).
        pub fn decode(d: &mut Decoder, nsurfaces: usize) -> Result<Bvh, crate::Error> {
            let nunits = d.count(1, "shared BVH count")?;
            let mut units = Vec::with_capacity(nunits);
            for _ in 0..nunits {
                let u = Bvh::decode_one(d, 0)?;
                units.push(std::sync::Arc::new(u));
            }
            let mut top = Bvh::decode_one(d, nunits)?;
            let nplaced = d.count(4 + 33 * 8 + 4, "placement count")?;
            if top
                .prims
                .iter()
                .any(|p| matches!(p.geom, PrimGeom::Placed(k) if k as usize >= nplaced))
            {
                return Err(d.corrupted("a placement beyond the list"));
            }
            for _ in 0..nplaced {
                let unit = d.required_index(nunits, "shared BVH")?;
                let fwd = read_m4(d, "placement matrix")?;
                let inv = read_m4(d, "placement inverse")?;
                let sca = d.f64("placement scale")?;
                let id_offset = d.u32("placement id offset")?;
                let bvh = units[unit].clone();
                let top_id = bvh.objects.iter().map(|o| o.id as usize).max();
                if top_id.is_some_and(|m| m + id_offset as usize >= nsurfaces) {
                    return Err(d.corrupted("a placed surface beyond the surface list"));
                }
                top.placed.push(Placed {
                    bvh,
                    fwd,
                    inv,
                    sca,
                    id_offset,
                });
            }
            if top.objects.iter().any(|o| o.id as usize >= nsurfaces) {
                return Err(d.corrupted("a surface beyond the surface list"));
            }
            Ok(top)
        }

        /// One BVH (its placements, if any, are read by [`Bvh::decode`]): `nunits` > 0
        /// allows placed primitives.
        fn decode_one(d: &mut Decoder, nunits: usize) -> Result<Bvh, crate::Error> {
            let centre = read_v3(d, "BVH centre")?;
            let lo = read_v3(d, "BVH bounds")?;
            let hi = read_v3(d, "BVH bounds")?;
            let pad = d.f64("BVH padding")?;
            let cwbvh = if d.bool("BVH flag")? {
                let n = d.count(80, "BVH node count")?;
                let mut nodes = Vec::with_capacity(n);
                for _ in 0..n {
                    let b = d.bytes(80, "BVH node")?;
                    let f = |k: usize| f32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]);
                    let u = |k: usize| u32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]);
                    let a8 = |k: usize| -> [u8; 8] { std::array::from_fn(|i| b[k + i]) };
                    nodes.push(CwBvhNode {
                        p: [f(0), f(4), f(8)].into(),
                        e: [b[12], b[13], b[14]],
                        imask: b[15],
                        child_base_idx: u(16),
                        primitive_base_idx: u(20),
                        child_meta: a8(24),
                        child_min_x: a8(32),
                        child_max_x: a8(40),
                        child_min_y: a8(48),
                        child_max_y: a8(56),
                        child_min_z: a8(64),
                        child_max_z: a8(72),
                    });
                }
                let f = d.f32s6("BVH box")?;
                let spatial = d.bool("BVH split flag")?;
                Some(CwBvh {
                    nodes,
                    primitive_indices: Vec::new(),
                    total_aabb: Aabb::new([f[0], f[1], f[2]].into(), [f[3], f[4], f[5]].into()),
                    exact_node_aabbs: None,
                    uses_spatial_splits: spatial,
                })
            } else {
                None
            };
            let np = d.count(5, "primitive count")?;
            let mut prims = Vec::with_capacity(np);
            while prims.len() < np {
                // Runs of triangles (all of a polygon scene's primitives) straight from
                // the bytes: 77-byte records, one bounds check each.
                let rest = d.peek();
                let mut used = 0;
                while prims.len() < np {
                    let Some(r) = rest.get(used..used + 77).filter(|r| r[0] == TRI) else {
                        break;
                    };
                    prims.push(Prim {
                        geom: PrimGeom::Tri(TriGeom {
                            v0: get_v3(&r[5..29]),
                            e1: get_v3(&r[29..53]),
                            e2: get_v3(&r[53..77]),
                        }),
                        obj: u32::from_le_bytes([r[1], r[2], r[3], r[4]]),
                    });
                    used += 77;
                }
                d.bytes(used, "triangles")?;
                if prims.len() == np {
                    break;
                }
                let tag = d.u8("primitive type")?;
                let obj = d.u32("primitive object")?;
                let geom = match tag {
                    TRI => {
                        let b = d.bytes(72, "triangle")?;
                        PrimGeom::Tri(TriGeom {
                            v0: get_v3(&b[0..24]),
                            e1: get_v3(&b[24..48]),
                            e2: get_v3(&b[48..72]),
                        })
                    }
                    SPHERE => PrimGeom::Analytic(AnalyticGeom::Sphere {
                        c: read_v3(d, "sphere")?,
                        r: d.f64("sphere")?,
                        inward: d.bool("sphere")?,
                    }),
                    CONE => PrimGeom::Analytic(AnalyticGeom::Cone {
                        p0: read_v3(d, "cone")?,
                        a: read_v3(d, "cone")?,
                        len: d.f64("cone")?,
                        r0: d.f64("cone")?,
                        k: d.f64("cone")?,
                        inward: d.bool("cone")?,
                    }),
                    RING => PrimGeom::Analytic(AnalyticGeom::Ring {
                        c: read_v3(d, "ring")?,
                        n: read_v3(d, "ring")?,
                        rin2: d.f64("ring")?,
                        rout2: d.f64("ring")?,
                    }),
                    PLACED if nunits > 0 => PrimGeom::Placed(obj),
                    t => return Err(d.corrupted(format!("primitive type {t}"))),
                };
                let obj = if matches!(geom, PrimGeom::Placed(_)) {
                    u32::MAX
                } else {
                    obj
                };
                prims.push(Prim { geom, obj });
            }
            let no = d.count(28, "object count")?;
            let objects: Vec<ObjInfo> = d
                .bytes(28 * no, "objects")?
                .chunks_exact(28)
                .map(|r| ObjInfo {
                    id: u32::from_le_bytes([r[0], r[1], r[2], r[3]]),
                    normal: get_v3(&r[4..]),
                })
                .collect();
            if prims
                .iter()
                .any(|p| !matches!(p.geom, PrimGeom::Placed(_)) && p.obj as usize >= no)
            {
                return Err(d.corrupted("a primitive of an object beyond the list"));
            }
            match &cwbvh {
                Some(cw) => check_nodes(cw, prims.len()).map_err(|e| d.corrupted(e))?,
                None if !prims.is_empty() => {
                    return Err(d.corrupted("primitives without a BVH"));
                }
                None => {}
            }
            Ok(Bvh {
                centre,
                lo,
                hi,
                pad,
                cwbvh,
                prims,
                objects,
                placed: Vec::new(),
                build_time: Duration::ZERO,
            })
        }
    }

    /// The structure obvhs' traversal relies on (`cwbvh/traverse_macro.rs`,
    /// `node.rs::get_child_and_index_bits`): every child slot is empty, an inner child
    /// (`meta = 0b001_11sss`, slot `s`, bit `s` of `imask`) or a leaf of 1-3 primitives
    /// (`meta` = unary count << 5 | offset < 24); inner children lie after their parent
    /// (so traversal ends) and inside the node list; leaves inside the primitive list.
    pub(super) fn check_nodes(cw: &CwBvh, nprims: usize) -> Result<(), String> {
        if cw.nodes.is_empty() {
            return Err("a BVH without nodes".into());
        }
        for (i, n) in cw.nodes.iter().enumerate() {
            let mut inner = 0u8;
            for (s, &meta) in n.child_meta.iter().enumerate() {
                if meta == 0 {
                    continue;
                }
                if meta & 0b11000 == 0b11000 {
                    if meta != 0b0010_0000 | (24 + s as u8) {
                        return Err(format!("node {i}: child {s} is malformed"));
                    }
                    inner |= 1 << s;
                } else {
                    let count = match meta >> 5 {
                        0b001 => 1,
                        0b011 => 2,
                        0b111 => 3,
                        _ => return Err(format!("node {i}: leaf {s} is malformed")),
                    };
                    let end = n.primitive_base_idx as usize + (meta & 31) as usize + count;
                    if (meta & 31) as usize + count > 24 || end > nprims {
                        return Err(format!("node {i}: leaf {s} beyond the primitives"));
                    }
                }
            }
            if inner != n.imask {
                return Err(format!("node {i}: inner children disagree with its mask"));
            }
            let k = inner.count_ones() as usize;
            let base = n.child_base_idx as usize;
            if k > 0 && (base <= i || base + k > cw.nodes.len()) {
                return Err(format!("node {i}: children outside the node list"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Shape;
    use rand::{Rng, SeedableRng};

    /// Rotate about z by 30°, mirror x, scale 1.7, translate: a similarity as `xf` makes.
    fn transform() -> ([[f64; 4]; 4], [[f64; 4]; 4], f64) {
        let (s, c) = 30f64.to_radians().sin_cos();
        let k = 1.7;
        // Row vectors: p' = p R M S + t, with R = rz(30), M = mirror x.
        let fwd = [
            [-c * k, s * k, 0.0, 0.0],
            [s * k, c * k, 0.0, 0.0],
            [0.0, 0.0, k, 0.0],
            [3.0, -1.0, 0.5, 1.0],
        ];
        // Inverse of a similarity: the 3x3 part transposed over k², translation back.
        let mut inv = [[0.0; 4]; 4];
        for i in 0..3 {
            for j in 0..3 {
                inv[i][j] = fwd[j][i] / (k * k);
            }
        }
        let back: [f64; 3] =
            std::array::from_fn(|n| -(0..3).map(|i| fwd[3][i] * inv[i][n]).sum::<f64>());
        inv[3][..3].copy_from_slice(&back);
        inv[3][3] = 1.0;
        (fwd, inv, k)
    }

    fn local_shapes() -> Vec<Shape> {
        vec![
            Shape::Polygon {
                vertices: vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
            },
            Shape::Polygon {
                vertices: vec![[0., 0., 0.], [0., 0., 1.], [1., 0., 1.]],
            },
            Shape::Sphere {
                centre: [0.5, 0.5, 0.6],
                radius: 0.3,
                inward: false,
            },
        ]
    }

    /// The same shapes moved into the world (polygon order reversed under a mirror, as
    /// `xform` does).
    fn world_shapes(fwd: &[[f64; 4]; 4], k: f64) -> Vec<Shape> {
        let p = |v: [f64; 3]| mat_point(fwd, Vec3::from(v)).to_array();
        local_shapes()
            .into_iter()
            .map(|s| match s {
                Shape::Polygon { vertices } => Shape::Polygon {
                    vertices: vertices.into_iter().rev().map(p).collect(),
                },
                Shape::Sphere {
                    centre,
                    radius,
                    inward,
                } => Shape::Sphere {
                    centre: p(centre),
                    radius: radius * k,
                    inward,
                },
                other => other,
            })
            .collect()
    }

    #[test]
    fn gathering_in_place_is_gathering() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        for n in [0usize, 1, 2, 7, 100, 1000] {
            let mut from: Vec<u32> = (0..n as u32).collect();
            for i in (1..n).rev() {
                from.swap(i, rng.random_range(0..=i));
            }
            let v: Vec<u64> = (0..n as u64).map(|x| x * 7 + 1).collect();
            let want: Vec<u64> = from.iter().map(|&k| v[k as usize]).collect();
            let mut got = v.clone();
            gather_in_place(&mut got, &from);
            assert_eq!(got, want, "n {n}");
        }
        // Not a permutation: a plain gather.
        let mut v = vec![1, 2, 3];
        gather_in_place(&mut v, &[2, 2, 0]);
        assert_eq!(v, [3, 3, 1]);
    }

    #[test]
    fn built_bvhs_pass_the_file_checks_and_round_trip() {
        use crate::formats::scene::compiled::{Decoder, Encoder};
        let (fwd, inv, k) = transform();
        let objs = |shapes: Vec<Shape>| -> Vec<Object> {
            shapes
                .into_iter()
                .enumerate()
                .map(|(i, shape)| Object {
                    shape,
                    id: i as u32,
                })
                .collect()
        };
        let shared = std::sync::Arc::new(Bvh::build(&objs(local_shapes())).unwrap());
        let mut top_shapes = world_shapes(&fwd, k);
        top_shapes.push(Shape::Cone {
            p0: [0., 0., 0.],
            p1: [0., 0., 1.],
            r0: 0.5,
            r1: 0.2,
            inward: false,
        });
        top_shapes.push(Shape::Ring {
            centre: [1., 1., 1.],
            normal: [0., 0., 1.],
            r_in: 0.1,
            r_out: 0.3,
        });
        let placed = Placed {
            bvh: shared,
            fwd,
            inv,
            sca: k,
            id_offset: 5,
        };
        let bvh = Bvh::build_placed(&objs(top_shapes), vec![placed]).unwrap();
        let mut e = Encoder::default();
        bvh.encode(&mut e);
        let mut d = Decoder::new(&e.buf, 0, "t");
        let back = Bvh::decode(&mut d, 8).unwrap();
        d.finish().unwrap();
        let mut again = Encoder::default();
        back.encode(&mut again);
        assert_eq!(again.buf, e.buf);
        // Hits are the same, bit for bit.
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        for _ in 0..2000 {
            let org = Vec3::new(
                rng.random_range(-3.0..6.0),
                rng.random_range(-4.0..4.0),
                rng.random_range(-1.0..3.0),
            );
            let dir = Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let ray = Ray::new(org, dir);
            let (a, b) = (
                bvh.intersect(&ray, 0.0, f64::INFINITY),
                back.intersect(&ray, 0.0, f64::INFINITY),
            );
            assert_eq!(format!("{a:?}"), format!("{b:?}"));
        }
        // Too few surfaces for the ids: refused.
        let mut d = Decoder::new(&e.buf, 0, "t");
        assert!(Bvh::decode(&mut d, 7).is_err());
        // Every prefix is an error; any byte changed is an error or a BVH that traces.
        for n in 0..e.buf.len() {
            let mut d = Decoder::new(&e.buf[..n], 0, "t");
            assert!(
                Bvh::decode(&mut d, 8).and_then(|_| d.finish()).is_err(),
                "{n}"
            );
        }
        for at in 0..e.buf.len() {
            let mut b = e.buf.clone();
            b[at] ^= 0x5a;
            let mut d = Decoder::new(&b, 0, "t");
            if let Ok(bvh) = Bvh::decode(&mut d, 8) {
                let ray = Ray::new(Vec3::new(0.5, 0.5, 2.0), Vec3::new(0.1, 0.0, -1.0));
                let _ = bvh.intersect(&ray, 0.0, f64::INFINITY);
                let _ = bvh.occluded(&ray, 10.0);
            }
        }
    }

    #[test]
    fn placed_bvh_hits_like_the_same_shapes_moved() {
        let (fwd, inv, k) = transform();
        let objs = |shapes: Vec<Shape>| -> Vec<Object> {
            shapes
                .into_iter()
                .enumerate()
                .map(|(i, shape)| Object {
                    shape,
                    id: i as u32,
                })
                .collect()
        };
        let shared = std::sync::Arc::new(Bvh::build(&objs(local_shapes())).unwrap());
        // A floor of our own plus the placed unit, against everything flattened.
        let floor = Object {
            shape: Shape::Polygon {
                vertices: vec![
                    [-5., -5., -0.1],
                    [8., -5., -0.1],
                    [8., 8., -0.1],
                    [-5., 8., -0.1],
                ],
            },
            id: 0,
        };
        let placed = Placed {
            bvh: shared,
            fwd,
            inv,
            sca: k,
            id_offset: 1,
        };
        let two = Bvh::build_placed(std::slice::from_ref(&floor), vec![placed]).unwrap();
        let mut flat = vec![floor];
        flat.extend(
            world_shapes(&fwd, k)
                .into_iter()
                .enumerate()
                .map(|(i, shape)| Object {
                    shape,
                    id: i as u32 + 1,
                }),
        );
        let flat = Bvh::build(&flat).unwrap();
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let mut hits = 0;
        for _ in 0..4000 {
            let org = Vec3::new(
                rng.random_range(-2.0..6.0),
                rng.random_range(-4.0..4.0),
                rng.random_range(-0.05..3.0),
            );
            let dir = Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            let ray = Ray::new(org, dir);
            let (a, b) = (
                two.intersect(&ray, 0.0, f64::INFINITY),
                flat.intersect(&ray, 0.0, f64::INFINITY),
            );
            match (a, b) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    hits += 1;
                    assert!((a.t - b.t).abs() < 1e-9 * b.t.max(1.0), "{a:?} vs {b:?}");
                    assert_eq!((a.object, a.front), (b.object, b.front), "{a:?} vs {b:?}");
                    assert!((a.normal - b.normal).length() < 1e-9, "{a:?} vs {b:?}");
                    // Shadow rays agree too, just before and after the hit.
                    assert!(two.occluded(&ray, b.t * 1.0001) && !two.occluded(&ray, b.t * 0.9999));
                }
                (a, b) => panic!("ray {ray:?}: two-level {a:?}, flat {b:?}"),
            }
            let bf = two.intersect_brute_force(&ray, 0.0, f64::INFINITY);
            assert_eq!(bf.map(|h| h.object), b.map(|h| h.object));
        }
        assert!(
            hits > 1000,
            "{hits} hits: the rays must mostly meet the scene"
        );
    }
}
