//! Rays, hit records, and the offset that keeps secondary rays off their own surface.
//!
//! A ray is `org + t·dir` with `dir` a unit vector, so `t` is a distance in scene units
//! (metres in practice), as in Radiance (`r->rdir` is normalised; `r->rot` is the distance).
//!
//! **Front side.** Radiance calls the side a surface normal points to the *front*; a ray hits
//! the front when `dir · normal < 0` (`r->rod = -DOT(r->rdir, r->ron)` and `rod > 0` means
//! front, `src/rt/sphere.c`, `src/rt/o_cone.c`, `src/rt/o_face.c`). [`Hit::normal`] is that
//! geometric normal, never flipped towards the ray, and [`Hit::front`] says which side was hit.
//!
//! **Secondary rays and self-intersection.** A hit point carries rounding error of a few ulps
//! of its own coordinates (the world point is `local + centre`, see `bvh.rs`) plus a few
//! `f64` epsilons of the distance travelled. [`Hit::spawn_origin`] moves the origin off the
//! surface along the geometric normal, to the side the new ray leaves towards, by
//! [`offset_distance`]`(point) = 1e-9 + 2^-40 · max(|x|,|y|,|z|)`: one nanometre near the
//! origin (far above the ~1e-15 m error of a 10 m scene) and 9e-8 m for a room 1e5 m away
//! (≈6000 ulps of 1e5, still far below any real feature size). Radiance instead rejects
//! hits closer than `FTINY = 1e-6` (`src/common/fvect.h`); the offset keeps contact shadows
//! and thin gaps that `FTINY` would swallow.

use super::vec3::Vec3;

/// A ray `org + t·dir`, `dir` of unit length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    pub org: Vec3,
    pub dir: Vec3,
}

impl Ray {
    /// A ray from `org` along `dir`, which is normalised here (a zero direction stays zero and
    /// hits nothing).
    #[inline]
    pub fn new(org: Vec3, dir: Vec3) -> Self {
        Ray {
            org,
            dir: dir.normalize(),
        }
    }
    /// The point at distance `t`.
    #[inline(always)]
    pub fn at(&self, t: f64) -> Vec3 {
        self.org + self.dir * t
    }
}

/// The closest intersection of a ray with the scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the ray.
    pub t: f64,
    /// World-space hit point.
    pub point: Vec3,
    /// Unit geometric normal on Radiance's front side (outward for sphere, cone, cylinder;
    /// inward for bubble, cup, tube; right-hand rule over the vertex order for polygons; the
    /// given direction for rings). Not flipped towards the ray.
    pub normal: Vec3,
    /// The caller's object id (one per scene primitive, e.g. its index in the `.rad` input).
    pub object: u32,
    /// True when the ray arrived on the front side (`dir · normal < 0`).
    pub front: bool,
}

/// How far [`Hit::spawn_origin`] moves a point off its surface: `1e-9 + 2^-40 · max|coord|`
/// (scene units). See the module documentation for the error budget behind it.
#[inline]
pub fn offset_distance(point: Vec3) -> f64 {
    1e-9 + point.max_abs() * (1.0 / (1u64 << 40) as f64)
}

impl Hit {
    /// Origin for a secondary ray leaving this hit towards `dir` (reflected or transmitted):
    /// the hit point moved by [`offset_distance`] along the normal, to the side of `dir`.
    #[inline]
    pub fn spawn_origin(&self, dir: Vec3) -> Vec3 {
        let d = offset_distance(self.point);
        if dir.dot(self.normal) >= 0.0 {
            self.point + self.normal * d
        } else {
            self.point - self.normal * d
        }
    }
    /// A secondary ray from this hit along `dir` (normalised here); trace it with `tmin = 0`.
    #[inline]
    pub fn spawn(&self, dir: Vec3) -> Ray {
        let dir = dir.normalize();
        Ray {
            org: self.spawn_origin(dir),
            dir,
        }
    }
}
