//! Smallest-surface-area oriented bounding box (OBB) of a point set.
//!
//! The seed (section 2.3.1) sizes every non-permanent object by the surface area of its OBB,
//! `A = 2 (ab + bc + ca)` for side lengths `a, b, c`, not by its volume, so that a desk modelled
//! as one polygon gets `2ab` (a zero-thickness box) instead of zero.
//!
//! ## Algorithm and what it guarantees
//!
//! 1. **Exact for a fixed up axis `u`.** Project the points onto the plane normal to `u`
//!    (height `h` = extent along `u`) and take their 2-D convex hull (Andrew's monotone
//!    chain). A box with up axis `u` and in-plane sides `a, b` has area `2 (ab + h(a + b)) =
//!    2 ((a + h)(b + h) - h^2)`. Between two consecutive hull-edge orientations the caliper
//!    widths `a(t)` and `b(t)` are each `|p_i - p_j| cos(t - phi)` with fixed extreme
//!    vertices, i.e. positive and concave; so `(a + h)(b + h)` is log-concave on the interval
//!    and its minimum lies at an end: **one box side is flush with a hull edge**. This is
//!    Freeman & Shapira's theorem for the minimum-area rectangle (H. Freeman, R. Shapira,
//!    "Determining the minimum-area encasing rectangle for an arbitrary closed curve", CACM
//!    18(7), 1975), extended to the surface-area cost by the log-concavity argument above.
//!    We try every hull edge (`O(h^2)`, hulls are small), which equals rotating calipers.
//! 2. **Search over up axes.** Candidates: the hint directions (the object's polygon normals
//!    and cylinder/cone/ring axes, i.e. the faces a box is likely to be flush with), the
//!    coordinate axes, the principal axes of the points (PCA), and a Fibonacci grid of
//!    [`GRID`] directions on the hemisphere. The best [`STARTS`] are refined by a compass
//!    (pattern) search on the sphere down to [`MIN_STEP`] rad.
//!
//! Guarantee: the result always encloses every point, and its area is the exact minimum
//! over boxes whose up axis is any evaluated direction. When the optimal box has a face
//! parallel to one of the object's polygons (every box-shaped or flat object, which is what
//! furniture is modelled from) it is the exact optimum; otherwise it is a local optimum no
//! worse than the best grid direction (O'Rourke's exact 3-D algorithm, 1985, minimises
//! volume and is far more complex; Chang, Gorissen & Melchior 2011 also search SO(3)).

use nalgebra::{Matrix3, SymmetricEigen};
use rdaylight_base::vec3::{V3, add, cross, dot, normalized, scale, sub};
use serde::Serialize;

/// Fibonacci-grid directions on the hemisphere tried as up axes (coarse global search).
pub const GRID: usize = 256;
/// How many of the best candidates the compass search refines.
pub const STARTS: usize = 3;
/// Final angular step of the compass search (rad): near the optimum the area changes with
/// the square of the angle, so the area is then within ~1e-12 relative of the local
/// optimum, far below the 0.5 % the levels need.
pub const MIN_STEP: f64 = 1e-6;

/// Compass-search iterations per start: a bound on the cost for any input (a start
/// converges in 30-150 on furniture).
pub const MAX_ITERS: usize = 400;

/// An oriented box: `center`, three orthonormal `axes` and the full side `size` along each.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Obb {
    pub center: V3,
    pub axes: [V3; 3],
    pub size: [f64; 3],
}

impl Obb {
    /// Surface area `2 (ab + bc + ca)`; `2ab` for a flat object (seed section 2.3.1).
    pub fn area(&self) -> f64 {
        let [a, b, c] = self.size;
        2.0 * (a * b + b * c + c * a)
    }

    /// True if `p` lies inside the box enlarged by `tol` on every side.
    pub fn contains(&self, p: V3, tol: f64) -> bool {
        let d = sub(p, self.center);
        (0..3).all(|k| dot(d, self.axes[k]).abs() <= 0.5 * self.size[k] + tol)
    }

    fn empty() -> Obb {
        Obb {
            center: [0.0; 3],
            axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            size: [0.0; 3],
        }
    }
}

/// Two unit vectors completing `u` to a right-handed orthonormal frame.
pub fn tangents(u: V3) -> (V3, V3) {
    let a = if u[0].abs() < 0.6 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let t1 = normalized(sub(a, scale(u, dot(a, u))));
    (t1, cross(u, t1))
}

fn cross2(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// 2-D convex hull (Andrew's monotone chain), counter-clockwise, collinear points dropped.
pub fn hull2(mut p: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let mut h: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = h.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while h.len() >= start + 2 && cross2(h[h.len() - 2], h[h.len() - 1], q) <= 0.0 {
                h.pop();
            }
            h.push(q);
        }
        h.pop();
    }
    h
}

/// The exact smallest-area box with up axis `u` (step 1 of the module's algorithm).
pub fn box_with_up(points: &[V3], u: V3) -> Obb {
    if points.is_empty() {
        return Obb::empty();
    }
    let u = normalized(u);
    let (e1, e2) = tangents(u);
    let (mut hmin, mut hmax) = (f64::INFINITY, f64::NEG_INFINITY);
    let flat: Vec<[f64; 2]> = points
        .iter()
        .map(|&p| {
            let h = dot(p, u);
            hmin = hmin.min(h);
            hmax = hmax.max(h);
            [dot(p, e1), dot(p, e2)]
        })
        .collect();
    let h = hmax - hmin;
    let hull = hull2(flat);
    // Candidate in-plane directions: every hull edge (one side is flush with one of them).
    let mut dirs: Vec<[f64; 2]> = Vec::with_capacity(hull.len());
    for i in 0..hull.len() {
        let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let l = dx.hypot(dy);
        if l > 0.0 {
            dirs.push([dx / l, dy / l]);
        }
    }
    if dirs.is_empty() {
        dirs.push([1.0, 0.0]); // a single point seen along u
    }
    let mut best: Option<(f64, [f64; 2], [f64; 4])> = None;
    for d in dirs {
        let n = [-d[1], d[0]];
        let (mut a0, mut a1, mut b0, mut b1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for q in &hull {
            let (x, y) = (q[0] * d[0] + q[1] * d[1], q[0] * n[0] + q[1] * n[1]);
            a0 = a0.min(x);
            a1 = a1.max(x);
            b0 = b0.min(y);
            b1 = b1.max(y);
        }
        let cost = (a1 - a0 + h) * (b1 - b0 + h);
        if best.as_ref().is_none_or(|b| cost < b.0) {
            best = Some((cost, d, [a0, a1, b0, b1]));
        }
    }
    let (_, d, [a0, a1, b0, b1]) = best.expect("at least one direction");
    let ax = normalized(add(scale(e1, d[0]), scale(e2, d[1])));
    let ay = cross(u, ax);
    let mid = |lo: f64, hi: f64| 0.5 * (lo + hi);
    let center = add(
        add(scale(ax, mid(a0, a1)), scale(ay, mid(b0, b1))),
        scale(u, mid(hmin, hmax)),
    );
    Obb {
        center,
        axes: [ax, ay, u],
        size: [a1 - a0, b1 - b0, h],
    }
}

/// Principal axes of the points (eigenvectors of their covariance).
pub fn principal_axes(points: &[V3]) -> [V3; 3] {
    let n = points.len().max(1) as f64;
    let mean = scale(points.iter().fold([0.0; 3], |s, &p| add(s, p)), 1.0 / n);
    let mut c = [[0.0; 3]; 3];
    for &p in points {
        let d = sub(p, mean);
        for i in 0..3 {
            for j in 0..3 {
                c[i][j] += d[i] * d[j] / n;
            }
        }
    }
    let eig = SymmetricEigen::new(Matrix3::from_fn(|i, j| c[i][j]));
    let v = |k: usize| {
        let col = eig.eigenvectors.column(k);
        [col[0], col[1], col[2]]
    };
    [v(0), v(1), v(2)]
}

/// Fibonacci directions on the upper hemisphere (`u` and `-u` give the same box).
fn hemisphere_grid(n: usize) -> impl Iterator<Item = V3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n).map(move |i| {
        let z = 1.0 - (i as f64 + 0.5) / n as f64;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = golden * i as f64;
        [r * phi.cos(), r * phi.sin(), z]
    })
}

/// The smallest-surface-area oriented box of `points`; `hints` are likely face normals (see
/// the module documentation for the algorithm and its guarantee). Empty input gives an empty
/// box at the origin; non-finite points are ignored.
pub fn min_area_obb(points: &[V3], hints: &[V3]) -> Obb {
    let mut pts: Vec<V3> = points
        .iter()
        .copied()
        .filter(|p| p.iter().all(|x| x.is_finite()))
        .collect();
    // Shared vertices repeat many times in a furniture model; one copy each is enough.
    pts.sort_by(|a, b| {
        a[0].total_cmp(&b[0])
            .then(a[1].total_cmp(&b[1]))
            .then(a[2].total_cmp(&b[2]))
    });
    pts.dedup();
    if pts.is_empty() {
        return Obb::empty();
    }
    let valid = |v: &V3| v.iter().all(|x| x.is_finite()) && dot(*v, *v) > 1e-24;
    let mut cands: Vec<V3> = hints
        .iter()
        .filter(|v| valid(v))
        .map(|&v| normalized(v))
        .collect();
    cands.extend([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    if pts.len() > 1 {
        cands.extend(principal_axes(&pts).into_iter().filter(valid));
    }
    cands.extend(hemisphere_grid(GRID));
    let mut scored: Vec<(f64, V3, Obb)> = cands
        .into_iter()
        .map(|u| {
            let b = box_with_up(&pts, u);
            (b.area(), u, b)
        })
        .collect();
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best = scored[0].2.clone();
    for (area0, u0, _) in scored.into_iter().take(STARTS) {
        let (mut area, mut u) = (area0, u0);
        let mut step = 0.05;
        let mut iters = 0;
        while step > MIN_STEP && iters < MAX_ITERS {
            iters += 1;
            let (t1, t2) = tangents(u);
            let mut moved = false;
            for t in [t1, t2, scale(t1, -1.0), scale(t2, -1.0)] {
                let v = normalized(add(scale(u, step.cos()), scale(t, step.sin())));
                let b = box_with_up(&pts, v);
                // A move must gain more than rounding noise, or the search creeps on
                // forever along a flat valley at tiny steps.
                if b.area() < area * (1.0 - 1e-12) {
                    (area, u) = (b.area(), v);
                    if area < best.area() {
                        best = b;
                    }
                    moved = true;
                    break;
                }
            }
            if !moved {
                step *= 0.5;
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_and_single_point_give_empty_boxes() {
        assert_eq!(min_area_obb(&[], &[]).area(), 0.0);
        let b = min_area_obb(&[[1.0, 2.0, 3.0]], &[]);
        assert_eq!(b.area(), 0.0);
        assert_eq!(b.center, [1.0, 2.0, 3.0]);
    }

    #[test]
    fn a_segment_has_zero_area_and_its_length() {
        let b = min_area_obb(&[[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]], &[]);
        assert!(b.area() < 1e-12, "{b:?}");
        let len = b.size.iter().cloned().fold(0.0, f64::max);
        assert!((len - 3f64.sqrt()).abs() < 1e-9);
    }

    #[test]
    fn hull_of_a_square_with_interior_and_collinear_points() {
        let h = hull2(vec![
            [0.0, 0.0],
            [1.0, 0.0],
            [0.5, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [0.5, 0.5],
        ]);
        assert_eq!(h.len(), 4);
    }
}
