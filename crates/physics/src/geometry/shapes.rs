//! Radiance's surface primitives as ray-intersection geometry.
//!
//! [`Shape`] is the input a scene converter fills from parsed `.rad` primitives
//! (`doc/ray.1`; argument layouts in radiance-notes §4.2):
//!
//! | Radiance type | [`Shape`] | front normal |
//! |---|---|---|
//! | `polygon` (3n reals) | `Polygon { vertices }` | right-hand rule over the vertex order |
//! | `sphere` / `bubble` (`cx cy cz r`) | `Sphere { inward: false / true }` | out / in |
//! | `cone` / `cup` (`p0 p1 r0 r1`) | `Cone { inward: false / true }` | out / in |
//! | `cylinder` / `tube` (`p0 p1 r`) | `Cylinder { inward: false / true }` | out / in |
//! | `ring` (`c n r0 r1`) | `Ring { centre, normal, r_in, r_out }` | `normal` |
//!
//! The converter applies Radiance's argument fix-ups before building a `Shape`: a negative
//! sphere, cylinder or cone radius flips the type (sphere↔bubble, cylinder↔tube, cone↔cup)
//! with a warning, a cone with equal radii is a cylinder, and ring radii may come in either
//! order (`src/rt/sphere.c`, `src/common/cone.c:getcone`). [`Shape::validate`] then rejects what
//! Radiance calls "illegal radii", "zero radius" or "unknown orientation".
//!
//! Cones and cylinders are open surfaces (Radiance's cone family has no end caps); both
//! sides of every surface can be hit. Intersections are exact in `f64`:
//! - sphere: the quadratic in its well-conditioned form (Ray Tracing Gems, ch. 7: the
//!   discriminant from the perpendicular distance `r² − |f − (f·d)d|²`, and the smaller root
//!   from `c/q`), so small spheres seen from far keep their precision;
//! - cone / cylinder: `|f⊥ + t d⊥|² = (r₀ + k (f·a + t d·a))²` with `k = (r₁ − r₀)/L`, keeping
//!   roots whose axial position lies in `[0, L]` (the same test as `src/rt/o_cone.c`, done in
//!   world space instead of Radiance's normalised cone space);
//! - ring: plane hit, then `r_in² ≤ |q|² ≤ r_out²`;
//! - triangle (from polygons): Möller–Trumbore with closed edge tests, in `f64`.
//!
//! [`Shape::intersect`] is a slow world-space reference (polygons by Radiance's own plane plus
//! even-odd crossing test, no triangulation) that the tests use as an independent oracle.

use super::ray::Ray;
use super::triangulate::{PolygonError, newell_normal};
use super::vec3::Vec3;

/// One scene surface, as the scene converter hands it over.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    Polygon {
        vertices: Vec<[f64; 3]>,
    },
    Sphere {
        centre: [f64; 3],
        radius: f64,
        /// `bubble`: normal points inward.
        inward: bool,
    },
    /// Truncated cone; one radius may be zero (an apex).
    Cone {
        p0: [f64; 3],
        p1: [f64; 3],
        r0: f64,
        r1: f64,
        /// `cup`: normal points inward.
        inward: bool,
    },
    Cylinder {
        p0: [f64; 3],
        p1: [f64; 3],
        r: f64,
        /// `tube`: normal points inward.
        inward: bool,
    },
    /// Disc with a hole (`r_in` may be 0); both radii orders are accepted.
    Ring {
        centre: [f64; 3],
        normal: [f64; 3],
        r_in: f64,
        r_out: f64,
    },
}

/// A shape tagged with the caller's object id, reported back in [`super::Hit::object`].
#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    pub shape: Shape,
    pub id: u32,
}

/// What is wrong with a shape's arguments (Radiance's own wording where it has one).
#[derive(Debug, Clone, PartialEq)]
pub enum ShapeError {
    Polygon(PolygonError),
    /// A coordinate or radius is NaN or infinite.
    NonFinite,
    /// A coordinate, radius or normal component beyond [`MAX_COORDINATE`] (the value).
    OutOfRange(f64),
    /// Radius zero or negative where a positive one is needed.
    IllegalRadius(f64),
    /// Cone radii both zero, negative, or ring radii equal.
    IllegalRadii(f64, f64),
    /// Axis endpoints coincide, or the ring normal is zero.
    UnknownOrientation,
}

impl std::fmt::Display for ShapeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ShapeError::Polygon(e) => e.fmt(f),
            ShapeError::NonFinite => write!(f, "non-finite argument; expected real numbers"),
            ShapeError::OutOfRange(v) => write!(
                f,
                "argument {v:e} out of range; coordinates and radii must be within \
                 +-{MAX_COORDINATE:e} m (the BVH works in 32-bit floats; model distant \
                 objects as a source or glow)"
            ),
            ShapeError::IllegalRadius(r) => {
                write!(f, "illegal radius {r}; expected a positive radius")
            }
            ShapeError::IllegalRadii(a, b) => write!(
                f,
                "illegal radii {a} {b}; expected non-negative radii, not both zero (ring: unequal)"
            ),
            ShapeError::UnknownOrientation => write!(
                f,
                "unknown orientation; expected distinct axis end points or a non-zero normal"
            ),
        }
    }
}

impl std::error::Error for ShapeError {}

impl ShapeError {
    /// The library error for this problem at `loc` (the primitive's `file:line`).
    pub fn at(&self, loc: crate::Location) -> crate::Error {
        crate::Error::parse(loc, self.to_string())
    }
}

/// The largest coordinate a shape may have (its reasons: [`crate::vec3::MAX_COORDINATE`]).
pub use crate::vec3::MAX_COORDINATE;

/// The first finite argument of `values` beyond [`MAX_COORDINATE`] (non-finite ones are
/// [`ShapeError::NonFinite`], reported by the per-shape checks).
fn out_of_range(values: impl IntoIterator<Item = f64>) -> Result<(), ShapeError> {
    match values
        .into_iter()
        .find(|v| v.is_finite() && v.abs() > MAX_COORDINATE)
    {
        Some(v) => Err(ShapeError::OutOfRange(v)),
        None => Ok(()),
    }
}

fn finite3(a: &[f64; 3]) -> bool {
    a.iter().all(|x| x.is_finite())
}

/// A shape borrowed for the BVH builder: the same cases as [`Shape`], a polygon's vertices
/// as a flat slice of coordinates (`x0 y0 z0 x1 ...`), so that a scene held column-wise (a
/// million polygons in one array) is read in place instead of copied into a `Vec` each.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShapeRef<'a> {
    /// Flat coordinates, three per vertex.
    Polygon(&'a [f64]),
    Sphere {
        centre: [f64; 3],
        radius: f64,
        inward: bool,
    },
    Cone {
        p0: [f64; 3],
        p1: [f64; 3],
        r0: f64,
        r1: f64,
        inward: bool,
    },
    Cylinder {
        p0: [f64; 3],
        p1: [f64; 3],
        r: f64,
        inward: bool,
    },
    Ring {
        centre: [f64; 3],
        normal: [f64; 3],
        r_in: f64,
        r_out: f64,
    },
}

/// The vertices of a flat coordinate slice (a trailing partial vertex is ignored; the
/// scene's count rule makes it a multiple of 3).
pub(crate) fn flat_vertices(flat: &[f64]) -> impl ExactSizeIterator<Item = Vec3> + '_ {
    flat.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2]))
}

impl Shape {
    /// The borrowed form (no copy).
    pub fn as_ref(&self) -> ShapeRef<'_> {
        match *self {
            Shape::Polygon { ref vertices } => ShapeRef::Polygon(vertices.as_flattened()),
            Shape::Sphere {
                centre,
                radius,
                inward,
            } => ShapeRef::Sphere {
                centre,
                radius,
                inward,
            },
            Shape::Cone {
                p0,
                p1,
                r0,
                r1,
                inward,
            } => ShapeRef::Cone {
                p0,
                p1,
                r0,
                r1,
                inward,
            },
            Shape::Cylinder { p0, p1, r, inward } => ShapeRef::Cylinder { p0, p1, r, inward },
            Shape::Ring {
                centre,
                normal,
                r_in,
                r_out,
            } => ShapeRef::Ring {
                centre,
                normal,
                r_in,
                r_out,
            },
        }
    }

    /// Check the arguments (see the module documentation for what the converter fixes first).
    pub fn validate(&self) -> Result<(), ShapeError> {
        self.as_ref().validate(&mut Vec::new())
    }

    /// Axis-aligned bounds `(min, max)` of a valid shape.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.as_ref().bounds()
    }

    /// Slow world-space reference intersection: nearest `t` in `(tmin, tmax)` and the front
    /// normal there. Polygons use Radiance's method (plane through the mean vertex offset, then
    /// an even-odd crossing test in the plane), not triangles.
    pub fn intersect(&self, ray: &Ray, tmin: f64, tmax: f64) -> Option<(f64, Vec3)> {
        match self {
            Shape::Polygon { vertices } => polygon_reference(vertices, ray, tmin, tmax),
            _ => {
                let g = AnalyticGeom::new(self.as_ref(), Vec3::ZERO)?;
                let t = g.intersect(ray.org, ray.dir, tmin, tmax)?;
                Some((t, g.normal(ray.at(t))))
            }
        }
    }
}

impl ShapeRef<'_> {
    /// Check the arguments, as [`Shape::validate`]; `scratch` holds a polygon's vertices
    /// (reused between calls, so checking a million polygons allocates once).
    pub fn validate(&self, scratch: &mut Vec<Vec3>) -> Result<(), ShapeError> {
        // Range first: triangulating or bounding a shape at 1e308 overflows to infinity.
        out_of_range(self.arguments())?;
        match *self {
            ShapeRef::Polygon(flat) => {
                scratch.clear();
                scratch.extend(flat_vertices(flat));
                super::triangulate::check(scratch)
                    .map(|_| ())
                    .map_err(ShapeError::Polygon)
            }
            ShapeRef::Sphere { centre, radius, .. } => {
                if !finite3(&centre) || !radius.is_finite() {
                    Err(ShapeError::NonFinite)
                } else if radius <= 0.0 {
                    Err(ShapeError::IllegalRadius(radius))
                } else {
                    Ok(())
                }
            }
            ShapeRef::Cone { p0, p1, r0, r1, .. } => {
                if !finite3(&p0) || !finite3(&p1) || !r0.is_finite() || !r1.is_finite() {
                    Err(ShapeError::NonFinite)
                } else if r0 < 0.0 || r1 < 0.0 || (r0 == 0.0 && r1 == 0.0) {
                    Err(ShapeError::IllegalRadii(r0, r1))
                } else if p0 == p1 {
                    Err(ShapeError::UnknownOrientation)
                } else {
                    Ok(())
                }
            }
            ShapeRef::Cylinder { p0, p1, r, .. } => {
                if !finite3(&p0) || !finite3(&p1) || !r.is_finite() {
                    Err(ShapeError::NonFinite)
                } else if r <= 0.0 {
                    Err(ShapeError::IllegalRadius(r))
                } else if p0 == p1 {
                    Err(ShapeError::UnknownOrientation)
                } else {
                    Ok(())
                }
            }
            ShapeRef::Ring {
                centre,
                normal,
                r_in,
                r_out,
            } => {
                if !finite3(&centre) || !finite3(&normal) || !r_in.is_finite() || !r_out.is_finite()
                {
                    Err(ShapeError::NonFinite)
                } else if r_in < 0.0 || r_out < 0.0 || r_in == r_out {
                    Err(ShapeError::IllegalRadii(r_in, r_out))
                } else if Vec3::from(normal).length_squared() == 0.0 {
                    Err(ShapeError::UnknownOrientation)
                } else {
                    Ok(())
                }
            }
        }
    }

    /// Every real argument (coordinates, radii, normal components), for range checks.
    fn arguments(&self) -> impl Iterator<Item = f64> + '_ {
        let (flat, fixed): (&[f64], [f64; 8]) = match *self {
            ShapeRef::Polygon(flat) => (flat, [0.0; 8]),
            ShapeRef::Sphere { centre, radius, .. } => (
                &[],
                [centre[0], centre[1], centre[2], radius, 0.0, 0.0, 0.0, 0.0],
            ),
            ShapeRef::Cone { p0, p1, r0, r1, .. } => {
                (&[], [p0[0], p0[1], p0[2], p1[0], p1[1], p1[2], r0, r1])
            }
            ShapeRef::Cylinder { p0, p1, r, .. } => {
                (&[], [p0[0], p0[1], p0[2], p1[0], p1[1], p1[2], r, 0.0])
            }
            ShapeRef::Ring {
                centre,
                normal,
                r_in,
                r_out,
            } => (
                &[],
                [
                    centre[0], centre[1], centre[2], normal[0], normal[1], normal[2], r_in, r_out,
                ],
            ),
        };
        flat.iter().copied().chain(fixed)
    }

    /// Axis-aligned bounds `(min, max)` of a valid shape.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        match *self {
            ShapeRef::Polygon(flat) => {
                let mut lo = Vec3::splat(f64::INFINITY);
                let mut hi = Vec3::splat(f64::NEG_INFINITY);
                for p in flat_vertices(flat) {
                    lo = lo.min(p);
                    hi = hi.max(p);
                }
                (lo, hi)
            }
            ShapeRef::Sphere { centre, radius, .. } => {
                let c = Vec3::from(centre);
                (c - Vec3::splat(radius), c + Vec3::splat(radius))
            }
            ShapeRef::Cone { p0, p1, r0, r1, .. } => cone_bounds(p0.into(), p1.into(), r0, r1),
            ShapeRef::Cylinder { p0, p1, r, .. } => cone_bounds(p0.into(), p1.into(), r, r),
            ShapeRef::Ring {
                centre,
                normal,
                r_in,
                r_out,
            } => {
                let r = r_in.max(r_out);
                let e = disc_extent(Vec3::from(normal).normalize(), r);
                let c = Vec3::from(centre);
                (c - e, c + e)
            }
        }
    }
}

/// Half-extents of a disc of radius `r` with unit normal `n`: `r·sqrt(1 − nᵢ²)` per axis.
fn disc_extent(n: Vec3, r: f64) -> Vec3 {
    let f = |c: f64| r * (1.0 - c * c).max(0.0).sqrt();
    Vec3::new(f(n.x), f(n.y), f(n.z))
}

fn cone_bounds(p0: Vec3, p1: Vec3, r0: f64, r1: f64) -> (Vec3, Vec3) {
    let a = (p1 - p0).normalize();
    let (e0, e1) = (disc_extent(a, r0), disc_extent(a, r1));
    ((p0 - e0).min(p1 - e1), (p0 + e0).max(p1 + e1))
}

/// Roots of `a t² + 2 h t + c = 0` in ascending order (`h` is half the usual `b`), computed
/// without cancellation. Returns how many are real (0, 1 or 2).
#[inline(always)]
fn quadratic_half(a: f64, h: f64, c: f64) -> (usize, f64, f64) {
    let disc = h * h - a * c;
    if disc < 0.0 {
        return (0, 0.0, 0.0);
    }
    let q = -(h + disc.sqrt().copysign(h));
    if a == 0.0 {
        if h == 0.0 {
            return (0, 0.0, 0.0);
        }
        let t = -c / (2.0 * h);
        return (1, t, t);
    }
    let t0 = q / a;
    let t1 = if q != 0.0 { c / q } else { t0 };
    if t0 <= t1 { (2, t0, t1) } else { (2, t1, t0) }
}

/// Sphere, cone, cylinder or ring, prepared for intersection, coordinates relative to the
/// scene centre the BVH subtracted (zero for world space).
#[derive(Debug, Clone, Copy)]
pub(crate) enum AnalyticGeom {
    Sphere {
        c: Vec3,
        r: f64,
        inward: bool,
    },
    /// Cylinders are cones with `k = 0`.
    Cone {
        p0: Vec3,
        /// Unit axis from p0 to p1.
        a: Vec3,
        len: f64,
        r0: f64,
        /// (r1 − r0) / len.
        k: f64,
        inward: bool,
    },
    Ring {
        c: Vec3,
        n: Vec3,
        rin2: f64,
        rout2: f64,
    },
}

impl AnalyticGeom {
    /// Prepared form of a valid non-polygon shape, shifted by `-centre`.
    pub(crate) fn new(shape: ShapeRef<'_>, centre: Vec3) -> Option<Self> {
        Some(match shape {
            ShapeRef::Polygon(_) => return None,
            ShapeRef::Sphere {
                centre: c,
                radius,
                inward,
            } => AnalyticGeom::Sphere {
                c: Vec3::from(c) - centre,
                r: radius,
                inward,
            },
            ShapeRef::Cone {
                p0,
                p1,
                r0,
                r1,
                inward,
            } => Self::cone(p0, p1, r0, r1, inward, centre),
            ShapeRef::Cylinder { p0, p1, r, inward } => Self::cone(p0, p1, r, r, inward, centre),
            ShapeRef::Ring {
                centre: c,
                normal,
                r_in,
                r_out,
            } => {
                let (lo, hi) = if r_in <= r_out {
                    (r_in, r_out)
                } else {
                    (r_out, r_in)
                };
                AnalyticGeom::Ring {
                    c: Vec3::from(c) - centre,
                    n: Vec3::from(normal).normalize(),
                    rin2: lo * lo,
                    rout2: hi * hi,
                }
            }
        })
    }

    fn cone(p0: [f64; 3], p1: [f64; 3], r0: f64, r1: f64, inward: bool, centre: Vec3) -> Self {
        let (p0, p1) = (Vec3::from(p0) - centre, Vec3::from(p1) - centre);
        let axis = p1 - p0;
        let len = axis.length();
        AnalyticGeom::Cone {
            p0,
            a: axis / len,
            len,
            r0,
            k: (r1 - r0) / len,
            inward,
        }
    }

    /// Nearest hit distance in the open interval `(tmin, tmax)`; `dir` must be unit length.
    #[inline]
    pub(crate) fn intersect(&self, org: Vec3, dir: Vec3, tmin: f64, tmax: f64) -> Option<f64> {
        match *self {
            AnalyticGeom::Sphere { c, r, .. } => {
                let f = org - c;
                let b = f.dot(dir);
                let perp = f - dir * b;
                let disc = r * r - perp.length_squared();
                if disc < 0.0 {
                    return None;
                }
                let q = -(b + disc.sqrt().copysign(b));
                let cc = f.length_squared() - r * r;
                let (t0, t1) = if q != 0.0 { (cc / q, q) } else { (0.0, 0.0) };
                let (t0, t1) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
                [t0, t1].into_iter().find(|&t| t > tmin && t < tmax)
            }
            AnalyticGeom::Cone {
                p0, a, len, r0, k, ..
            } => {
                let f = org - p0;
                let (fa, da) = (f.dot(a), dir.dot(a));
                let (fp, dp) = (f - a * fa, dir - a * da);
                let rf = r0 + k * fa;
                let qa = dp.length_squared() - k * k * da * da;
                let qh = fp.dot(dp) - k * da * rf;
                let qc = fp.length_squared() - rf * rf;
                // A ray (nearly) parallel to a generator line makes `qa` vanish; relative to
                // its terms it is then only rounding, and the equation is linear.
                let qa = if qa.abs() <= 1e-14 * (dp.length_squared() + k * k * da * da) {
                    0.0
                } else {
                    qa
                };
                let (n, t0, t1) = quadratic_half(qa, qh, qc);
                let ok = |t: f64| {
                    let h = fa + t * da;
                    t > tmin && t < tmax && (0.0..=len).contains(&h)
                };
                match n {
                    0 => None,
                    _ if ok(t0) => Some(t0),
                    2 if ok(t1) => Some(t1),
                    _ => None,
                }
            }
            AnalyticGeom::Ring { c, n, rin2, rout2 } => {
                let dn = dir.dot(n);
                if dn == 0.0 {
                    return None;
                }
                let t = (c - org).dot(n) / dn;
                if !(t > tmin && t < tmax) {
                    return None;
                }
                let q = org + dir * t - c;
                let d2 = (q - n * q.dot(n)).length_squared();
                (d2 >= rin2 && d2 <= rout2).then_some(t)
            }
        }
    }

    /// Front normal at a point on the surface (same coordinates as the geometry).
    #[inline]
    pub(crate) fn normal(&self, p: Vec3) -> Vec3 {
        match *self {
            AnalyticGeom::Sphere { c, inward, .. } => {
                let n = (p - c).normalize();
                if inward { -n } else { n }
            }
            AnalyticGeom::Cone {
                p0, a, k, inward, ..
            } => {
                let q = p - p0;
                let radial = (q - a * q.dot(a)).normalize();
                // Outward normal of the slanted side: radial·L − (r1 − r0)·axis, normalised
                // (Radiance: `(al·radial − (r1 − r0)·ad) / sl` in o_cone.c).
                let n = (radial - a * k).normalize();
                if inward { -n } else { n }
            }
            AnalyticGeom::Ring { n, .. } => n,
        }
    }
}

/// Radiance's polygon test (`src/rt/o_face.c`, `src/common/face.c:inface`): plane with the
/// Newell normal through the mean vertex offset, then an even-odd crossing count in the
/// projection that drops the normal's dominant axis.
fn polygon_reference(
    vertices: &[[f64; 3]],
    ray: &Ray,
    tmin: f64,
    tmax: f64,
) -> Option<(f64, Vec3)> {
    let v: Vec<Vec3> = vertices.iter().map(|&p| p.into()).collect();
    let n = newell_normal(&v).normalize();
    if n == Vec3::ZERO {
        return None;
    }
    let offset = v.iter().map(|p| p.dot(n)).sum::<f64>() / v.len() as f64;
    let dn = ray.dir.dot(n);
    if dn == 0.0 {
        return None;
    }
    let t = (offset - ray.org.dot(n)) / dn;
    if !(t > tmin && t < tmax) {
        return None;
    }
    let p = ray.at(t);
    let ax = if n.y.abs() > n.x.abs() { 1 } else { 0 };
    let ax = if n.z.abs() > n[ax].abs() { 2 } else { ax };
    let (xi, yi) = ((ax + 1) % 3, (ax + 2) % 3);
    let (x, y) = (p[xi], p[yi]);
    let mut inside = false;
    let mut j = v.len() - 1;
    for i in 0..v.len() {
        let (a, b) = (v[j], v[i]);
        if (a[yi] > y) != (b[yi] > y) {
            let xc = a[xi] + (y - a[yi]) * (b[xi] - a[xi]) / (b[yi] - a[yi]);
            if xc > x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside.then_some((t, n))
}

/// A triangle from a polygon, prepared for Möller–Trumbore, in BVH-local coordinates.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TriGeom {
    pub v0: Vec3,
    pub e1: Vec3,
    pub e2: Vec3,
}

impl TriGeom {
    pub(crate) fn new(a: Vec3, b: Vec3, c: Vec3) -> Self {
        TriGeom {
            v0: a,
            e1: b - a,
            e2: c - a,
        }
    }
    /// Hit distance in `(tmin, tmax)`. Edge tests are closed (`u ≥ 0`, `v ≥ 0`, `u + v ≤ 1`)
    /// so that a ray through a shared edge of two triangles of one polygon hits at least one.
    #[inline(always)]
    pub(crate) fn intersect(&self, org: Vec3, dir: Vec3, tmin: f64, tmax: f64) -> Option<f64> {
        let pv = dir.cross(self.e2);
        let det = self.e1.dot(pv);
        if det == 0.0 {
            return None;
        }
        let inv = 1.0 / det;
        let tv = org - self.v0;
        let u = tv.dot(pv) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let qv = tv.cross(self.e1);
        let v = dir.dot(qv) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = self.e2.dot(qv) * inv;
        (t > tmin && t < tmax).then_some(t)
    }
}
