//! 3-vectors, one home for the whole stack: [`Vec3`], a small `f64` 3-vector for the
//! ray-tracing hot path, and free functions on `[f64; 3]` ([`V3`]) for code that keeps
//! plain arrays (formats, samplers, glare, reconstruction).
//!
//! Three normalisations are kept on purpose, each bit-identical to what its users have
//! always computed (outputs are compared byte for byte across versions and with Radiance):
//! [`normalized`] divides by the length (as [`Vec3::normalize`]); [`normalized_recip`]
//! multiplies by its reciprocal (the material samplers); [`normalize_radiance`] is
//! Radiance's `normalize` (`src/common/fvect.c`) with its first-order shortcut for lengths
//! within `FTINY` of 1 (views and cameras, to agree with Radiance to the last bits).
//!
//! Why not `nalgebra::Vector3<f64>`: nalgebra's generic storage compiles to the same code in
//! release builds, but its debug builds (which the test profile uses for this crate) are many
//! times slower, its operator impls go through several layers of traits, and the intersection
//! routines read better with plain `x, y, z` fields. `Vec3` is `Copy`, `#[repr(C)]` (24 bytes,
//! no padding), and converts to and from `nalgebra::Vector3<f64>` and `[f64; 3]` for callers
//! that use those.

/// Largest magnitude of a coordinate, radius or normal component a shape may have, in scene
/// units (metres). The BVH (`rdaylight_physics::geometry::bvh`) stores boxes in `f32`, whose
/// largest value is 3.4e38: a sphere of radius 1e39 became an infinite box and obvhs indexed out of bounds
/// (issue #19). 1e9 m (2.6 times the distance to the Moon) keeps box corners, their
/// differences (2e9) and the squared extents of its surface-area heuristic (4e18) finite
/// and exact enough in `f32`, and the squares the `f64` intersection routines form (1e18)
/// far from overflow, while no daylight scene comes near it.
/// View points (`-vp`) are held to the same bound: rays from there would meet the same
/// BVH and overflow the same way (issue #19).
pub const MAX_COORDINATE: f64 = 1e9;

use std::ops::{Add, AddAssign, Div, Index, Mul, Neg, Sub, SubAssign};

/// A 3-vector (point, direction or normal) in double precision.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[repr(C)]
pub struct Vec3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl Vec3 {
    pub const ZERO: Vec3 = Vec3::new(0.0, 0.0, 0.0);

    #[inline(always)]
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Vec3 { x, y, z }
    }
    #[inline(always)]
    pub const fn splat(v: f64) -> Self {
        Vec3 { x: v, y: v, z: v }
    }
    #[inline(always)]
    pub fn dot(self, o: Vec3) -> f64 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    #[inline(always)]
    pub fn cross(self, o: Vec3) -> Vec3 {
        Vec3::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
    #[inline(always)]
    pub fn length_squared(self) -> f64 {
        self.dot(self)
    }
    #[inline(always)]
    pub fn length(self) -> f64 {
        self.dot(self).sqrt()
    }
    /// Unit vector in the same direction; the zero vector stays zero (callers check lengths
    /// where it matters).
    #[inline(always)]
    pub fn normalize(self) -> Vec3 {
        let l = self.length();
        if l > 0.0 { self / l } else { self }
    }
    #[inline(always)]
    pub fn min(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x.min(o.x), self.y.min(o.y), self.z.min(o.z))
    }
    #[inline(always)]
    pub fn max(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x.max(o.x), self.y.max(o.y), self.z.max(o.z))
    }
    #[inline(always)]
    pub fn abs(self) -> Vec3 {
        Vec3::new(self.x.abs(), self.y.abs(), self.z.abs())
    }
    /// Largest component.
    #[inline(always)]
    pub fn max_elem(self) -> f64 {
        self.x.max(self.y).max(self.z)
    }
    /// Largest absolute component (the infinity norm).
    #[inline(always)]
    pub fn max_abs(self) -> f64 {
        self.abs().max_elem()
    }
    #[inline(always)]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
    #[inline(always)]
    pub fn to_array(self) -> [f64; 3] {
        [self.x, self.y, self.z]
    }
    #[inline(always)]
    pub fn to_f32(self) -> [f32; 3] {
        [self.x as f32, self.y as f32, self.z as f32]
    }
}

impl From<[f64; 3]> for Vec3 {
    #[inline(always)]
    fn from(a: [f64; 3]) -> Self {
        Vec3::new(a[0], a[1], a[2])
    }
}
impl From<Vec3> for [f64; 3] {
    #[inline(always)]
    fn from(v: Vec3) -> Self {
        v.to_array()
    }
}
impl From<nalgebra::Vector3<f64>> for Vec3 {
    #[inline(always)]
    fn from(v: nalgebra::Vector3<f64>) -> Self {
        Vec3::new(v.x, v.y, v.z)
    }
}
impl From<Vec3> for nalgebra::Vector3<f64> {
    #[inline(always)]
    fn from(v: Vec3) -> Self {
        nalgebra::Vector3::new(v.x, v.y, v.z)
    }
}

impl Index<usize> for Vec3 {
    type Output = f64;
    /// Component by axis number 0, 1, 2 (panics on other values, like an array).
    #[inline(always)]
    fn index(&self, i: usize) -> &f64 {
        match i {
            0 => &self.x,
            1 => &self.y,
            2 => &self.z,
            _ => panic!("Vec3 index {i} out of range 0..3"),
        }
    }
}

impl Add for Vec3 {
    type Output = Vec3;
    #[inline(always)]
    fn add(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}
impl AddAssign for Vec3 {
    #[inline(always)]
    fn add_assign(&mut self, o: Vec3) {
        *self = *self + o;
    }
}
impl Sub for Vec3 {
    type Output = Vec3;
    #[inline(always)]
    fn sub(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
impl SubAssign for Vec3 {
    #[inline(always)]
    fn sub_assign(&mut self, o: Vec3) {
        *self = *self - o;
    }
}
impl Mul<f64> for Vec3 {
    type Output = Vec3;
    #[inline(always)]
    fn mul(self, s: f64) -> Vec3 {
        Vec3::new(self.x * s, self.y * s, self.z * s)
    }
}
impl Mul<Vec3> for f64 {
    type Output = Vec3;
    #[inline(always)]
    fn mul(self, v: Vec3) -> Vec3 {
        v * self
    }
}
impl Div<f64> for Vec3 {
    type Output = Vec3;
    #[inline(always)]
    fn div(self, s: f64) -> Vec3 {
        Vec3::new(self.x / s, self.y / s, self.z / s)
    }
}
impl Neg for Vec3 {
    type Output = Vec3;
    #[inline(always)]
    fn neg(self) -> Vec3 {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}

/// A point or direction as a plain array.
pub type V3 = [f64; 3];

/// Radiance's `FTINY` (double build, `src/common/fvect.h`).
pub const FTINY: f64 = 1e-6;

/// Dot product in Radiance's order (`DOT`: x, then y, then z).
#[inline(always)]
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline(always)]
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
pub fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline(always)]
pub fn neg(a: V3) -> V3 {
    [-a[0], -a[1], -a[2]]
}

#[inline(always)]
pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a / |a|`, or `a` itself when it is zero.
#[inline(always)]
pub fn normalized(a: V3) -> V3 {
    let l = dot(a, a).sqrt();
    if l > 0.0 {
        [a[0] / l, a[1] / l, a[2] / l]
    } else {
        a
    }
}

/// `a (1 / |a|)`, or `a` itself when it is zero (the material samplers' rounding).
#[inline(always)]
pub fn normalized_recip(a: V3) -> V3 {
    let l = dot(a, a).sqrt();
    if l > 0.0 { scale(a, 1.0 / l) } else { a }
}

/// Normalise in place and return the old length, as Radiance's `normalize` (`fvect.c`)
/// does, including its first-order shortcut for squared lengths within `FTINY` of 1;
/// keeping the shortcut makes vectors agree with Radiance's to the last bits rather than to
/// 1e-12. A zero vector stays zero (length 0).
pub fn normalize_radiance(v: &mut V3) -> f64 {
    let d = dot(*v, *v);
    if d == 0.0 {
        return 0.0;
    }
    let (len, inv) = if (1.0 - FTINY..=1.0 + FTINY).contains(&d) {
        let len = 0.5 + 0.5 * d;
        (len, 2.0 - len)
    } else {
        let len = d.sqrt();
        (len, 1.0 / len)
    };
    *v = scale(*v, inv);
    len
}

#[cfg(test)]
mod array_tests {
    use super::*;

    #[test]
    fn normalisations_agree_to_rounding_and_keep_zero() {
        let a = [3.0, -4.0, 12.0];
        let (n1, n2) = (normalized(a), normalized_recip(a));
        let mut n3 = a;
        assert_eq!(normalize_radiance(&mut n3), 13.0);
        for i in 0..3 {
            assert!((n1[i] - n2[i]).abs() < 1e-15 && (n1[i] - n3[i]).abs() < 1e-15);
        }
        assert_eq!(Vec3::from(a).normalize().to_array(), n1);
        assert_eq!(normalized([0.0; 3]), [0.0; 3]);
        assert_eq!(normalized_recip([0.0; 3]), [0.0; 3]);
        assert_eq!(cross([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]);
    }
}
