//! Polygon triangulation by ear clipping in the polygon's own plane.
//!
//! Radiance polygons (`doc/ray.1`, `src/common/face.c`) list their vertices counter-clockwise
//! seen from the front, so the front normal follows the right-hand rule. They may be
//! non-convex and may have holes, which are cut in with a *seam*: the outline walks to the
//! hole, around it the other way, and back along the same edge. Radiance itself never
//! triangulates: it intersects the plane and runs an even-odd crossing test (`inface`). To
//! put polygons in a triangle BVH we triangulate instead, keeping the same area and normal.
//!
//! Method:
//! 1. Normal by Newell's method, `N = ½ Σ (vᵢ − v₀) × (vᵢ₊₁ − v₀)`, the same sum Radiance's
//!    `getface` uses; `|N|` is the area. A polygon whose area is below `1e-12 · L²`
//!    (`L` = largest bounding-box side) is *degenerate*: Radiance warns "zero area" and the
//!    polygon never intersects anything, so we report [`PolygonError::ZeroArea`] for the caller
//!    to turn into a `file:line` warning or error ([`PolygonError::at`]).
//! 2. Project onto a right-handed basis `(u, v)` of the plane (`u × v = N/|N|`), so the outline
//!    is counter-clockwise in 2-D whatever the 3-D orientation.
//! 3. Remove repeated vertices (within `1e-9 · L`) and vertices where the outline goes straight
//!    on or turns back (twice-signed triangle area within `1e-12 · L²`): they add no area.
//! 4. Clip ears: a vertex `b` with neighbours `a`, `c` is an ear when the turn `a→b→c` is
//!    strictly left and no other remaining vertex lies inside or on the triangle `abc`, except
//!    vertices at the same position as `a`, `b` or `c` — these are the duplicated seam
//!    vertices, and skipping them is what lets a seam-joined hole triangulate.
//! 5. If a full pass finds no ear (input that is not weakly simple, or rounding), the most
//!    convex vertex is clipped anyway, so the loop always ends; triangles then may overlap.
//!
//! Output triangles are index triples into the input, in the polygon's orientation: each
//! triangle's right-hand normal points the same way as the polygon's Newell normal.
//! Cost is O(n²) per polygon (fine for the tens of vertices of architectural polygons).

use std::fmt;

use super::vec3::Vec3;
use crate::error::{Error, Location};

/// Why a polygon could not be triangulated.
#[derive(Debug, Clone, PartialEq)]
pub enum PolygonError {
    /// Fewer than three vertices.
    TooFewVertices(usize),
    /// A vertex coordinate is NaN or infinite.
    NonFinite(usize),
    /// The Newell area is zero (or below `1e-12 · L²`); `area` is what was found.
    ZeroArea { area: f64 },
}

impl fmt::Display for PolygonError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PolygonError::TooFewVertices(n) => {
                write!(f, "polygon has {n} vertices; expected at least 3")
            }
            PolygonError::NonFinite(i) => {
                write!(
                    f,
                    "polygon vertex {} is not finite; expected real coordinates",
                    i + 1
                )
            }
            PolygonError::ZeroArea { area } => write!(
                f,
                "polygon has zero area ({area:e}); expected vertices spanning a plane"
            ),
        }
    }
}

impl std::error::Error for PolygonError {}

impl PolygonError {
    /// The library error for this problem at `loc` (the primitive's `file:line`).
    pub fn at(&self, loc: Location) -> Error {
        Error::parse(loc, self.to_string())
    }
}

/// Newell normal of a polygon: direction of the front side, length equal to the area.
pub fn newell_normal(verts: &[Vec3]) -> Vec3 {
    let Some(&v0) = verts.first() else {
        return Vec3::ZERO;
    };
    let mut n = Vec3::ZERO;
    // Relative to v0 so that a polygon far from the origin keeps its precision.
    for w in verts.windows(2).skip(1) {
        n += (w[0] - v0).cross(w[1] - v0);
    }
    n * 0.5
}

/// Area of a polygon (half the length of the Newell sum). Holes joined by seams count as
/// holes because they are walked the other way round.
pub fn polygon_area(verts: &[Vec3]) -> f64 {
    newell_normal(verts).length()
}

/// Triangulate a polygon; see the module documentation. Returns index triples into `verts`.
pub fn triangulate(verts: &[Vec3]) -> Result<Vec<[usize; 3]>, PolygonError> {
    let mut out = Vec::new();
    triangulate_into(verts, &mut out)?;
    Ok(out)
}

/// [`triangulate`] into `out` (cleared first), so a loop over a million polygons
/// allocates once.
pub fn triangulate_into(verts: &[Vec3], out: &mut Vec<[usize; 3]>) -> Result<(), PolygonError> {
    out.clear();
    let (size, nrm, area) = check(verts)?;
    if verts.len() == 3 {
        out.push([0, 1, 2]);
        return Ok(());
    }
    let w = nrm / area;
    // Any unit vector perpendicular to w, then v = w × u so that u × v = w.
    let helper = if w.x.abs() < 0.6 {
        Vec3::new(1.0, 0.0, 0.0)
    } else {
        Vec3::new(0.0, 1.0, 0.0)
    };
    let u = helper.cross(w).normalize();
    let v = w.cross(u);
    let pts: Vec<[f64; 2]> = verts
        .iter()
        .map(|&p| {
            let d = p - verts[0];
            [d.dot(u), d.dot(v)]
        })
        .collect();
    out.extend(EarClipper::new(pts, size).run());
    Ok(())
}

/// Whether [`triangulate`] succeeds (its only failures are these checks; ear clipping
/// itself always ends), without building the triangles. Returns the largest
/// bounding-box side, the Newell normal and its length (the area).
pub fn check(verts: &[Vec3]) -> Result<(f64, Vec3, f64), PolygonError> {
    let n = verts.len();
    if n < 3 {
        return Err(PolygonError::TooFewVertices(n));
    }
    if let Some(i) = verts.iter().position(|v| !v.is_finite()) {
        return Err(PolygonError::NonFinite(i));
    }
    let (lo, hi) = verts
        .iter()
        .fold((verts[0], verts[0]), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let size = (hi - lo).max_elem();
    let nrm = newell_normal(verts);
    let area = nrm.length();
    // `area` is finite here (finite vertices), so `<=` also covers the degenerate case.
    if area <= 1e-12 * size * size {
        return Err(PolygonError::ZeroArea { area });
    }
    Ok((size, nrm, area))
}

/// Twice the signed area of the 2-D triangle `abc` (positive for a left turn).
#[inline]
fn cross2(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

struct EarClipper {
    pts: Vec<[f64; 2]>,
    prev: Vec<usize>,
    next: Vec<usize>,
    alive: Vec<bool>,
    count: usize,
    eps_len2: f64,
    eps_area: f64,
    tris: Vec<[usize; 3]>,
}

impl EarClipper {
    fn new(pts: Vec<[f64; 2]>, size: f64) -> Self {
        let n = pts.len();
        let eps_len = 1e-9 * size;
        EarClipper {
            prev: (0..n).map(|i| (i + n - 1) % n).collect(),
            next: (0..n).map(|i| (i + 1) % n).collect(),
            alive: vec![true; n],
            count: n,
            eps_len2: eps_len * eps_len,
            eps_area: 1e-12 * size * size,
            tris: Vec::with_capacity(n.saturating_sub(2)),
            pts,
        }
    }

    fn same(&self, i: usize, j: usize) -> bool {
        let (p, q) = (self.pts[i], self.pts[j]);
        let (dx, dy) = (p[0] - q[0], p[1] - q[1]);
        dx * dx + dy * dy <= self.eps_len2
    }

    fn turn(&self, i: usize) -> f64 {
        cross2(self.pts[self.prev[i]], self.pts[i], self.pts[self.next[i]])
    }

    fn remove(&mut self, i: usize) {
        let (p, n) = (self.prev[i], self.next[i]);
        self.next[p] = n;
        self.prev[n] = p;
        self.alive[i] = false;
        self.count -= 1;
    }

    /// Remove `i` if it repeats its successor or the outline goes straight on or turns back
    /// there; then re-examine its neighbours. Returns a live vertex near `i`.
    fn clean_from(&mut self, start: usize) -> usize {
        let mut stack = vec![start];
        let mut live = start;
        while let Some(i) = stack.pop() {
            if !self.alive[i] || self.count <= 3 {
                if self.alive[i] {
                    live = i;
                }
                continue;
            }
            let (p, n) = (self.prev[i], self.next[i]);
            if self.same(i, n) || self.turn(i).abs() <= self.eps_area {
                self.remove(i);
                stack.push(p);
                stack.push(n);
                live = n;
            } else {
                live = i;
            }
        }
        if self.alive[live] {
            live
        } else {
            (0..self.alive.len()).find(|&i| self.alive[i]).unwrap_or(0)
        }
    }

    fn is_ear(&self, b: usize) -> bool {
        let (a, c) = (self.prev[b], self.next[b]);
        if self.turn(b) <= self.eps_area {
            return false;
        }
        let (pa, pb, pc) = (self.pts[a], self.pts[b], self.pts[c]);
        let mut p = self.next[c];
        while p != a {
            if !(self.same(p, a) || self.same(p, b) || self.same(p, c)) {
                let q = self.pts[p];
                // Inside or on the closed triangle, with a tolerance that errs on "inside".
                let e = -self.eps_area;
                if cross2(pa, pb, q) >= e && cross2(pb, pc, q) >= e && cross2(pc, pa, q) >= e {
                    return false;
                }
            }
            p = self.next[p];
        }
        true
    }

    fn clip(&mut self, b: usize) -> usize {
        let (a, c) = (self.prev[b], self.next[b]);
        self.tris.push([a, b, c]);
        self.remove(b);
        let a = self.clean_from(a);
        if self.alive[c] { self.clean_from(c) } else { a }
    }

    fn run(mut self) -> Vec<[usize; 3]> {
        let n = self.pts.len();
        let mut cur = 0;
        for i in 0..n {
            if self.alive[i] {
                cur = self.clean_from(i);
            }
        }
        // Convex quadrilateral (the most common polygon of all): split on one diagonal.
        if self.count == 4 && (0..4).all(|k| self.turn(self.nth_from(cur, k)) > self.eps_area) {
            let [a, b, c, d] = [0, 1, 2, 3].map(|k| self.nth_from(cur, k));
            self.tris.push([a, b, c]);
            self.tris.push([a, c, d]);
            return self.tris;
        }
        let mut misses = 0;
        while self.count >= 3 {
            if self.count == 3 {
                let (a, c) = (self.prev[cur], self.next[cur]);
                if self.turn(cur) > 0.0 {
                    self.tris.push([a, cur, c]);
                }
                break;
            }
            if self.is_ear(cur) {
                cur = self.clip(cur);
                misses = 0;
                continue;
            }
            cur = self.next[cur];
            misses += 1;
            if misses > self.count {
                // No ear in a full pass: clip the most convex vertex, or give up when the rest
                // encloses no positive area.
                let mut best = cur;
                let mut best_turn = f64::NEG_INFINITY;
                let mut p = cur;
                for _ in 0..self.count {
                    let t = self.turn(p);
                    if t > best_turn {
                        best_turn = t;
                        best = p;
                    }
                    p = self.next[p];
                }
                if best_turn <= 0.0 {
                    break;
                }
                cur = self.clip(best);
                misses = 0;
            }
        }
        self.tris
    }

    fn nth_from(&self, start: usize, k: usize) -> usize {
        (0..k).fold(start, |i, _| self.next[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    #[test]
    fn triangle_and_too_few() {
        let t = [v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.)];
        assert_eq!(triangulate(&t).unwrap(), vec![[0, 1, 2]]);
        assert_eq!(
            triangulate(&t[..2]).unwrap_err(),
            PolygonError::TooFewVertices(2)
        );
    }

    #[test]
    fn zero_area_message_has_location() {
        let line = [v(0., 0., 0.), v(1., 1., 1.), v(2., 2., 2.), v(3., 3., 3.)];
        let e = triangulate(&line).unwrap_err();
        assert!(matches!(e, PolygonError::ZeroArea { .. }));
        let msg = e.at(Location::line("room.rad", 12)).to_string();
        assert!(
            msg.starts_with("room.rad:12: polygon has zero area"),
            "{msg}"
        );
    }
}
