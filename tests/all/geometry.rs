//! Geometry: triangulation, exact shape intersections, and the scene BVH.
//!
//! Oracles: plane shoelace areas and point coverage for triangulation; an independent
//! root search on each surface's implicit equation for the analytic shapes; a brute-force
//! loop over `Shape::intersect` (polygons by Radiance's own even-odd test, not triangles) for
//! the BVH; the same room traced at the origin and 1e5 m away; real `rtrace -oLNs`.

use crate::common;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rdaylight::geometry::{
    Bvh, Object, PolygonError, Ray, Shape, ShapeError, Vec3, offset_distance, polygon_area,
    triangulate,
};

fn v(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

fn rng(seed: u64) -> Pcg64 {
    Pcg64::seed_from_u64(seed)
}

fn unit(r: &mut Pcg64) -> Vec3 {
    loop {
        let p = v(
            r.random_range(-1.0..1.0),
            r.random_range(-1.0..1.0),
            r.random_range(-1.0..1.0),
        );
        let l = p.length();
        if l > 0.1 && l <= 1.0 {
            return p / l;
        }
    }
}

fn in_box(r: &mut Pcg64, lo: f64, hi: f64) -> Vec3 {
    v(
        r.random_range(lo..hi),
        r.random_range(lo..hi),
        r.random_range(lo..hi),
    )
}

/// Right-handed basis (u, v) of the plane with unit normal n.
fn basis(n: Vec3) -> (Vec3, Vec3) {
    let h = if n.x.abs() < 0.6 {
        v(1., 0., 0.)
    } else {
        v(0., 1., 0.)
    };
    let u = h.cross(n).normalize();
    (u, n.cross(u))
}

// ---------------------------------------------------------------------------------------
// Triangulation
// ---------------------------------------------------------------------------------------

/// Signed shoelace area of the polygon projected on the plane (u, v).
fn shoelace(p: &[Vec3], u: Vec3, w: Vec3) -> f64 {
    let q: Vec<(f64, f64)> = p.iter().map(|&x| (x.dot(u), x.dot(w))).collect();
    let mut a = 0.0;
    for i in 0..q.len() {
        let (x0, y0) = q[i];
        let (x1, y1) = q[(i + 1) % q.len()];
        a += x0 * y1 - x1 * y0;
    }
    0.5 * a
}

/// Even-odd inside test in the plane (u, v).
fn inside_2d(p: &[Vec3], u: Vec3, w: Vec3, x: f64, y: f64) -> bool {
    let q: Vec<(f64, f64)> = p.iter().map(|&a| (a.dot(u), a.dot(w))).collect();
    let mut c = false;
    let mut j = q.len() - 1;
    for i in 0..q.len() {
        let ((xi, yi), (xj, yj)) = (q[i], q[j]);
        if (yi > y) != (yj > y) && x < xj + (y - yj) * (xi - xj) / (yi - yj) {
            c = !c;
        }
        j = i;
    }
    c
}

/// Check a triangulation: areas sum to the shoelace area, every triangle keeps the polygon's
/// orientation, and random points are covered once inside and never outside.
fn check_triangulation(p: &[Vec3], expected_area: Option<f64>, r: &mut Pcg64) {
    let tris = triangulate(p).unwrap();
    let n = rdaylight::geometry::triangulate::newell_normal(p);
    let nu = n.normalize();
    let (u, w) = basis(nu);
    let area = shoelace(p, u, w);
    assert!(
        area > 0.0,
        "projection basis must see the polygon counter-clockwise"
    );
    if let Some(e) = expected_area {
        assert!(
            (area - e).abs() <= 1e-9 * e,
            "shoelace {area} vs expected {e}"
        );
    }
    assert!((polygon_area(p) - area).abs() <= 1e-9 * area);
    let mut sum = 0.0;
    for &[a, b, c] in &tris {
        let tn = (p[b] - p[a]).cross(p[c] - p[a]);
        assert!(tn.dot(nu) > 0.0, "triangle {a} {b} {c} is flipped");
        sum += 0.5 * tn.length();
    }
    assert!(
        (sum - area).abs() <= 1e-9 * area,
        "triangle areas {sum} vs polygon {area} ({} triangles)",
        tris.len()
    );
    // Coverage: points away from edges are inside exactly as many triangles as the even-odd
    // rule says (0 or 1).
    let q: Vec<(f64, f64)> = p.iter().map(|&a| (a.dot(u), a.dot(w))).collect();
    let (x0, x1) = q
        .iter()
        .fold((f64::MAX, f64::MIN), |a, b| (a.0.min(b.0), a.1.max(b.0)));
    let (y0, y1) = q
        .iter()
        .fold((f64::MAX, f64::MIN), |a, b| (a.0.min(b.1), a.1.max(b.1)));
    for _ in 0..400 {
        let (x, y) = (r.random_range(x0..x1), r.random_range(y0..y1));
        let mut count = 0;
        let mut near_edge = false;
        for &[a, b, c] in &tris {
            let (pa, pb, pc) = (q[a], q[b], q[c]);
            let e = |s: (f64, f64), t: (f64, f64)| {
                ((t.0 - s.0) * (y - s.1) - (t.1 - s.1) * (x - s.0)) / ((t.0 - s.0).hypot(t.1 - s.1))
            };
            let (d0, d1, d2) = (e(pa, pb), e(pb, pc), e(pc, pa));
            let m = d0.abs().min(d1.abs()).min(d2.abs());
            if d0 > 0.0 && d1 > 0.0 && d2 > 0.0 {
                count += 1;
            }
            if m < 1e-9 {
                near_edge = true;
            }
        }
        if near_edge {
            continue;
        }
        let expect = inside_2d(p, u, w, x, y) as usize;
        assert_eq!(count, expect, "point ({x}, {y}) covered {count} times");
    }
}

/// Random star-shaped polygon with `n` vertices in a random plane.
fn star_polygon(r: &mut Pcg64, n: usize) -> Vec<Vec3> {
    let nrm = unit(r);
    let (u, w) = basis(nrm);
    let c = in_box(r, -5.0, 5.0);
    // One vertex per angular sector, so that the centre sees every edge: a simple polygon.
    let sector = std::f64::consts::TAU / n as f64;
    (0..n)
        .map(|k| {
            let a = (k as f64 + r.random_range(0.05..0.95)) * sector;
            let rad = r.random_range(0.2..2.0);
            c + u * (rad * a.cos()) + w * (rad * a.sin())
        })
        .collect()
}

#[test]
fn random_star_polygons_keep_area_and_orientation() {
    let mut r = rng(1);
    for i in 0..300 {
        let n = 3 + i % 40;
        let mut p = star_polygon(&mut r, n);
        if p.len() < 3 {
            continue;
        }
        if i % 2 == 1 {
            p.reverse(); // other orientation: triangles must follow it
        }
        check_triangulation(&p, None, &mut r);
    }
}

#[test]
fn random_combs_non_star_shaped() {
    // A comb: teeth of random height along x, a spine below; not star-shaped.
    let mut r = rng(2);
    for _ in 0..50 {
        let teeth = r.random_range(2..15);
        let spine = 0.5;
        let mut area = 0.0;
        // Build explicitly: bottom edge left to right, then teeth right to left on top.
        let mut xs = Vec::new();
        let mut cx = 0.0;
        for _ in 0..teeth {
            let w = r.random_range(0.1..1.0);
            let gap = r.random_range(0.1..1.0);
            let h = r.random_range(0.5..3.0);
            xs.push((cx, cx + w, h));
            area += w * h;
            cx += w + gap;
        }
        let end = xs.last().unwrap().1;
        area += end * spine;
        let mut p = vec![v(0., 0., 0.), v(end, 0., 0.)];
        for &(a, b, h) in xs.iter().rev() {
            p.push(v(b, spine, 0.));
            p.push(v(b, spine + h, 0.));
            p.push(v(a, spine + h, 0.));
            p.push(v(a, spine, 0.));
        }
        check_triangulation(&p, Some(area), &mut r);
    }
}

#[test]
fn l_shape_both_orientations() {
    let mut r = rng(3);
    let l = vec![
        v(0., 0., 0.),
        v(3., 0., 0.),
        v(3., 1., 0.),
        v(1., 1., 0.),
        v(1., 2., 0.),
        v(0., 2., 0.),
    ];
    check_triangulation(&l, Some(4.0), &mut r);
    let tris = triangulate(&l).unwrap();
    assert_eq!(tris.len(), 4);
    let mut rev = l.clone();
    rev.reverse();
    check_triangulation(&rev, Some(4.0), &mut r);
    // The same L standing as a wall far from the origin.
    let wall: Vec<Vec3> = l.iter().map(|p| v(1e5 + p.x, -1e5, 1e5 + p.y)).collect();
    check_triangulation(&wall, Some(4.0), &mut r);
}

/// A 6 m × 3 m wall (facing -y, as seen from outside) with a 2 m × 1.5 m window cut in by a
/// seam, vertex order as a Radiance modeller writes it.
fn window_wall() -> Vec<Vec3> {
    vec![
        // outer boundary, counter-clockwise seen from -y (front), x to the right, z up
        v(0., 0., 0.),
        v(6., 0., 0.),
        v(6., 0., 3.),
        v(0., 0., 3.),
        v(0., 0., 0.), // back at the start: seam to the hole's first corner
        v(2., 0., 0.8),
        // hole, clockwise seen from the front
        v(2., 0., 2.3),
        v(4., 0., 2.3),
        v(4., 0., 0.8),
        v(2., 0., 0.8), // close the hole, then back along the seam
    ]
}

#[test]
fn window_wall_with_seam_hole() {
    let mut r = rng(4);
    let p = window_wall();
    // Radiance orientation: CCW seen from -y means the normal is -y.
    let n = rdaylight::geometry::triangulate::newell_normal(&p).normalize();
    assert!((n - v(0., -1., 0.)).length() < 1e-12, "{n:?}");
    check_triangulation(&p, Some(18.0 - 3.0), &mut r);
    // Two windows, each joined by its own seam, on a tilted wall.
    let two = vec![
        v(0., 0., 0.),
        v(10., 0., 0.),
        v(10., 0., 3.),
        v(0., 0., 3.),
        v(0., 0., 0.),
        v(1., 0., 1.),
        v(1., 0., 2.),
        v(3., 0., 2.),
        v(3., 0., 1.),
        v(1., 0., 1.),
        v(0., 0., 0.),
        v(6., 0., 1.),
        v(6., 0., 2.5),
        v(9., 0., 2.5),
        v(9., 0., 1.),
        v(6., 0., 1.),
    ];
    let tilt = |p: &Vec3| v(p.x, p.y + 0.3 * p.z, p.z * 0.95);
    let two: Vec<Vec3> = two.iter().map(tilt).collect();
    check_triangulation(&two, None, &mut r);
    let a = shoelace(
        &[v(0., 0., 0.), v(10., 0., 0.), v(10., 0., 3.), v(0., 0., 3.)],
        v(1., 0., 0.),
        v(0., 0., 1.),
    );
    assert!((a - 30.0).abs() < 1e-12);
}

#[test]
fn duplicate_and_nearly_collinear_vertices() {
    let mut r = rng(5);
    let p = vec![
        v(0., 0., 0.),
        v(0., 0., 0.),    // exact duplicate
        v(1., 1e-14, 0.), // nearly on the bottom edge
        v(2., 0., 0.),
        v(2., 1., 0.),
        v(2., 1. + 1e-13, 0.), // near-duplicate
        v(1., 1., 0.),         // straight-through vertex on the top edge
        v(0., 1., 0.),
        v(0., 0., 0.), // last == first, as Radiance allows
    ];
    check_triangulation(&p, Some(2.0), &mut r);
    // A spike (the outline goes out and straight back) adds no area and no triangle.
    let spike = vec![
        v(0., 0., 0.),
        v(1., 0., 0.),
        v(1., 0.5, 0.),
        v(3., 0.5, 0.),
        v(1., 0.5, 0.),
        v(1., 1., 0.),
        v(0., 1., 0.),
    ];
    check_triangulation(&spike, Some(1.0), &mut r);
}

#[test]
fn degenerate_polygons_are_errors_with_location() {
    let collinear = [v(0., 0., 0.), v(1., 0., 0.), v(2., 0., 0.), v(5., 0., 0.)];
    let e = triangulate(&collinear).unwrap_err();
    assert!(matches!(e, PolygonError::ZeroArea { .. }), "{e:?}");
    let msg = e.at(rdaylight::Location::line("walls.rad", 7)).to_string();
    assert!(
        msg.starts_with("walls.rad:7: polygon has zero area"),
        "{msg}"
    );
    let same = [v(1., 1., 1.); 4];
    assert!(matches!(
        triangulate(&same),
        Err(PolygonError::ZeroArea { .. })
    ));
    let nan = [v(0., 0., 0.), v(1., f64::NAN, 0.), v(0., 1., 0.)];
    assert_eq!(triangulate(&nan), Err(PolygonError::NonFinite(1)));
    // A bow-tie has zero net area: degenerate for Radiance too.
    let bow = [v(0., 0., 0.), v(1., 1., 0.), v(1., 0., 0.), v(0., 1., 0.)];
    assert!(triangulate(&bow).is_err());
    // Through the BVH build, the failing object's index and id come back.
    let objs = vec![
        Object {
            shape: Shape::Sphere {
                centre: [0.; 3],
                radius: 1.0,
                inward: false,
            },
            id: 10,
        },
        Object {
            shape: Shape::Polygon {
                vertices: collinear.iter().map(|p| p.to_array()).collect(),
            },
            id: 11,
        },
    ];
    let e = Bvh::build(&objs).err().unwrap();
    assert_eq!((e.index, e.id), (1, 11));
    let msg = e.at(rdaylight::Location::line("walls.rad", 9)).to_string();
    assert!(
        msg.starts_with("walls.rad:9: polygon has zero area"),
        "{msg}"
    );
    assert!(matches!(
        e.error,
        ShapeError::Polygon(PolygonError::ZeroArea { .. })
    ));
}

#[test]
fn illegal_shape_arguments() {
    let bad = [
        Shape::Sphere {
            centre: [0.; 3],
            radius: 0.0,
            inward: false,
        },
        Shape::Cone {
            p0: [0.; 3],
            p1: [0., 0., 1.],
            r0: 0.0,
            r1: 0.0,
            inward: false,
        },
        Shape::Cylinder {
            p0: [1.; 3],
            p1: [1.; 3],
            r: 1.0,
            inward: true,
        },
        Shape::Ring {
            centre: [0.; 3],
            normal: [0., 0., 1.],
            r_in: 1.0,
            r_out: 1.0,
        },
        Shape::Ring {
            centre: [0.; 3],
            normal: [0., 0., 0.],
            r_in: 0.0,
            r_out: 1.0,
        },
    ];
    for s in &bad {
        let e = s.validate().unwrap_err();
        let msg = e.at(rdaylight::Location::line("f.rad", 3)).to_string();
        assert!(msg.starts_with("f.rad:3: "), "{msg}");
        assert!(msg.contains("expected"), "{msg}");
    }
}

// ---------------------------------------------------------------------------------------
// Analytic shapes
// ---------------------------------------------------------------------------------------

fn hit_of(shape: &Shape, org: Vec3, dir: Vec3) -> Option<rdaylight::geometry::Hit> {
    let bvh = Bvh::build(&[Object {
        shape: shape.clone(),
        id: 1,
    }])
    .unwrap();
    bvh.intersect(&Ray::new(org, dir), 0.0, f64::INFINITY)
}

#[test]
fn sphere_and_bubble_analytic() {
    let s = Shape::Sphere {
        centre: [1., 2., 3.],
        radius: 0.5,
        inward: false,
    };
    let h = hit_of(&s, v(1., 2., 10.), v(0., 0., -1.)).unwrap();
    assert!((h.t - 6.5).abs() < 1e-12 && h.front);
    assert!((h.normal - v(0., 0., 1.)).length() < 1e-12);
    // From inside: the far side, seen from its back.
    let h = hit_of(&s, v(1., 2., 3.), v(0., 0., -1.)).unwrap();
    assert!((h.t - 0.5).abs() < 1e-12 && !h.front);
    let b = Shape::Sphere {
        centre: [1., 2., 3.],
        radius: 0.5,
        inward: true,
    };
    let h = hit_of(&b, v(1., 2., 3.), v(0., 0., -1.)).unwrap();
    assert!((h.normal - v(0., 0., 1.)).length() < 1e-12 && h.front);
    assert!(hit_of(&s, v(1., 2.6, 10.), v(0., 0., -1.)).is_none());
    // A 1 mm sphere 1 km away keeps its precision.
    let tiny = Shape::Sphere {
        centre: [1000., 0., 0.],
        radius: 1e-3,
        inward: false,
    };
    let h = hit_of(&tiny, v(0., 0., 0.), v(1., 0., 0.)).unwrap();
    assert!((h.t - (1000. - 1e-3)).abs() < 1e-10, "{}", h.t);
}

#[test]
fn cone_cylinder_ring_analytic() {
    // Cone along z from r=1 at z=0 to apex r=0 at z=2: side at 45°·atan(1/2).
    let c = Shape::Cone {
        p0: [0., 0., 0.],
        p1: [0., 0., 2.],
        r0: 1.0,
        r1: 0.0,
        inward: false,
    };
    // Horizontal ray at z=1 meets radius 0.5.
    let h = hit_of(&c, v(5., 0., 1.), v(-1., 0., 0.)).unwrap();
    assert!((h.t - 4.5).abs() < 1e-12);
    let expect = v(2., 0., 1.).normalize(); // outward, tilted up by the slope 1/2
    assert!((h.normal - expect).length() < 1e-12, "{:?}", h.normal);
    assert!(h.front);
    // Open: a ray down the axis passes through the (absent) base and hits nothing but the apex
    // region from inside; from below it enters the open base and hits the inside near the apex.
    let h = hit_of(&c, v(0.3, 0., -5.), v(0., 0., 1.)).unwrap();
    assert!((h.t - (5.0 + 1.4)).abs() < 1e-12, "{}", h.t); // r(z) = 1 - z/2 = 0.3 at z = 1.4
    assert!(!h.front);
    // Beyond the apex the mirror nappe does not exist.
    assert!(hit_of(&c, v(5., 0., 3.), v(-1., 0., 0.)).is_none());
    // Cup: same surface, inward normal.
    let cup = Shape::Cone {
        p0: [0., 0., 2.],
        p1: [0., 0., 0.],
        r0: 0.0,
        r1: 1.0,
        inward: true,
    };
    let h = hit_of(&cup, v(5., 0., 1.), v(-1., 0., 0.)).unwrap();
    assert!((h.normal + expect).length() < 1e-12 && !h.front);
    // Truncated cone r 1 → 2 over z 0..1; ray at z=0.5 from outside hits r=1.5.
    let t = Shape::Cone {
        p0: [0., 0., 0.],
        p1: [0., 0., 1.],
        r0: 1.0,
        r1: 2.0,
        inward: false,
    };
    let h = hit_of(&t, v(0., -5., 0.5), v(0., 1., 0.)).unwrap();
    assert!((h.t - 3.5).abs() < 1e-12);
    assert!((h.normal - v(0., -1., -1.).normalize()).length() < 1e-12);
    // Cylinder and tube.
    let cyl = Shape::Cylinder {
        p0: [0., 0., 0.],
        p1: [0., 3., 0.],
        r: 0.25,
        inward: false,
    };
    let h = hit_of(&cyl, v(0., 1., 4.), v(0., 0., -1.)).unwrap();
    assert!((h.t - 3.75).abs() < 1e-12 && h.front);
    assert!((h.normal - v(0., 0., 1.)).length() < 1e-12);
    assert!(hit_of(&cyl, v(0., 3.1, 4.), v(0., 0., -1.)).is_none()); // past p1
    let tube = Shape::Cylinder {
        p0: [0., 0., 0.],
        p1: [0., 3., 0.],
        r: 0.25,
        inward: true,
    };
    let h = hit_of(&tube, v(0., 1., 0.), v(0., 0., -1.)).unwrap();
    assert!((h.t - 0.25).abs() < 1e-12 && h.front);
    // Ring: disc r 0.5..1 at z=1 facing +z.
    let ring = Shape::Ring {
        centre: [0., 0., 1.],
        normal: [0., 0., 2.],
        r_in: 1.0,
        r_out: 0.5, // either order
    };
    let h = hit_of(&ring, v(0.75, 0., 3.), v(0., 0., -1.)).unwrap();
    assert!((h.t - 2.0).abs() < 1e-12 && h.front && h.normal == v(0., 0., 1.));
    assert!(hit_of(&ring, v(0.25, 0., 3.), v(0., 0., -1.)).is_none());
    assert!(hit_of(&ring, v(1.25, 0., 3.), v(0., 0., -1.)).is_none());
    let h = hit_of(&ring, v(0.75, 0., -3.), v(0., 0., 1.)).unwrap();
    assert!(!h.front);
}

/// Implicit description of an analytic shape for the brute-force root search: signed
/// function value and whether the point is within the shape's extent.
fn implicit(shape: &Shape, p: Vec3) -> (f64, bool) {
    match *shape {
        Shape::Sphere { centre, radius, .. } => ((p - centre.into()).length() - radius, true),
        Shape::Cone { p0, p1, r0, r1, .. } => cone_implicit(p, p0.into(), p1.into(), r0, r1),
        Shape::Cylinder { p0, p1, r, .. } => cone_implicit(p, p0.into(), p1.into(), r, r),
        Shape::Ring {
            centre,
            normal,
            r_in,
            r_out,
        } => {
            let n = Vec3::from(normal).normalize();
            let q = p - centre.into();
            let h = q.dot(n);
            let rr = (q - n * h).length();
            let (a, b) = (r_in.min(r_out), r_in.max(r_out));
            (h, rr >= a && rr <= b)
        }
        Shape::Polygon { .. } => unreachable!(),
    }
}

fn cone_implicit(p: Vec3, p0: Vec3, p1: Vec3, r0: f64, r1: f64) -> (f64, bool) {
    let len = (p1 - p0).length();
    let a = (p1 - p0) / len;
    let q = p - p0;
    let h = q.dot(a);
    let rad = (q - a * h).length();
    let rr = r0 + (r1 - r0) * h / len;
    (rad - rr, (0.0..=len).contains(&h))
}

/// First root of the implicit function along the ray, by stepping and bisection.
fn brute_root(shape: &Shape, ray: &Ray, tmax: f64, steps: usize) -> Option<f64> {
    let f = |t: f64| implicit(shape, ray.at(t));
    let dt = tmax / steps as f64;
    let mut t0 = 1e-9;
    let (mut f0, _) = f(t0);
    for i in 1..=steps {
        let t1 = i as f64 * dt;
        let (f1, _) = f(t1);
        if (f0 > 0.0) != (f1 > 0.0) {
            let (mut a, mut b, mut fa) = (t0, t1, f0);
            for _ in 0..100 {
                let m = 0.5 * (a + b);
                let (fm, _) = f(m);
                if (fa > 0.0) == (fm > 0.0) {
                    a = m;
                    fa = fm;
                } else {
                    b = m;
                }
            }
            let t = 0.5 * (a + b);
            if f(t).1 {
                return Some(t);
            }
        }
        t0 = t1;
        f0 = f1;
    }
    None
}

fn random_analytic(r: &mut Pcg64, kind: usize, c: Vec3) -> Shape {
    let inward = r.random_bool(0.5);
    match kind {
        0 => Shape::Sphere {
            centre: c.to_array(),
            radius: r.random_range(0.1..1.5),
            inward,
        },
        1 => {
            // Truncated cone, sometimes with an apex (r = 0) at either end.
            let a = c + unit(r) * r.random_range(0.3..1.5);
            let b = c - unit(r) * r.random_range(0.3..1.5);
            let (r0, r1) = match r.random_range(0..3) {
                0 => (0.0, r.random_range(0.1..1.0)),
                1 => (r.random_range(0.1..1.0), 0.0),
                _ => (r.random_range(0.1..1.0), r.random_range(0.1..1.0)),
            };
            Shape::Cone {
                p0: a.to_array(),
                p1: b.to_array(),
                r0,
                r1,
                inward,
            }
        }
        2 => {
            let a = c + unit(r) * r.random_range(0.3..1.5);
            let b = c - unit(r) * r.random_range(0.3..1.5);
            Shape::Cylinder {
                p0: a.to_array(),
                p1: b.to_array(),
                r: r.random_range(0.05..1.0),
                inward,
            }
        }
        _ => Shape::Ring {
            centre: c.to_array(),
            normal: (unit(r) * r.random_range(0.5..3.0)).to_array(),
            r_in: if r.random_bool(0.3) {
                0.0
            } else {
                r.random_range(0.0..0.5)
            },
            r_out: r.random_range(0.6..1.5),
        },
    }
}

/// Expected front normal from the implicit description: gradient direction, flipped for
/// inward shapes.
fn expected_normal(shape: &Shape, p: Vec3) -> Vec3 {
    let e = 1e-6;
    let g = v(
        implicit(shape, p + v(e, 0., 0.)).0 - implicit(shape, p - v(e, 0., 0.)).0,
        implicit(shape, p + v(0., e, 0.)).0 - implicit(shape, p - v(0., e, 0.)).0,
        implicit(shape, p + v(0., 0., e)).0 - implicit(shape, p - v(0., 0., e)).0,
    )
    .normalize();
    let inward = matches!(
        shape,
        Shape::Sphere { inward: true, .. }
            | Shape::Cone { inward: true, .. }
            | Shape::Cylinder { inward: true, .. }
    );
    if inward { -g } else { g }
}

#[test]
fn random_rays_on_analytic_shapes_match_root_search() {
    let mut r = rng(6);
    let mut compared = 0;
    let mut grazing_misses = 0;
    for kind in 0..4 {
        for _ in 0..60 {
            let c = in_box(&mut r, -2.0, 2.0);
            let shape = random_analytic(&mut r, kind, c);
            let bvh = Bvh::build(&[Object {
                shape: shape.clone(),
                id: 3,
            }])
            .unwrap();
            for k in 0..50 {
                let org = c + unit(&mut r) * r.random_range(0.0..4.0);
                // Half the rays aim near the shape's centre, half go anywhere.
                let dir = if k % 2 == 0 {
                    (c + unit(&mut r) * r.random_range(0.0..1.2) - org).normalize()
                } else {
                    unit(&mut r)
                };
                let ray = Ray::new(org, dir);
                let ours = bvh.intersect(&ray, 0.0, 20.0);
                let refer = shape.intersect(&ray, 0.0, 20.0);
                // Recentred (BVH) and world-space (reference) arithmetic agree to rounding.
                assert_eq!(ours.is_some(), refer.is_some(), "BVH vs Shape::intersect");
                if let (Some(a), Some(b)) = (ours, refer) {
                    assert!(
                        (a.t - b.0).abs() <= 1e-12 * (1.0 + a.t),
                        "{} vs {}",
                        a.t,
                        b.0
                    );
                }
                let brute = brute_root(&shape, &ray, 20.0, 4000);
                compared += 1;
                match (ours, brute) {
                    (Some(h), Some(t)) => {
                        assert!((h.t - t).abs() < 1e-7, "{shape:?} {ray:?}: {} vs {t}", h.t);
                        assert!(implicit(&shape, h.point).0.abs() < 1e-9);
                        assert!((h.normal.length() - 1.0).abs() < 1e-12);
                        let en = expected_normal(&shape, h.point);
                        assert!(
                            (h.normal - en).length() < 1e-4,
                            "{shape:?}: normal {:?} vs {en:?}",
                            h.normal
                        );
                        assert_eq!(h.front, ray.dir.dot(h.normal) < 0.0);
                        assert_eq!(h.object, 3);
                    }
                    (None, None) => {}
                    (Some(h), None) => {
                        // A tangent pair of roots inside one step of the search: ours must
                        // still be on the surface.
                        assert!(
                            implicit(&shape, h.point).0.abs() < 1e-9,
                            "{shape:?} {ray:?}"
                        );
                        grazing_misses += 1;
                    }
                    (None, Some(t)) => panic!("{shape:?} {ray:?}: missed the root at {t}"),
                }
            }
        }
    }
    assert!(
        grazing_misses * 500 < compared,
        "{grazing_misses} of {compared} rays disagreed with the root search"
    );
}

// ---------------------------------------------------------------------------------------
// BVH
// ---------------------------------------------------------------------------------------

/// A random scene in a 10 m cube with every shape type (non-convex and holed polygons too).
fn random_scene(r: &mut Pcg64, offset: Vec3) -> Vec<Object> {
    let mut objs = Vec::new();
    let mut id = 100;
    let mut push = |shape: Shape, objs: &mut Vec<Object>| {
        objs.push(Object { shape, id });
        id += 1;
    };
    for i in 0..400 {
        let p = star_polygon(r, 3 + i % 12);
        if p.len() >= 3 {
            push(
                Shape::Polygon {
                    vertices: p.iter().map(|&q| (q + offset).to_array()).collect(),
                },
                &mut objs,
            );
        }
    }
    for k in 0..3 {
        let c = in_box(r, -5.0, 5.0);
        let wall: Vec<Vec3> = window_wall()
            .iter()
            .map(|p| {
                let q = *p - v(3., 0., 1.5);
                match k {
                    0 => c + q,
                    1 => c + v(q.z, q.x, q.y),
                    _ => c + v(q.y, q.z, q.x),
                }
            })
            .collect();
        push(
            Shape::Polygon {
                vertices: wall.iter().map(|&q| (q + offset).to_array()).collect(),
            },
            &mut objs,
        );
    }
    for kind in 0..4 {
        for _ in 0..60 {
            let c = in_box(r, -5.0, 5.0) + offset;
            push(random_analytic(r, kind, c), &mut objs);
        }
    }
    objs
}

fn oracle(objs: &[Object], ray: &Ray, tmin: f64, tmax: f64) -> Option<(f64, u32, Vec3)> {
    let mut best: Option<(f64, u32, Vec3)> = None;
    for o in objs {
        let lim = best.map_or(tmax, |b| b.0);
        if let Some((t, n)) = o.shape.intersect(ray, tmin, lim) {
            best = Some((t, o.id, n));
        }
    }
    best
}

fn random_ray(r: &mut Pcg64, offset: Vec3) -> Ray {
    // Most origins inside the scene, some far outside looking in.
    let org = if r.random_bool(0.8) {
        in_box(r, -6.0, 6.0)
    } else {
        unit(r) * 50.0
    };
    let dir = if r.random_bool(0.8) {
        unit(r)
    } else {
        (in_box(r, -3.0, 3.0) - org).normalize()
    };
    Ray::new(org + offset, dir)
}

#[test]
fn bvh_matches_brute_force_oracle_on_10000_rays() {
    let mut r = rng(7);
    let objs = random_scene(&mut r, Vec3::ZERO);
    let bvh = Bvh::build(&objs).unwrap();
    assert!(bvh.primitive_count() > 1500);
    let (mut hits, mut ties) = (0, 0);
    for _ in 0..10_000 {
        let ray = random_ray(&mut r, Vec3::ZERO);
        let ours = bvh.intersect(&ray, 0.0, f64::INFINITY);
        // Same primitives without the BVH: bit-identical.
        assert_eq!(ours, bvh.intersect_brute_force(&ray, 0.0, f64::INFINITY));
        let want = oracle(&objs, &ray, 0.0, f64::INFINITY);
        match (ours, want) {
            (None, None) => {}
            (Some(h), Some((t, id, n))) => {
                hits += 1;
                assert!((h.t - t).abs() < 1e-5, "t {} vs {t} for {ray:?}", h.t);
                if h.object != id {
                    // Only acceptable when two surfaces meet at that point.
                    assert!((h.t - t).abs() < 1e-9, "object {} vs {id}", h.object);
                    ties += 1;
                    continue;
                }
                assert!((h.normal - n).length() < 1e-9, "{:?} vs {n:?}", h.normal);
                assert!((h.point - ray.at(t)).length() < 1e-5);
            }
            (a, b) => panic!("{ray:?}: ours {a:?}, oracle {b:?}"),
        }
    }
    assert!(
        hits > 5000,
        "only {hits} hits: the test scene is too sparse"
    );
    assert!(ties < 5, "{ties} ties");
}

#[test]
fn occluded_agrees_with_intersect() {
    let mut r = rng(8);
    let objs = random_scene(&mut r, Vec3::ZERO);
    let bvh = Bvh::build(&objs).unwrap();
    let mut both = [0usize; 2];
    for _ in 0..5000 {
        let ray = random_ray(&mut r, Vec3::ZERO);
        let tmax = r.random_range(0.0..8.0);
        let blocked = bvh.occluded(&ray, tmax);
        assert_eq!(
            blocked,
            bvh.intersect(&ray, 0.0, tmax).is_some(),
            "{ray:?} {tmax}"
        );
        both[blocked as usize] += 1;
    }
    assert!(both[0] > 500 && both[1] > 500, "{both:?}");
}

#[test]
fn far_from_origin_gives_the_same_hits() {
    // The same random room traced at the origin and 1e5 m away (scene size 10 m): same objects,
    // t within 1e-6 × room size.
    let offset = v(1e5, -1e5, 1e5);
    let near = random_scene(&mut rng(9), Vec3::ZERO);
    let far = random_scene(&mut rng(9), offset);
    let (bn, bf) = (Bvh::build(&near).unwrap(), Bvh::build(&far).unwrap());
    let mut r = rng(10);
    let mut hits = 0;
    let mut worst: f64 = 0.0;
    for _ in 0..10_000 {
        let ray = random_ray(&mut r, Vec3::ZERO);
        let rf = Ray {
            org: ray.org + offset,
            dir: ray.dir,
        };
        let (a, b) = (
            bn.intersect(&ray, 0.0, f64::INFINITY),
            bf.intersect(&rf, 0.0, f64::INFINITY),
        );
        assert_eq!(a.is_some(), b.is_some(), "{ray:?}");
        if let (Some(a), Some(b)) = (a, b) {
            hits += 1;
            assert_eq!(a.object, b.object);
            assert_eq!(a.front, b.front);
            worst = worst.max((a.t - b.t).abs());
            assert!(((b.point - offset) - a.point).length() < 1e-5);
            assert!((a.normal - b.normal).length() < 1e-9);
        }
    }
    assert!(worst < 1e-5, "worst t difference {worst}");
    assert!(hits > 5000);
    eprintln!("far-from-origin: {hits} hits, worst |Δt| = {worst:e} m");
}

#[test]
fn empty_scene() {
    let bvh = Bvh::build(&[]).unwrap();
    let ray = Ray::new(v(0., 0., 0.), v(0., 0., 1.));
    assert_eq!(bvh.intersect(&ray, 0.0, f64::INFINITY), None);
    assert!(!bvh.occluded(&ray, f64::INFINITY));
    assert_eq!(bvh.primitive_count(), 0);
}

#[test]
fn zero_or_nan_direction_hits_nothing() {
    let bvh = Bvh::build(&[Object {
        shape: Shape::Sphere {
            centre: [0.; 3],
            radius: 1.0,
            inward: false,
        },
        id: 1,
    }])
    .unwrap();
    for dir in [Vec3::ZERO, v(f64::NAN, 0., 1.)] {
        let ray = Ray::new(v(0., 0., 0.), dir);
        assert_eq!(bvh.intersect(&ray, 0.0, f64::INFINITY), None);
        assert!(!bvh.occluded(&ray, f64::INFINITY));
    }
}

#[test]
fn secondary_rays_do_not_hit_their_own_surface() {
    for offset in [Vec3::ZERO, v(1e5, 1e5, -1e5)] {
        let mut r = rng(11);
        let objs = random_scene(&mut r, offset);
        let bvh = Bvh::build(&objs).unwrap();
        let mut spawned = 0;
        for _ in 0..3000 {
            let ray = random_ray(&mut r, offset);
            let Some(h) = bvh.intersect(&ray, 0.0, f64::INFINITY) else {
                continue;
            };
            // Reflection and transmission-like directions, including near-grazing ones.
            for side in [1.0, -1.0] {
                let mut d = unit(&mut r);
                if d.dot(h.normal) * side < 0.0 {
                    d = -d;
                }
                if r.random_bool(0.2) {
                    // grazing: tilt almost into the tangent plane
                    d = (d - h.normal * d.dot(h.normal) * 0.999).normalize();
                }
                let s = h.spawn(d);
                assert!((s.org - h.point).length() <= 2.0 * offset_distance(h.point));
                spawned += 1;
                if let Some(h2) = bvh.intersect(&s, 0.0, f64::INFINITY) {
                    assert!(
                        h2.t > 1e-6 || h2.object != h.object,
                        "self-hit at t={} on object {} (offset {offset:?})",
                        h2.t,
                        h.object
                    );
                }
            }
        }
        assert!(spawned > 2000);
    }
    // Convex sphere: a ray leaving outward never comes back to it.
    let bvh = Bvh::build(&[Object {
        shape: Shape::Sphere {
            centre: [1e5, 2e5, 3.0],
            radius: 0.3,
            inward: false,
        },
        id: 0,
    }])
    .unwrap();
    let mut r = rng(12);
    for _ in 0..2000 {
        let org = v(1e5, 2e5, 3.0) + unit(&mut r) * 5.0;
        let dir = (v(1e5, 2e5, 3.0) + unit(&mut r) * 0.25 - org).normalize();
        let h = bvh
            .intersect(&Ray::new(org, dir), 0.0, f64::INFINITY)
            .unwrap();
        let d = h.normal * 0.01 + unit(&mut r);
        let d = if d.dot(h.normal) < 0.0 { -d } else { d };
        assert!(!bvh.occluded(&h.spawn(d), f64::INFINITY));
    }
}

/// Random triangles in a 100 m cube as polygons.
fn triangle_soup(n: usize, seed: u64) -> Vec<Object> {
    let mut r = rng(seed);
    (0..n)
        .map(|i| {
            let c = in_box(&mut r, -50.0, 50.0);
            let vs = (0..3)
                .map(|_| (c + unit(&mut r) * r.random_range(0.05..0.5)).to_array())
                .collect();
            Object {
                shape: Shape::Polygon { vertices: vs },
                id: i as u32,
            }
        })
        .collect()
}

#[test]
#[ignore = "slow: builds a 1,000,000-triangle BVH and prints the time"]
fn million_triangle_build() {
    let objs = triangle_soup(1_000_000, 13);
    let t = std::time::Instant::now();
    let bvh = Bvh::build(&objs).unwrap();
    eprintln!(
        "1M triangles: build {:.2} s ({} primitives)",
        t.elapsed().as_secs_f64(),
        bvh.primitive_count()
    );
    assert_eq!(bvh.primitive_count(), 1_000_000);
    let mut r = rng(14);
    for _ in 0..200 {
        let ray = Ray::new(in_box(&mut r, -50., 50.), unit(&mut r));
        assert_eq!(
            bvh.intersect(&ray, 0.0, f64::INFINITY),
            bvh.intersect_brute_force(&ray, 0.0, f64::INFINITY)
        );
    }
}

/// Regression: obvhs drops BVH nodes whose exit distance is below 1e-4, which once lost every
/// surface closer than 0.1 mm to a ray's origin.
#[test]
fn surfaces_closer_than_obvhs_epsilon_are_found() {
    let floor = Shape::Polygon {
        vertices: vec![[0., 0., 0.], [4., 0., 0.], [4., 3., 0.], [0., 3., 0.]],
    };
    let wall = Shape::Polygon {
        vertices: vec![[4., 0., 0.], [4., 0., 2.5], [4., 3., 2.5], [4., 3., 0.]],
    };
    let ring = Shape::Ring {
        centre: [2., 1.5, 1.],
        normal: [0., 0., 1.],
        r_in: 0.,
        r_out: 0.3,
    };
    let objs = [
        Object {
            shape: floor,
            id: 1,
        },
        Object { shape: wall, id: 2 },
        Object { shape: ring, id: 3 },
    ];
    for offset in [Vec3::ZERO, v(1e5, 1e5, 1e5)] {
        let objs: Vec<Object> = objs
            .iter()
            .map(|o| {
                let mut o = o.clone();
                match &mut o.shape {
                    Shape::Polygon { vertices } => {
                        for p in vertices {
                            *p = (Vec3::from(*p) + offset).to_array();
                        }
                    }
                    Shape::Ring { centre, .. } => {
                        *centre = (Vec3::from(*centre) + offset).to_array()
                    }
                    _ => unreachable!(),
                }
                o
            })
            .collect();
        let bvh = Bvh::build(&objs).unwrap();
        for d in [1e-3, 1e-4, 1e-5, 1e-6, 1e-7] {
            // Down onto the floor, onto the wall, and onto the flat ring from just above.
            let cases = [
                (v(1., 1., d), v(0., 0., -1.), 1),
                (v(4. - d, 1., 1.), v(1., 0., 0.), 2),
                (v(2., 1.5, 1. + d), v(0., 0., -1.), 3),
            ];
            for (org, dir, id) in cases {
                let ray = Ray::new(org + offset, dir);
                let h = bvh.intersect(&ray, 0.0, f64::INFINITY);
                let h =
                    h.unwrap_or_else(|| panic!("missed object {id} at {d} (offset {offset:?})"));
                assert_eq!(h.object, id);
                assert!((h.t - d).abs() < 1e-9, "{} vs {d}", h.t);
                assert!(bvh.occluded(&ray, 2.0 * d));
                assert!(!bvh.occluded(&ray, 0.5 * d));
            }
        }
    }
}

/// The scene as Radiance scene text: one `plastic` modifier, surfaces named `s<id>`.
fn to_rad(objs: &[Object]) -> String {
    use std::fmt::Write;
    let mut s = String::from("void plastic m 0 0 5 .5 .5 .5 0 0\n");
    let f = |a: &[f64]| {
        a.iter()
            .map(|x| format!("{x:e}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    for o in objs {
        let (kind, args): (&str, Vec<f64>) = match &o.shape {
            Shape::Polygon { vertices } => ("polygon", vertices.concat()),
            Shape::Sphere {
                centre,
                radius,
                inward,
            } => (
                if *inward { "bubble" } else { "sphere" },
                [&centre[..], &[*radius]].concat(),
            ),
            Shape::Cone {
                p0,
                p1,
                r0,
                r1,
                inward,
            } => (
                if *inward { "cup" } else { "cone" },
                [&p0[..], &p1[..], &[*r0, *r1]].concat(),
            ),
            Shape::Cylinder { p0, p1, r, inward } => (
                if *inward { "tube" } else { "cylinder" },
                [&p0[..], &p1[..], &[*r]].concat(),
            ),
            Shape::Ring {
                centre,
                normal,
                r_in,
                r_out,
            } => (
                "ring",
                [&centre[..], &normal[..], &[*r_in, *r_out]].concat(),
            ),
        };
        writeln!(s, "m {kind} s{}\n0\n0\n{} {}", o.id, args.len(), f(&args)).unwrap();
    }
    s
}

#[test]
fn agrees_with_rtrace_distance_normal_and_surface() {
    if !common::have_radiance("agrees_with_rtrace_distance_normal_and_surface") {
        return;
    }
    let mut r = rng(15);
    let objs = random_scene(&mut r, Vec3::ZERO);
    let bvh = Bvh::build(&objs).unwrap();
    let dir = common::tmpdir();
    let rad = dir.path().join("scene.rad");
    std::fs::write(&rad, to_rad(&objs)).unwrap();
    let oct = common::run_ok(common::radiance("oconv").arg(&rad), b"");
    let octf = dir.path().join("scene.oct");
    std::fs::write(&octf, oct).unwrap();
    let rays: Vec<Ray> = (0..3000).map(|_| random_ray(&mut r, Vec3::ZERO)).collect();
    let input: String = rays
        .iter()
        .map(|q| {
            format!(
                "{:e} {:e} {:e} {:e} {:e} {:e}\n",
                q.org.x, q.org.y, q.org.z, q.dir.x, q.dir.y, q.dir.z
            )
        })
        .collect();
    let out = common::run_ok(
        common::radiance("rtrace")
            .args(["-h", "-ab", "0", "-oLNs"])
            .arg(&octf),
        input.as_bytes(),
    );
    let out = String::from_utf8(out).unwrap();
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), rays.len());
    let (mut hits, mut worst_t, mut worst_n) = (0, 0.0f64, 0.0f64);
    for (ray, line) in rays.iter().zip(&lines) {
        let w: Vec<&str> = line.split('\t').filter(|s| !s.is_empty()).collect();
        assert_eq!(w.len(), 5, "{line}");
        let num = |i: usize| w[i].parse::<f64>().unwrap();
        let ours = bvh.intersect(ray, 1e-6, f64::INFINITY); // Radiance ignores t <= FTINY
        if w[4] == "*" {
            assert!(ours.is_none(), "rtrace missed, we hit {ours:?} for {ray:?}");
            continue;
        }
        let h =
            ours.unwrap_or_else(|| panic!("rtrace hit {} at {}, we missed {ray:?}", w[4], w[0]));
        hits += 1;
        assert_eq!(format!("s{}", h.object), w[4], "{ray:?}");
        // rtrace prints 7 significant digits (%e).
        let t = num(0);
        worst_t = worst_t.max((h.t - t).abs() / t.max(1.0));
        assert!((h.t - t).abs() <= 2e-6 * t.max(1.0), "t {} vs {t}", h.t);
        let n = v(num(1), num(2), num(3));
        worst_n = worst_n.max((h.normal - n).length());
        assert!(
            (h.normal - n).length() < 1e-5,
            "normal {:?} vs {n:?}",
            h.normal
        );
    }
    assert!(hits > 1500, "{hits}");
    eprintln!("rtrace: {hits} hits agree; worst relative t {worst_t:e}, normal {worst_n:e}");
}
