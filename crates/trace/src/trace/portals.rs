//! Window portals: sampling the light that enters a room through its glazing.
//!
//! In a side-lit room nearly all daylight enters through the window panes, yet a path
//! bouncing off a wall finds a window only when its cosine-distributed direction happens to
//! point at one (with probability "projected solid angle of the windows / pi", a few per
//! cent deep in a room). Rendering practice (Bitterli et al., "Portal-Masked Environment
//! Map Sampling", EGSR 2015; Pharr, Jakob & Humphreys, *Physically Based Rendering* 4th
//! ed., sections 12.5 and 13.4) samples such *portals* directly. At a Lambertian vertex
//! `x` inside the room the tracer ([`super::integrator`]) uses them twice:
//!
//! 1. **Next-event estimation of the sky** through the part of the panes *above* `x`
//!    (where rising directions reach the sky; see "rising-only panes" below): a point `y`
//!    on a pane, a shadow ray from `x` through `y` that must pass glass only and escape,
//!    and the sky behind it counted.
//! 2. **The path's own continuation**, drawn from a mixture: with probability
//!    [`FALL_SHARE`] through the part of a rising-only pane *below* `x` (the light the
//!    ground outside reflects in, the main source of a ceiling's light), otherwise from
//!    the material's cosine distribution. Its weight is `f cos / m(w)` with the mixture's
//!    density `m(w) = (1 - a) cos/pi + a p_fall(w)` (a one-sample "defensive" mixture,
//!    Hesterberg 1995; Veach's thesis section 9.2.2).
//!
//! Both the shadow ray of (1) and the continuation of (2) can reach the sky straight
//! through glass, so each of those paths is weighted by the balance heuristic (Veach &
//! Guibas, "Optimally Combining Sampling Techniques for Monte Carlo Rendering", SIGGRAPH
//! 1995, eq. 8):
//!
//! ```text
//! w_continuation(w) = m(w) / (m(w) + p_sky(w)),   w_sky(w) = p_sky(w) / (m(w) + p_sky(w))
//! ```
//!
//! which keeps the estimator unbiased whatever the portals are: how well they are chosen
//! only changes the noise. Everything else a path meets (walls, furniture, the glass's
//! reflected ray, a glow on a surface, a BSDF) is found only by the continuation, with
//! weight 1.
//!
//! ## Which panes are portals
//! Polygons of the top-level scene whose material is `glass`, and only when one side of the
//! pane sees the sky (the *outside*) and the other sees mostly the room: from the pane's
//! centroid, [`PROBE_RAYS`] cosine-distributed probes on each side are traced through glass;
//! the side with more escapes is the outside when at least [`MIN_OUTSIDE`] of its probes
//! escape and the other side's share is at most half of it. A vertex uses a portal only
//! from the inside half-space of its plane. Panes in `mesh` or `instance` files are not
//! portals (found by the continuation as before). A scene with more than [`MAX_PORTALS`]
//! candidate panes gets none.
//!
//! **Rising-only panes**: when fewer than a tenth of a pane's falling outside probes
//! escape (modelled ground, terrain or a street outside), falling directions through it
//! almost never reach the sky, so the sky is sampled only through the part of the pane
//! above the vertex (directions with `z > 0`), and the part below is what the mixture of
//! (2) aims at.
//!
//! ## Densities
//! The pane is chosen with probability proportional to an estimate of how much of `x`'s
//! cosine-weighted hemisphere its sampled part covers (area x cosine at the pane / squared
//! distance of the part's centroid, times `0.1 + cos` at `x`; every usable pane keeps a
//! positive share), the point uniformly by area over that part: by the two parameters of a
//! parallelogram pane (so stratified numbers stay stratified), else over its triangles
//! clipped at the vertex's height. The solid-angle density of a direction `w` is then
//! `sum_k P(k) d_k^2 / (A_k |cos theta_k|)` over every usable pane `k` whose sampled part
//! the ray `x + t w` crosses at distance `d_k` (geometry only: occlusion is the shadow
//! ray's business), the same sum whichever strategy produced `w`.

use crate::geometry::triangulate::triangulate;
use crate::geometry::{Ray, Vec3};
use std::f64::consts::PI;

/// Most panes sampled as portals; a scene with more candidates gets none (the selection
/// walks every pane at every vertex).
pub const MAX_PORTALS: usize = 64;
/// Probe rays per side of a candidate pane when deciding which side is outside.
pub const PROBE_RAYS: usize = 64;
/// Least share of a pane's outside probes that must escape to the sky.
pub const MIN_OUTSIDE: f64 = 0.1;
/// Share of a vertex's continuations aimed through the panes' parts below it, when it
/// has any (rising-only panes).
pub const FALL_SHARE: f64 = 0.3;

/// Which part of a pane a strategy samples from a vertex at height `z`.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Part {
    All,
    Above(f64),
    Below(f64),
}

/// One window pane used as a portal.
#[derive(Debug, Clone)]
pub struct Portal {
    tris: Vec<[Vec3; 3]>,
    /// Cumulative triangle areas over the pane's area (last = 1).
    cum: Vec<f64>,
    area: f64,
    /// Unit front normal (Radiance's right-hand rule).
    normal: Vec3,
    /// `normal . p` for points `p` of the plane.
    offset: f64,
    /// +1 when the room is on the front side, -1 on the back side.
    inside: f64,
    centroid: Vec3,
    /// See "rising-only panes" in the module documentation.
    rising_only: bool,
    /// A parallelogram pane `v0 + a e1 + b e2` (`a, b` in [0, 1]), the commonest window:
    /// sampled by its two parameters directly, so stratified `(a, b)` stay stratified over
    /// the whole pane (and over a part cut at a height when `e1` is level).
    para: Option<[Vec3; 3]>,
}

/// The part of triangle `t` above (`above`) or below height `z0`: a convex polygon of up
/// to four vertices (one clipping plane of Sutherland and Hodgman's polygon clipping,
/// CACM 1974).
fn clip(t: &[Vec3; 3], z0: f64, above: bool) -> ([Vec3; 4], usize) {
    let mut out = [Vec3::ZERO; 4];
    let mut n = 0;
    let keep = |p: Vec3| if above { p.z > z0 } else { p.z < z0 };
    for i in 0..3 {
        let (a, b) = (t[i], t[(i + 1) % 3]);
        let (ina, inb) = (keep(a), keep(b));
        if ina {
            out[n] = a;
            n += 1;
        }
        if ina != inb {
            let s = (z0 - a.z) / (b.z - a.z);
            out[n] = a + (b - a) * s;
            n += 1;
        }
    }
    (out, n)
}

/// Area and area-weighted centroid of a convex polygon (fan from its first vertex).
fn fan_area(v: &[Vec3]) -> (f64, Vec3) {
    let mut area = 0.0;
    let mut c = Vec3::ZERO;
    for i in 1..v.len().saturating_sub(1) {
        let a = 0.5 * (v[i] - v[0]).cross(v[i + 1] - v[0]).length();
        area += a;
        c += (v[0] + v[i] + v[i + 1]) * (a / 3.0);
    }
    if area > 0.0 {
        (area, c / area)
    } else {
        (0.0, v.first().copied().unwrap_or(Vec3::ZERO))
    }
}

/// Whether parallelogram `q`'s first edge is level (a cut at a height is then a range of
/// the second parameter).
fn e1_level(q: &[Vec3; 3]) -> bool {
    q[1].z.abs() <= 1e-9 * q[1].length() && q[2].z != 0.0
}

/// `[v0, e1, e2]` when the four `v` form a parallelogram `v0 + a e1 + b e2`, with `e1`
/// the more level edge.
fn parallelogram(v: &[Vec3]) -> Option<[Vec3; 3]> {
    if v.len() != 4 {
        return None;
    }
    let scale = (v[2] - v[0]).length().max((v[3] - v[1]).length());
    if (v[0] + v[2] - v[1] - v[3]).length() > 1e-9 * scale {
        return None;
    }
    let (e1, e2) = (v[1] - v[0], v[3] - v[0]);
    if e1.cross(e2).length() <= 1e-12 * scale * scale {
        return None;
    }
    Some(if e1.z.abs() <= e2.z.abs() {
        [v[0], e1, e2]
    } else {
        [v[0], e2, e1]
    })
}

/// The range of the second parameter of a level parallelogram `q` within `part`
/// (`None`: empty).
fn level_range(q: &[Vec3; 3], part: Part) -> Option<(f64, f64)> {
    let [v0, _, e2] = *q;
    let (z0, above) = match part {
        Part::All => return Some((0.0, 1.0)),
        Part::Above(z) => (z, true),
        Part::Below(z) => (z, false),
    };
    let b = (z0 - v0.z) / e2.z;
    let (lo, hi) = if (e2.z > 0.0) == above {
        (b, 1.0)
    } else {
        (0.0, b)
    };
    let (lo, hi) = (lo.clamp(0.0, 1.0), hi.clamp(0.0, 1.0));
    (hi > lo).then_some((lo, hi))
}

/// A point uniformly by area in triangle `t` from `(a, b)`.
fn in_triangle(t: [Vec3; 3], a: f64, b: f64) -> Vec3 {
    let s = a.sqrt();
    let (b0, b1) = (1.0 - s, b * s);
    t[0] * b0 + t[1] * b1 + t[2] * (1.0 - b0 - b1)
}

impl Portal {
    /// A pane from its polygon vertices (`None` for a degenerate polygon).
    pub fn new(vertices: &[[f64; 3]]) -> Option<Portal> {
        let v: Vec<Vec3> = vertices.iter().map(|&p| Vec3::from(p)).collect();
        let idx = triangulate(&v).ok()?;
        let tris: Vec<[Vec3; 3]> = idx.iter().map(|t| [v[t[0]], v[t[1]], v[t[2]]]).collect();
        let areas: Vec<f64> = tris
            .iter()
            .map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
            .collect();
        let area: f64 = areas.iter().sum();
        if area <= 0.0 || !area.is_finite() {
            return None;
        }
        let mut acc = 0.0;
        let cum = areas
            .iter()
            .map(|a| {
                acc += a / area;
                acc
            })
            .collect();
        let normal = crate::geometry::triangulate::newell_normal(&v).normalize();
        let centroid = tris.iter().zip(&areas).fold(Vec3::ZERO, |c, (t, a)| {
            c + (t[0] + t[1] + t[2]) * (a / (3.0 * area))
        });
        Some(Portal {
            tris,
            cum,
            area,
            normal,
            offset: normal.dot(centroid),
            inside: 1.0,
            centroid,
            rising_only: false,
            para: parallelogram(&v),
        })
    }

    /// The pane's unit front normal and centroid.
    pub fn frame(&self) -> (Vec3, Vec3) {
        (self.normal, self.centroid)
    }

    /// Set the side the room is on (+1 front, -1 back).
    pub fn set_inside(&mut self, sign: f64) {
        self.inside = sign.signum();
    }

    /// Sample the sky only through the part above a vertex (see the module documentation).
    pub fn set_rising_only(&mut self, on: bool) {
        self.rising_only = on;
    }

    /// Signed distance of `x` from the plane, positive on the room's side.
    fn height(&self, x: Vec3) -> f64 {
        self.inside * (self.normal.dot(x) - self.offset)
    }

    /// The part the sky strategy (`fall` false) or the falling continuation (`fall` true)
    /// samples from `x`; `None` when that strategy does not use this pane.
    fn part(&self, x: Vec3, fall: bool) -> Option<Part> {
        match (self.rising_only, fall) {
            (false, false) => Some(Part::All),
            (false, true) => None,
            (true, false) => Some(Part::Above(x.z)),
            (true, true) => Some(Part::Below(x.z)),
        }
    }

    /// Whether direction `dir` from a vertex leaves through `part` of a pane it crosses
    /// (the crossing point's height against the vertex's).
    fn in_part(part: Part, dir: Vec3) -> bool {
        match part {
            Part::All => true,
            Part::Above(_) => dir.z > 0.0,
            Part::Below(_) => dir.z < 0.0,
        }
    }

    /// Area and centroid of `part` of the pane.
    fn usable(&self, part: Part) -> (f64, Vec3) {
        let (z0, above) = match part {
            Part::All => return (self.area, self.centroid),
            Part::Above(z) => (z, true),
            Part::Below(z) => (z, false),
        };
        if let Some(q) = &self.para {
            if e1_level(q) {
                return match level_range(q, part) {
                    Some((lo, hi)) => (
                        self.area * (hi - lo),
                        q[0] + q[1] * 0.5 + q[2] * (0.5 * (lo + hi)),
                    ),
                    None => (0.0, self.centroid),
                };
            }
        }
        let mut area = 0.0;
        let mut c = Vec3::ZERO;
        for t in &self.tris {
            let (v, n) = clip(t, z0, above);
            let (a, ct) = fan_area(&v[..n]);
            area += a;
            c += ct * a;
        }
        if area > 0.0 {
            (area, c / area)
        } else {
            (0.0, self.centroid)
        }
    }

    /// A point uniformly by area over `part` (of area `area`, from [`Portal::usable`]):
    /// `u` picks the triangle or piece, `(a, b)` the point.
    fn point_in(&self, part: Part, area: f64, u: f64, a: f64, b: f64) -> Vec3 {
        if let Some(q) = &self.para {
            if part == Part::All || e1_level(q) {
                let (lo, hi) = level_range(q, part).unwrap_or((0.0, 1.0));
                return q[0] + q[1] * a + q[2] * (lo + (hi - lo) * b);
            }
        }
        let (z0, above) = match part {
            Part::All => {
                let k = self
                    .cum
                    .partition_point(|&c| c <= u)
                    .min(self.tris.len() - 1);
                return in_triangle(self.tris[k], a, b);
            }
            Part::Above(z) => (z, true),
            Part::Below(z) => (z, false),
        };
        let target = u * area;
        let mut acc = 0.0;
        let mut last = None;
        for t in &self.tris {
            let (v, n) = clip(t, z0, above);
            // Convex piece: a fan of one or two triangles.
            for i in 1..n.saturating_sub(1) {
                let tri = [v[0], v[i], v[i + 1]];
                let at = 0.5 * (tri[1] - tri[0]).cross(tri[2] - tri[0]).length();
                last = Some(tri);
                if target < acc + at {
                    return in_triangle(tri, a, b);
                }
                acc += at;
            }
        }
        last.map_or(self.centroid, |tri| in_triangle(tri, a, b))
    }

    /// Distance along the ray to the pane, if the ray crosses it (Moller-Trumbore on each
    /// triangle; both faces).
    fn crossing(&self, org: Vec3, dir: Vec3) -> Option<f64> {
        for t in &self.tris {
            let e1 = t[1] - t[0];
            let e2 = t[2] - t[0];
            let p = dir.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-300 {
                continue;
            }
            let inv = 1.0 / det;
            let s = org - t[0];
            let u = s.dot(p) * inv;
            if !(0.0..=1.0).contains(&u) {
                continue;
            }
            let q = s.cross(e1);
            let v = dir.dot(q) * inv;
            if v < 0.0 || u + v > 1.0 {
                continue;
            }
            let d = e2.dot(q) * inv;
            if d > 0.0 {
                return Some(d);
            }
        }
        None
    }
}

/// The scene's portals.
#[derive(Debug, Clone, Default)]
pub struct Portals {
    list: Vec<Portal>,
}

/// One strategy's pane probabilities and sampled parts from one vertex.
struct Selection {
    prob: [f64; MAX_PORTALS],
    /// Area of each pane's sampled part.
    area: [f64; MAX_PORTALS],
    part: [Part; MAX_PORTALS],
}

impl Portals {
    pub fn new(list: Vec<Portal>) -> Portals {
        if list.len() > MAX_PORTALS {
            return Portals::default();
        }
        Portals { list }
    }

    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// How many panes are rising-only (for `--stats` and tests).
    pub fn rising_only(&self) -> usize {
        self.list.iter().filter(|p| p.rising_only).count()
    }

    /// One strategy's selection from `x` with oriented normal `n` (`None`: no pane usable).
    fn selection(&self, x: Vec3, n: Vec3, fall: bool) -> Option<Selection> {
        let mut sel = Selection {
            prob: [0.0; MAX_PORTALS],
            area: [0.0; MAX_PORTALS],
            part: [Part::All; MAX_PORTALS],
        };
        let mut total = 0.0;
        for (k, p) in self.list.iter().enumerate() {
            if p.height(x) <= 1e-9 {
                continue;
            }
            let Some(part) = p.part(x, fall) else {
                continue;
            };
            let (a, c) = p.usable(part);
            if a <= 1e-12 * p.area {
                continue;
            }
            let to = c - x;
            let d2 = to.length_squared();
            let d = d2.sqrt();
            if d <= 0.0 {
                continue;
            }
            let cos_p = (p.normal.dot(to) / d).abs();
            let cos_x = n.dot(to) / d;
            let w = a * cos_p.max(0.05) / (d2 + a) * (0.1 + cos_x.max(0.0));
            sel.prob[k] = w;
            sel.area[k] = a;
            sel.part[k] = part;
            total += w;
        }
        if total <= 0.0 || !total.is_finite() {
            return None;
        }
        for w in sel.prob.iter_mut().take(self.list.len()) {
            *w /= total;
        }
        Some(sel)
    }

    /// The portal strategies at vertex `x` with oriented normal `n` (`None`: no pane is
    /// usable from there).
    pub fn at(&self, x: Vec3, n: Vec3) -> Option<At<'_>> {
        let sky = self.selection(x, n, false);
        let fall = if self.list.iter().any(|p| p.rising_only) {
            self.selection(x, n, true)
        } else {
            None
        };
        (sky.is_some() || fall.is_some()).then_some(At {
            portals: self,
            sky,
            fall,
            x,
        })
    }

    /// Solid-angle density of the sky strategy producing direction `dir` (unit) from `x`.
    pub fn pdf(&self, x: Vec3, n: Vec3, dir: Vec3) -> f64 {
        self.at(x, n).map_or(0.0, |a| a.pdf(dir))
    }

    /// A sky-strategy direction from `x`: see [`At::sample`].
    pub fn sample(&self, x: Vec3, n: Vec3, u: f64, a: f64, b: f64) -> Option<(Vec3, f64)> {
        self.at(x, n)?.sample(u, a, b)
    }
}

/// The portal strategies at one vertex: the sky's (next-event estimation through the
/// panes' parts that see the sky) and the falling continuation's.
pub struct At<'a> {
    portals: &'a Portals,
    sky: Option<Selection>,
    fall: Option<Selection>,
    x: Vec3,
}

impl At<'_> {
    fn density(&self, sel: &Selection, dir: Vec3) -> f64 {
        let mut pdf = 0.0;
        for (k, p) in self.portals.list.iter().enumerate() {
            if sel.prob[k] <= 0.0 || !Portal::in_part(sel.part[k], dir) {
                continue;
            }
            if let Some(t) = p.crossing(self.x, dir) {
                let cos = dir.dot(p.normal).abs();
                if cos > 1e-12 {
                    pdf += sel.prob[k] * t * t / (sel.area[k] * cos);
                }
            }
        }
        pdf
    }

    fn draw(&self, sel: &Selection, u: f64, a: f64, b: f64) -> Option<(Vec3, f64)> {
        let list = &self.portals.list;
        // The pane whose share of [0, 1) holds `u`, and `u` rescaled within that share
        // (rounding past the last share falls to the last usable pane).
        let mut acc = 0.0;
        let mut pick = None;
        for (k, &pk) in sel.prob.iter().enumerate().take(list.len()) {
            if pk <= 0.0 {
                continue;
            }
            pick = Some((k, ((u - acc) / pk).clamp(0.0, 1.0 - 1e-16)));
            if u < acc + pk {
                break;
            }
            acc += pk;
        }
        let (k, ur) = pick?;
        let y = list[k].point_in(sel.part[k], sel.area[k], ur, a, b);
        let to = y - self.x;
        let d = to.length();
        if d <= 0.0 || !d.is_finite() {
            return None;
        }
        let dir = to / d;
        let pdf = self.density(sel, dir);
        (pdf > 0.0 && pdf.is_finite()).then_some((dir, pdf))
    }

    /// Solid-angle density of direction `dir` (unit) under the sky strategy.
    pub fn pdf(&self, dir: Vec3) -> f64 {
        self.sky.as_ref().map_or(0.0, |s| self.density(s, dir))
    }

    /// A sky-strategy direction: `(dir, pdf)` with the direction's full density over every
    /// pane (`None` when no pane's sky part is usable, or for a degenerate draw). `u` picks
    /// the pane and its triangle, `(a, b)` the point on it.
    pub fn sample(&self, u: f64, a: f64, b: f64) -> Option<(Vec3, f64)> {
        self.draw(self.sky.as_ref()?, u, a, b)
    }

    /// Share of the continuation drawn by [`At::sample_fall`]: [`FALL_SHARE`] when a pane
    /// has a usable part below the vertex, else 0.
    pub fn fall_share(&self) -> f64 {
        if self.fall.is_some() { FALL_SHARE } else { 0.0 }
    }

    /// Density of direction `dir` under the falling continuation.
    pub fn fall_pdf(&self, dir: Vec3) -> f64 {
        self.fall.as_ref().map_or(0.0, |s| self.density(s, dir))
    }

    /// A falling-continuation direction (through a pane's part below the vertex).
    pub fn sample_fall(&self, u: f64, a: f64, b: f64) -> Option<Vec3> {
        self.draw(self.fall.as_ref()?, u, a, b).map(|(d, _)| d)
    }
}

/// Cosine-distributed probe directions about `n` on a fixed spiral (deterministic, so the
/// same scene always gets the same portals).
pub(super) fn probe_rays(org: Vec3, n: Vec3) -> impl Iterator<Item = Ray> {
    let golden = PI * (3.0 - 5f64.sqrt());
    let (t, b) = crate::material::sampling::frame(n.to_array());
    let (t, b) = (Vec3::from(t), Vec3::from(b));
    (0..PROBE_RAYS).map(move |i| {
        let u = (i as f64 + 0.5) / PROBE_RAYS as f64;
        let phi = golden * i as f64;
        let r = u.sqrt();
        let dir = (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u).sqrt()).normalize();
        Ray { org, dir }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// A 2 x 1.5 m pane in the plane y = 0 from z = 1 to 2.5, front normal -y.
    fn window(x0: f64) -> Portal {
        Portal::new(&[
            [x0, 0.0, 1.0],
            [x0 + 2.0, 0.0, 1.0],
            [x0 + 2.0, 0.0, 2.5],
            [x0, 0.0, 2.5],
        ])
        .unwrap()
    }

    /// A pentagon (not a parallelogram: sampled over its clipped triangles).
    fn pentagon() -> Portal {
        Portal::new(&[
            [3.0, 0.0, 0.5],
            [4.0, 0.0, 0.5],
            [4.2, 0.0, 1.5],
            [3.5, 0.0, 2.2],
            [2.8, 0.0, 1.5],
        ])
        .unwrap()
    }

    #[test]
    fn pane_geometry() {
        let p = window(0.0);
        assert!((p.area - 3.0).abs() < 1e-12);
        assert!((p.normal.dot(Vec3::new(0.0, -1.0, 0.0)) - 1.0).abs() < 1e-12);
        assert!((p.centroid - Vec3::new(1.0, 0.0, 1.75)).length() < 1e-12);
        assert!(p.para.is_some() && pentagon().para.is_none());
        // The part above z = 2 of the rectangle: 2 x 0.5, centred at z = 2.25.
        let (a, c) = p.usable(Part::Above(2.0));
        assert!((a - 1.0).abs() < 1e-12 && (c.z - 2.25).abs() < 1e-12);
        let (a, _) = pentagon().usable(Part::Below(1.0));
        let (b, _) = pentagon().usable(Part::Above(1.0));
        assert!((a + b - pentagon().area).abs() < 1e-12);
    }

    /// Stratified quadrature over the sphere of `f(dir)`.
    fn sphere_integral(m: usize, f: impl Fn(Vec3) -> f64) -> f64 {
        let mut sum = 0.0;
        for i in 0..m {
            for j in 0..m {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / m as f64;
                let phi = 2.0 * PI * (j as f64 + 0.5) / m as f64;
                let r = (1.0 - z * z).max(0.0).sqrt();
                sum += f(Vec3::new(r * phi.cos(), r * phi.sin(), z));
            }
        }
        sum * 4.0 * PI / (m * m) as f64
    }

    /// Both strategies' densities integrate to 1 over the sphere (proper densities), and
    /// their samples reproduce them: E[1/pdf] is the solid angle they cover. For plain
    /// panes and for rising-only ones (sky above, the falling continuation below), for a
    /// parallelogram and a pentagon.
    #[test]
    fn densities_are_normalised_and_match_their_samples() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        let x = Vec3::new(1.5, -2.0, 1.3);
        let n = Vec3::new(0.0, 0.0, 1.0);
        for rising in [false, true] {
            let mut a = window(0.0);
            let mut b = pentagon();
            for p in [&mut a, &mut b] {
                p.set_inside(1.0); // room on the front (-y) side
                p.set_rising_only(rising);
            }
            let ports = Portals::new(vec![a, b]);
            let at = ports.at(x, n).unwrap();
            type Density<'a> = Box<dyn Fn(Vec3) -> f64 + 'a>;
            let strategies: Vec<(&str, Density)> = if rising {
                vec![
                    ("sky", Box::new(|d| at.pdf(d))),
                    ("fall", Box::new(|d| at.fall_pdf(d))),
                ]
            } else {
                vec![("sky", Box::new(|d| at.pdf(d)))]
            };
            assert_eq!(at.fall_share() > 0.0, rising);
            for (name, pdf) in &strategies {
                let integral = sphere_integral(500, pdf);
                assert!(
                    (integral - 1.0).abs() < 0.01,
                    "{name} rising {rising}: {integral}"
                );
                let omega = sphere_integral(500, |d| f64::from(u8::from(pdf(d) > 0.0)));
                let k = 200_000;
                let mut inv = 0.0;
                for _ in 0..k {
                    let (u, s, t) = (rng.random(), rng.random(), rng.random());
                    let (d, p) = if *name == "sky" {
                        at.sample(u, s, t).unwrap()
                    } else {
                        let d = at.sample_fall(u, s, t).unwrap();
                        (d, at.fall_pdf(d))
                    };
                    assert!((pdf(d) - p).abs() <= 1e-9 * p);
                    if rising {
                        assert_eq!(d.z > 0.0, *name == "sky");
                    }
                    inv += 1.0 / p;
                }
                inv /= k as f64;
                assert!(
                    (inv - omega).abs() < 0.01 * omega,
                    "{name}: {inv} vs {omega}"
                );
            }
        }
    }

    #[test]
    fn the_outside_half_space_uses_no_pane() {
        let mut a = window(0.0);
        a.set_inside(1.0);
        let ports = Portals::new(vec![a]);
        let outside = Vec3::new(1.0, 2.0, 1.5);
        let n = Vec3::new(0.0, -1.0, 0.0);
        assert!(ports.sample(outside, n, 0.3, 0.4, 0.5).is_none());
        assert_eq!(ports.pdf(outside, n, Vec3::new(0.0, -1.0, 0.0)), 0.0);
    }
}
