//! The points an object's box must enclose, per primitive, and the face normals worth
//! trying as box axes.
//!
//! Polygons give their vertices (exact). Curved surfaces are sampled **on** the surface
//! (the seed bounds the objects' modelled surfaces): circles by [`CIRCLE`] points, spheres by
//! [`SPHERE`] Fibonacci points plus the six axis extremes. A sampled extent is short of the
//! true one by at most `1 - cos(pi / CIRCLE)` = 0.12 % for circles and about 0.1 % for
//! spheres (their points' covering radius), inside the 0.5 % the level thresholds need. `source`, `instance`, `mesh` and any other
//! type without inline geometry give `None`: their extent is not in the scene file.

use rdaylight_base::vec3::{V3, add, dot, normalized, scale, sub};
use rdaylight_formats::scene::Primitive;

use crate::obb::tangents;

/// Points per sampled circle (cylinder, cone and ring rims).
pub const CIRCLE: usize = 64;
/// Points per sphere (Fibonacci lattice). Their covering radius is about 2.5 degrees, so an
/// extent is short by at most ~0.1 % (test `a_sphere_sample_reaches_its_radius...`).
pub const SPHERE: usize = 2000;

/// Points on a primitive's surface and its likely face normals.
#[derive(Debug, Clone, Default)]
pub struct Sampled {
    pub points: Vec<V3>,
    pub normals: Vec<V3>,
}

/// Newell's normal of a polygon (robust for non-convex and slightly non-planar polygons).
pub fn newell_normal(v: &[V3]) -> V3 {
    let mut n = [0.0; 3];
    for i in 0..v.len() {
        let (a, b) = (v[i], v[(i + 1) % v.len()]);
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    n
}

fn circle(out: &mut Vec<V3>, center: V3, axis: V3, r: f64) {
    if r == 0.0 {
        out.push(center);
        return;
    }
    let (t1, t2) = tangents(normalized(axis));
    for k in 0..CIRCLE {
        let a = std::f64::consts::TAU * k as f64 / CIRCLE as f64;
        out.push(add(
            center,
            add(scale(t1, r * a.cos()), scale(t2, r * a.sin())),
        ));
    }
}

/// Surface points and normal hints of a geometric primitive; `None` when the primitive has no
/// inline geometry (or degenerate axes).
pub fn sample(p: &Primitive) -> Option<Sampled> {
    let mut s = Sampled::default();
    match p {
        Primitive::Polygon { vertices } => {
            s.points = vertices.clone();
            s.normals.push(newell_normal(vertices));
        }
        Primitive::Sphere { center, radius, .. } => {
            // Fibonacci points: the most even cheap covering of the sphere.
            let r = radius.abs();
            let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
            for i in 0..SPHERE {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / SPHERE as f64;
                let rr = (1.0 - z * z).max(0.0).sqrt();
                let phi = golden * i as f64;
                s.points
                    .push(add(*center, scale([rr * phi.cos(), rr * phi.sin(), z], r)));
            }
            // The six axis extremes, so axis-aligned boxes of spheres are exact.
            for k in 0..3 {
                for sign in [-1.0, 1.0] {
                    let mut d = [0.0; 3];
                    d[k] = sign * r;
                    s.points.push(add(*center, d));
                }
            }
        }
        Primitive::Cylinder { p0, p1, radius, .. } => {
            let axis = sub(*p1, *p0);
            if dot(axis, axis) == 0.0 {
                return None;
            }
            circle(&mut s.points, *p0, axis, radius.abs());
            circle(&mut s.points, *p1, axis, radius.abs());
            s.normals.push(axis);
        }
        Primitive::Cone { p0, p1, r0, r1, .. } => {
            let axis = sub(*p1, *p0);
            if dot(axis, axis) == 0.0 {
                return None;
            }
            circle(&mut s.points, *p0, axis, r0.abs());
            circle(&mut s.points, *p1, axis, r1.abs());
            s.normals.push(axis);
        }
        Primitive::Ring {
            center, normal, r1, ..
        } => {
            if dot(*normal, *normal) == 0.0 {
                return None;
            }
            // The outer radius bounds the disc or annulus (r0 only cuts a hole).
            circle(&mut s.points, *center, *normal, r1.abs());
            s.normals.push(*normal);
        }
        _ => return None,
    }
    if s.points.iter().any(|p| p.iter().any(|x| !x.is_finite())) {
        return None;
    }
    Some(s)
}

/// A unit normal of a polygon, `None` for a degenerate one.
pub fn polygon_normal(v: &[V3]) -> Option<V3> {
    let n = newell_normal(v);
    (dot(n, n) > 1e-24).then(|| normalized(n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sphere_sample_reaches_its_radius_within_the_stated_bound() {
        let s = sample(&Primitive::Sphere {
            center: [1.0, 2.0, 3.0],
            radius: 0.5,
            inward: false,
        })
        .unwrap();
        for d in [
            [1.0, 0.0, 0.0],
            normalized([1.0, 1.0, 1.0]),
            [0.3, -0.2, 0.9],
        ] {
            let d = normalized(d);
            let reach = s
                .points
                .iter()
                .map(|&p| dot(sub(p, [1.0, 2.0, 3.0]), d))
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(
                (0.5 * (1.0 - 0.0015)..=0.5 + 1e-12).contains(&reach),
                "{reach}"
            );
        }
    }

    #[test]
    fn sources_and_instances_have_no_points() {
        assert!(
            sample(&Primitive::Source {
                direction: [0.0, 0.0, 1.0],
                angle: 0.5
            })
            .is_none()
        );
    }
}
