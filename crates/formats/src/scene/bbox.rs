//! Bounding box of a scene's surfaces, computed as Radiance's `getbbox` does
//! (`src/ot/bbox.c:add2bbox`).
//!
//! - sphere/bubble: centre +- radius on each axis;
//! - polygon: its vertices;
//! - cone/cup/cylinder/tube: both end circles; ring: its outer circle. A circle of radius `r`
//!   around unit axis `a` extends `r * sqrt(1 - a_i^2)` along axis `i` (exact, not a box
//!   around the disc);
//! - `source` is at infinity and never counts; `instance`/`mesh` would need their octree or
//!   mesh file and are skipped here (getbbox reads them).

use super::{Primitive, Scene, Vec3};

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BBox {
    pub min: Vec3,
    pub max: Vec3,
}

impl BBox {
    fn empty() -> Self {
        BBox {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        }
    }

    fn add_point(&mut self, p: Vec3) {
        for ((lo, hi), v) in self.min.iter_mut().zip(&mut self.max).zip(p) {
            *lo = lo.min(v);
            *hi = hi.max(v);
        }
    }

    fn add_circle(&mut self, center: Vec3, axis: Vec3, radius: f64) {
        let len = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        for i in 0..3 {
            // A degenerate axis leaves the direction unknown: take the whole sphere.
            let a = if len > 0.0 { axis[i] / len } else { 0.0 };
            let r = (1.0 - a * a).max(0.0).sqrt() * radius.abs();
            self.min[i] = self.min[i].min(center[i] - r);
            self.max[i] = self.max[i].max(center[i] + r);
        }
    }

    fn is_empty(&self) -> bool {
        (0..3).any(|i| self.min[i] > self.max[i])
    }
}

impl Scene {
    /// Bounds of all finite surfaces, `None` if there are none.
    pub fn bounding_box(&self) -> Option<BBox> {
        let mut b = BBox::empty();
        for (_, o) in self.surfaces() {
            match &o.kind {
                Primitive::Sphere { center, radius, .. } => {
                    for i in 0..3 {
                        for s in [-1.0, 1.0] {
                            let mut p = *center;
                            p[i] += s * radius;
                            b.add_point(p);
                        }
                    }
                }
                Primitive::Polygon { vertices } => vertices.iter().for_each(|v| b.add_point(*v)),
                Primitive::Cone { p0, p1, r0, r1, .. } => {
                    let axis = [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]];
                    b.add_circle(*p0, axis, *r0);
                    b.add_circle(*p1, axis, *r1);
                }
                Primitive::Cylinder { p0, p1, radius, .. } => {
                    let axis = [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]];
                    b.add_circle(*p0, axis, *radius);
                    b.add_circle(*p1, axis, *radius);
                }
                Primitive::Ring {
                    center,
                    normal,
                    r0,
                    r1,
                } => {
                    b.add_circle(*center, *normal, r0.abs().max(r1.abs()));
                }
                _ => {}
            }
        }
        (!b.is_empty()).then_some(b)
    }
}
