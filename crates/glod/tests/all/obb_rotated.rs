//! The OBB against the truth: boxes and rectangles of known size under random rotations
//! (fixed seeds), with and without face-normal hints; the area must be within 0.5 % of
//! `2 (ab + bc + ca)` (the brief's tolerance; the hinted case is exact to rounding).

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rdaylight_base::vec3::{V3, add, cross, dot, normalized, scale};
use rdaylight_glod::obb::min_area_obb;

/// A uniformly random rotation (random unit quaternion, Shoemake 1992) as three columns.
fn rotation(rng: &mut Pcg64) -> [V3; 3] {
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let tau = std::f64::consts::TAU;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let q = [
        a * (tau * u2).sin(),
        a * (tau * u2).cos(),
        b * (tau * u3).sin(),
        b * (tau * u3).cos(),
    ];
    let [x, y, z, w] = q;
    let c0 = [
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y + z * w),
        2.0 * (x * z - y * w),
    ];
    let c1 = [
        2.0 * (x * y - z * w),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z + x * w),
    ];
    [normalized(c0), normalized(c1), normalized(cross(c0, c1))]
}

fn apply(r: &[V3; 3], p: V3, t: V3) -> V3 {
    add(
        add(add(scale(r[0], p[0]), scale(r[1], p[1])), scale(r[2], p[2])),
        t,
    )
}

/// Corners (and face normals) of a box of sides `s` rotated by `r` and moved to `t`.
fn rotated_box(s: V3, r: &[V3; 3], t: V3) -> (Vec<V3>, Vec<V3>) {
    let mut pts = Vec::new();
    for i in 0..8 {
        let p = [
            if i & 1 == 0 { 0.0 } else { s[0] },
            if i & 2 == 0 { 0.0 } else { s[1] },
            if i & 4 == 0 { 0.0 } else { s[2] },
        ];
        pts.push(apply(r, p, t));
    }
    (pts, r.to_vec())
}

fn truth(s: V3) -> f64 {
    2.0 * (s[0] * s[1] + s[1] * s[2] + s[2] * s[0])
}

#[test]
fn rotated_boxes_with_face_hints_are_exact() {
    let mut rng = Pcg64::seed_from_u64(1);
    for _ in 0..40 {
        let s = [
            rng.random_range(0.05..2.0),
            rng.random_range(0.05..2.0),
            rng.random_range(0.05..2.0),
        ];
        let r = rotation(&mut rng);
        let t = [
            rng.random_range(-5.0..5.0),
            rng.random_range(-5.0..5.0),
            rng.random_range(0.0..3.0),
        ];
        let (pts, normals) = rotated_box(s, &r, t);
        let b = min_area_obb(&pts, &normals);
        assert!(
            (b.area() - truth(s)).abs() <= 1e-9 * truth(s),
            "{s:?}: {}",
            b.area()
        );
        assert!(pts.iter().all(|&p| b.contains(p, 1e-9)));
    }
}

#[test]
fn rotated_boxes_from_points_alone_within_half_a_percent() {
    let mut rng = Pcg64::seed_from_u64(2);
    for _ in 0..25 {
        let s = [
            rng.random_range(0.1..2.0),
            rng.random_range(0.1..2.0),
            rng.random_range(0.1..2.0),
        ];
        let r = rotation(&mut rng);
        let (mut pts, _) = rotated_box(s, &r, [1.0, 2.0, 0.5]);
        // Interior points must not matter.
        for _ in 0..50 {
            let p = [
                rng.random::<f64>() * s[0],
                rng.random::<f64>() * s[1],
                rng.random::<f64>() * s[2],
            ];
            pts.push(apply(&r, p, [1.0, 2.0, 0.5]));
        }
        let b = min_area_obb(&pts, &[]);
        let err = (b.area() - truth(s)) / truth(s);
        assert!(
            (-1e-9..=0.005).contains(&err),
            "{s:?}: area {} truth {} err {err}",
            b.area(),
            truth(s)
        );
        assert!(pts.iter().all(|&p| b.contains(p, 1e-9)));
    }
}

#[test]
fn rotated_rectangles_get_the_flat_box_area_2ab() {
    let mut rng = Pcg64::seed_from_u64(3);
    for hinted in [true, false] {
        for _ in 0..25 {
            let (a, b) = (rng.random_range(0.1..3.0), rng.random_range(0.1..3.0));
            let r = rotation(&mut rng);
            let corners: Vec<V3> = [[0.0, 0.0, 0.0], [a, 0.0, 0.0], [a, b, 0.0], [0.0, b, 0.0]]
                .iter()
                .map(|&p| apply(&r, p, [0.3, -0.2, 1.0]))
                .collect();
            let hints = if hinted { vec![r[2]] } else { vec![] };
            let bx = min_area_obb(&corners, &hints);
            let err = (bx.area() - 2.0 * a * b) / (2.0 * a * b);
            assert!(
                (-1e-9..=0.005).contains(&err),
                "{a} x {b} hinted {hinted}: {}",
                bx.area()
            );
        }
    }
}

#[test]
fn the_smallest_box_of_a_sloped_prism_is_not_axis_aligned() {
    // A 2 x 0.4 x 0.4 bar rotated 30 degrees about z: its AABB is much larger.
    let c = 30f64.to_radians();
    let r = [
        [c.cos(), c.sin(), 0.0],
        [-c.sin(), c.cos(), 0.0],
        [0.0, 0.0, 1.0],
    ];
    let (pts, _) = rotated_box([2.0, 0.4, 0.4], &r, [0.0; 3]);
    let b = min_area_obb(&pts, &[]);
    assert!(
        (b.area() - truth([2.0, 0.4, 0.4])).abs() < 1e-6,
        "{}",
        b.area()
    );
    assert!(dot(b.axes[0], [0.0, 0.0, 1.0]).abs() < 1.0 + 1e-12);
}
