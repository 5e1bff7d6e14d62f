//! Windows per wall (seed chapter 4.3.1.3): candidate patches from holes in the wall's
//! Delaunay triangulation, ranking, and regularised outlines.
//!
//! For each wall: the points within `band` of its plane and inside its polygon are projected
//! to the plane (with samples along the wall's outline, so that an opening touching the edge
//! is still enclosed) and Delaunay-triangulated (`spade`). A *hole* is a triangle whose empty
//! circumcircle is wider than `edge_threshold` (seed: 8 cm; see [`hole_test`] for why not the
//! seed's all-edges test); edge-connected holes form *regions*; regions
//! above `min_area` (seed: 10 cm²) are *candidates*, numbered per wall by rank.
//!
//! What the stations saw (issue 19): the old ranking wanted points behind the wall (reveals,
//! the outside) as proof of an opening, and real glazing is often flush with the wall, so
//! scans show no reveal and the beams that pass the glass return nothing. Evidence that does
//! not depend on reveals is the scan's free space ([`super::visibility`]; Adán & Huber 2011,
//! Xiong et al. 2013): each triangle of a region is tested, at its centroid, against every
//! station. It is *open* when a station that faces it has a clear line of sight to it (the
//! scanner looked there and the wall did not answer) or when a return beyond the wall plane
//! was measured along a beam crossing it on a clear line of sight (reveals, the outside, the
//! few stray returns through glazing); otherwise it is *occluded* (every facing station's
//! view ends on clutter or another wall first: an occlusion shadow) or *unseen*. A region is
//! split into edge-connected parts of one label, so that a shadow touching a window stays
//! out of it; the parts above `min_area` are the *candidates*, numbered per wall by rank.
//!
//! `--auto` (the seed's user picks with a lasso; we decide on what the user looks at) takes
//! an open candidate of at least `auto_min_area` whose sill is above the floor (a gap
//! reaching the floor is a door or lies under furniture), at least `auto_min_side` wide and
//! high, and filling at least `auto_min_fill` of its bounding rectangle; each candidate
//! carries the reason for the decision (JSON summary, review pictures). Candidates are
//! ranked by area, rectangularity, being open, sill above the floor and returns beyond.
//!
//! Reveal depth: reveal points lie on the opening's edges seen along the wall normal; the
//! 98th percentile of the depths (within 1 m) of the points behind the wall there, i.e. where
//! the reveal meets the frame. An open candidate without a reveal has flush glazing (depth 0).
//!
//! Regularisation: a region whose rectangularity is at least `rect_fit` becomes a rectangle in
//! the wall frame (u horizontal, v up); otherwise the seed's more robust symmetric prior: a
//! polygon symmetric about the region's vertical mid-line whose half-width at `levels` + 1
//! heights (bottom and top included) is the widest extent of the region there (this keeps
//! arches). The rectangle's sides, and the symmetric outline's sides and bottom, are placed at
//! the rim samples nearest the opening ([`rim_edges`]) rather than at the extreme ones.

use super::cloud::PointCloud;
use super::model::{FaceKind, Frame, Opening};
use super::shell::Shell;
use super::visibility::{Sight, Views};
use crate::error::{Error, Result};
use crate::geometry::Vec3;
use spade::{DelaunayTriangulation, Point2, PositionInTriangulation, Triangulation};
use std::collections::HashMap;

/// Window detection settings (defaults: seed chapter 4 where it gives them).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct OpeningParams {
    /// Hole triangles have all edges longer than this (seed: 0.08 m).
    pub edge_threshold: f64,
    /// Regions smaller than this are no candidates (seed: 10 cm² = 0.001 m²).
    pub min_area: f64,
    /// Points within this distance of the wall plane belong to the wall.
    pub band: f64,
    /// `--auto`: smallest window taken, m².
    pub auto_min_area: f64,
    /// `--auto`: smallest width and height, m.
    pub auto_min_side: f64,
    /// `--auto`: smallest rectangularity (area over bounding rectangle).
    pub auto_min_fill: f64,
    /// Rectangularity from which the outline becomes a rectangle.
    pub rect_fit: f64,
    /// Heights of the symmetric outline.
    pub levels: usize,
    /// Openings keep this distance from the wall's edges, m.
    pub margin: f64,
}

impl Default for OpeningParams {
    fn default() -> Self {
        OpeningParams {
            edge_threshold: 0.08,
            min_area: 0.001,
            band: 0.03,
            auto_min_area: 0.15,
            // The smallest windows of dwellings (toilet, stair lights) are about 0.3 x 0.5 m;
            // narrower open gaps are the slivers an occluder's edge or a corner leaves.
            auto_min_side: 0.2,
            // Rectangles measure 0.96-0.99 and arches 0.9 (`rect_fit` below); a diagonal
            // sliver along a shadow's edge fills less than half its rectangle.
            auto_min_fill: 0.5,
            // Rectangles measure 0.96-0.99 on simulated scans at 4 cm spacing; a semicircular
            // arch over a 1.2 x 1.1 m rectangle measures 0.92.
            rect_fit: 0.94,
            levels: 16,
            margin: 0.02,
        }
    }
}

/// What the stations saw of a candidate (see [`super::visibility`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum View {
    /// A station had a clear line of sight and got no return from the wall (or returns from
    /// beyond it): the wall is not there.
    Open,
    /// Every station facing it was blocked by clutter or the shell: an occlusion shadow.
    Occluded,
    /// No station faced it (behind all of them, too oblique or out of range).
    Unseen,
}

/// A window candidate on one wall.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Candidate {
    /// 1-based number on its wall (by rank).
    pub id: usize,
    pub area: f64,
    /// Bounding rectangle in the wall frame: u0, v0, u1, v1.
    pub rect: [f64; 4],
    pub rectangularity: f64,
    pub view: View,
    /// Stations facing it, and of those the stations with a clear line of sight (means over
    /// its area).
    pub facing: f64,
    pub clear: f64,
    /// Returns beyond the wall plane whose beams crossed it here (reveals, the outside, stray
    /// returns through glazing), confirmed up to three per triangle.
    pub through: usize,
    pub score: f64,
    pub auto: bool,
    /// Why `--auto` takes it or leaves it.
    pub reason: String,
    /// Reveal depth measured from the points behind the wall around the candidate, metres.
    pub depth: Option<f64>,
    /// Regularised outline in the wall frame, counter-clockwise.
    pub outline: Vec<[f64; 2]>,
    /// Region triangles (for the review picture).
    #[serde(skip)]
    pub triangles: Vec<[[f64; 2]; 3]>,
}

/// Which candidates become windows.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Selection {
    /// None (the shell only; the review shows the candidates).
    #[default]
    None,
    /// The automatic ranking.
    Auto,
    /// Candidate numbers per wall name (`wall3:2,5`).
    Explicit(Vec<(String, Vec<usize>)>),
}

impl Selection {
    /// Parse `--windows` values: `wall3:2,5` (repeatable).
    pub fn parse(specs: &[String]) -> Result<Selection> {
        let mut out = Vec::new();
        for s in specs {
            let (wall, ids) = s.split_once(':').ok_or_else(|| {
                Error::Usage(format!(
                    "--windows '{s}'; expected WALL:N[,N...] such as wall3:2,5"
                ))
            })?;
            let ids = ids
                .split(',')
                .map(|x| x.trim().parse::<usize>())
                .collect::<std::result::Result<Vec<_>, _>>()
                .map_err(|_| {
                    Error::Usage(format!(
                        "--windows '{s}'; expected candidate numbers after ':'"
                    ))
                })?;
            out.push((wall.to_string(), ids));
        }
        Ok(Selection::Explicit(out))
    }
}

/// Point in polygon by the crossing-number (even-odd) rule.
pub(crate) fn in_polygon(poly: &[[f64; 2]], q: [f64; 2]) -> bool {
    let mut inside = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a[1] > q[1]) != (b[1] > q[1]) {
            let x = a[0] + (q[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if q[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// Candidates of every wall of the shell (empty lists for floors and ceilings). `strays` are
/// the returns the outlier filter removed (isolated points beyond glazing among them);
/// `views` holds the stations and what blocks their lines of sight.
pub fn detect_all(
    shell: &Shell,
    cloud: &PointCloud,
    strays: &PointCloud,
    views: &Views,
    spacing: f64,
    p: &OpeningParams,
) -> Vec<Vec<Candidate>> {
    shell
        .model
        .faces
        .iter()
        .enumerate()
        .map(|(fi, f)| {
            if f.kind != FaceKind::Wall {
                return vec![];
            }
            detect_wall(fi, &f.polygon, cloud, strays, views, spacing, p)
        })
        .collect()
}

/// Stations to try for a return: its own when the cloud says which, else all of them.
fn stations_of(c: &PointCloud, i: usize, n: usize) -> std::ops::Range<usize> {
    match c.station_of.as_ref().and_then(|s| s.get(i)) {
        Some(&s) if (s as usize) < n => s as usize..s as usize + 1,
        _ => 0..n,
    }
}

/// Candidates of wall `face`, whose polygon (counter-clockwise seen from inside) is
/// `polygon`.
pub fn detect_wall(
    face: usize,
    polygon: &[Vec3],
    cloud: &PointCloud,
    strays: &PointCloud,
    views: &Views,
    spacing: f64,
    p: &OpeningParams,
) -> Vec<Candidate> {
    let fr = Frame::of_polygon(polygon);
    let wall: Vec<[f64; 2]> = polygon.iter().map(|&v| fr.to_2d(v)).collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for q in &wall {
        for k in 0..2 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
        }
    }
    let mut on = Vec::new();
    let mut behind = Vec::new();
    for pt in &cloud.points {
        let v = Vec3::from(*pt);
        let h = fr.height(v);
        if h.abs() > 2.0 || h > p.band {
            continue;
        }
        let q = fr.to_2d(v);
        if q[0] < lo[0] - 0.05 || q[0] > hi[0] + 0.05 || q[1] < lo[1] - 0.05 || q[1] > hi[1] + 0.05
        {
            continue;
        }
        if h.abs() <= p.band {
            if in_polygon(&wall, q) {
                on.push(q);
            }
        } else {
            behind.push([q[0], q[1], -h]);
        }
    }
    if on.len() < 3 {
        return vec![];
    }
    // Outline samples so that holes at the wall's edge are enclosed.
    let step = spacing.max(0.01);
    let n = wall.len();
    for i in 0..n {
        let (a, b) = (wall[i], wall[(i + 1) % n]);
        let len = dist2(a, b).sqrt();
        let k = (len / step).ceil().max(1.0) as usize;
        for j in 0..k {
            let t = j as f64 / k as f64;
            on.push([a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]);
        }
    }
    let verts: Vec<Point2<f64>> = on.iter().map(|q| Point2::new(q[0], q[1])).collect();
    let Ok(tri) = DelaunayTriangulation::<Point2<f64>>::bulk_load(verts) else {
        return vec![];
    };
    // Hole triangles (in the triangulation's face order, so runs are reproducible), their
    // positions by face index, and their hole neighbours.
    let t2 = p.edge_threshold * p.edge_threshold;
    let mut tris: Vec<[[f64; 2]; 3]> = Vec::new();
    let mut pos: HashMap<usize, usize> = HashMap::new();
    let mut faces = Vec::new();
    for f in tri.inner_faces() {
        let v = f.vertices().map(|v| {
            let q = v.position();
            [q.x, q.y]
        });
        if hole_test(&v, t2) && in_polygon(&wall, centroid(&v)) {
            pos.insert(f.fix().index(), tris.len());
            tris.push(v);
            faces.push(f);
        }
    }
    let neighbours: Vec<Vec<usize>> = faces
        .iter()
        .map(|f| {
            f.adjacent_edges()
                .iter()
                .filter_map(|e| e.rev().face().as_inner())
                .filter_map(|nb| pos.get(&nb.fix().index()).copied())
                .collect()
        })
        .collect();
    // Regions: edge-connected hole triangles (all of them, or those with one label).
    let components = |members: &[usize], same: &dyn Fn(usize, usize) -> bool| {
        let mut inside = vec![false; tris.len()];
        for &m in members {
            inside[m] = true;
        }
        let mut seen = vec![false; tris.len()];
        let mut out: Vec<Vec<usize>> = Vec::new();
        for &start in members {
            if seen[start] {
                continue;
            }
            seen[start] = true;
            let mut stack = vec![start];
            let mut comp = vec![];
            while let Some(k) = stack.pop() {
                comp.push(k);
                for &nb in &neighbours[k] {
                    if inside[nb] && !seen[nb] && same(k, nb) {
                        seen[nb] = true;
                        stack.push(nb);
                    }
                }
            }
            comp.sort_unstable();
            out.push(comp);
        }
        out
    };
    let all: Vec<usize> = (0..tris.len()).collect();
    let regions: Vec<Vec<usize>> = components(&all, &|_, _| true)
        .into_iter()
        .filter(|r| r.iter().map(|&k| tri_area(&tris[k])).sum::<f64>() >= p.min_area)
        .collect();
    // What the stations saw of each triangle of a candidate region, at its centroid.
    let mut sight = vec![Sight::default(); tris.len()];
    for r in &regions {
        for &k in r {
            sight[k] = views.sight(fr.to_3d(centroid(&tris[k])), face);
        }
    }
    // Returns beyond the wall whose beams crossed its plane in a hole triangle, with a clear
    // line of sight to the crossing (a return behind clutter is noise, not a view). Confirmed
    // up to three per triangle: enough to open it, and the line-of-sight tests stay few.
    let boxes: Vec<[f64; 4]> = regions
        .iter()
        .map(|r| bbox(r.iter().map(|&k| &tris[k])))
        .collect();
    let mut through = vec![0usize; tris.len()];
    for c in [cloud, strays] {
        for (i, pt) in c.points.iter().enumerate() {
            let v = Vec3::from(*pt);
            let hp = fr.height(v);
            if hp >= -p.band {
                continue;
            }
            for si in stations_of(c, i, views.stations.len()) {
                let st = views.stations[si];
                let hs = fr.height(st);
                if hs <= 0.0 {
                    continue;
                }
                let q = fr.to_2d(st + (v - st) * (hs / (hs - hp)));
                if !boxes
                    .iter()
                    .any(|b| q[0] >= b[0] && q[0] <= b[2] && q[1] >= b[1] && q[1] <= b[3])
                {
                    continue;
                }
                let fi = match tri.locate(Point2::new(q[0], q[1])) {
                    PositionInTriangulation::OnFace(f) => Some(f.index()),
                    PositionInTriangulation::OnEdge(e) => tri
                        .directed_edge(e)
                        .face()
                        .as_inner()
                        .map(|f| f.fix().index()),
                    _ => None,
                };
                let Some(&k) = fi.and_then(|f| pos.get(&f)) else {
                    continue;
                };
                if through[k] < 3 && views.clear(st, v, face) {
                    through[k] += 1;
                    break;
                }
            }
        }
    }
    let open = |k: usize| sight[k].clear > 0 || through[k] > 0;
    let mut cands = Vec::new();
    for r in &regions {
        for members in components(r, &|a, b| open(a) == open(b)) {
            let ts: Vec<[[f64; 2]; 3]> = members.iter().map(|&k| tris[k]).collect();
            let area: f64 = ts.iter().map(tri_area).sum();
            if area < p.min_area {
                continue;
            }
            let is_open = open(members[0]);
            let weighted = |f: &dyn Fn(usize) -> f64| {
                members
                    .iter()
                    .map(|&k| f(k) * tri_area(&tris[k]))
                    .sum::<f64>()
                    / area
            };
            let facing = weighted(&|k| sight[k].facing as f64);
            let clear = weighted(&|k| sight[k].clear as f64);
            let faced = weighted(&|k| if sight[k].facing > 0 { 1.0 } else { 0.0 });
            let through: usize = members.iter().map(|&k| through[k]).sum();
            let view = if is_open {
                View::Open
            } else if faced >= 0.5 {
                View::Occluded
            } else {
                View::Unseen
            };
            cands.push(candidate(
                &ts, area, view, facing, clear, through, &behind, lo, spacing, p,
            ));
        }
    }
    cands.sort_by(|x, y| y.score.total_cmp(&x.score));
    for (i, c) in cands.iter_mut().enumerate() {
        c.id = i + 1;
    }
    // Keep outlines inside the wall with a margin.
    for c in &mut cands {
        for q in &mut c.outline {
            q[0] = q[0].clamp(lo[0] + p.margin, hi[0] - p.margin);
            q[1] = q[1].clamp(lo[1] + p.margin, hi[1] - p.margin);
        }
    }
    cands
}

/// One candidate from its triangles and evidence: shape, reveal depth, the `--auto` decision
/// and its reason, the rank score. `floor` is the wall's lowest v (the floor line).
#[allow(clippy::too_many_arguments)]
fn candidate(
    tris: &[[[f64; 2]; 3]],
    area: f64,
    view: View,
    facing: f64,
    clear: f64,
    through: usize,
    behind: &[[f64; 3]],
    floor: [f64; 2],
    spacing: f64,
    p: &OpeningParams,
) -> Candidate {
    let [a0, a1, b0, b1] = bbox(tris.iter());
    let (a, b) = ([a0, a1], [b0, b1]);
    let rect_area = (b[0] - a[0]) * (b[1] - a[1]);
    let rectangularity = if rect_area > 0.0 {
        area / rect_area
    } else {
        0.0
    };
    // Reveal depth. Reveals are perpendicular to the wall, so their points lie, seen along
    // the wall normal, on the opening's edges; returns through the glazing (the outside,
    // strays) spread over its inside. Points within 1.5 spacings of the rectangle's edges
    // and 1 m of the wall count, and a reveal needs a fifth of a sampled perimeter of them;
    // its depth is where it meets the frame, their 98th percentile.
    let rim = 1.5 * spacing;
    let edge = |q: &[f64; 3]| {
        let inside =
            q[0] > a[0] - rim && q[0] < b[0] + rim && q[1] > a[1] - rim && q[1] < b[1] + rim;
        let core = q[0] > a[0] + rim && q[0] < b[0] - rim && q[1] > a[1] + rim && q[1] < b[1] - rim;
        inside && !core
    };
    let mut depths: Vec<f64> = behind
        .iter()
        .filter(|q| edge(q))
        .map(|q| q[2])
        .filter(|&d| d <= 1.0)
        .collect();
    depths.sort_by(f64::total_cmp);
    let perimeter = 2.0 * ((b[0] - a[0]) + (b[1] - a[1]));
    let needed = (0.2 * perimeter / spacing.max(1e-3)).max(10.0);
    let depth = if depths.len() as f64 >= needed {
        Some(depths[(depths.len() * 98 / 100).min(depths.len() - 1)])
    } else if view == View::Open {
        // Open, and no reveal where the stations looked: the glazing is flush with the wall.
        Some(0.0)
    } else {
        None
    };
    // Edges from the rim points. A symmetric outline (an arch) has straight sides in its
    // lower half only, and its top is a curve, not an edge: it keeps the triangles' extent.
    let rectangle = rectangularity >= p.rect_fit;
    let straight = if rectangle { b[1] } else { 0.5 * (a[1] + b[1]) };
    let (ra, mut rb) = rim_edges(tris, a, b, straight, spacing);
    if !rectangle {
        rb[1] = b[1];
    }
    let outline = regularise(tris, a, b, rectangularity, p)
        .into_iter()
        .map(|q| [q[0].clamp(ra[0], rb[0]), q[1].clamp(ra[1], rb[1])])
        .collect();
    let touches_floor = a[1] < floor[1] + 0.05;
    let (w, h) = (b[0] - a[0], b[1] - a[1]);
    let reason = match view {
        View::Occluded => "hidden from every station facing it: an occlusion shadow".to_string(),
        View::Unseen => "no station faced it closely enough to tell".to_string(),
        View::Open if area < p.auto_min_area => {
            format!("open, but smaller than {} m2", p.auto_min_area)
        }
        View::Open if touches_floor => {
            "open, but reaches the floor (a door, or a gap under furniture)".to_string()
        }
        View::Open if w.min(h) < p.auto_min_side => {
            format!("open, but narrower than {} m", p.auto_min_side)
        }
        View::Open if rectangularity < p.auto_min_fill => format!(
            "open, but fills only {:.0} % of its bounding rectangle",
            100.0 * rectangularity
        ),
        View::Open => format!(
            "window: a clear line of sight from {clear:.1} station(s), {through} return(s) beyond"
        ),
    };
    let auto = reason.starts_with("window");
    let score = area.sqrt()
        * rectangularity.max(0.2)
        * if view == View::Open { 1.0 } else { 0.1 }
        * if touches_floor { 0.5 } else { 1.0 }
        * if through > 0 { 1.25 } else { 1.0 };
    Candidate {
        id: 0,
        area,
        rect: [a[0], a[1], b[0], b[1]],
        rectangularity,
        view,
        facing,
        clear,
        through,
        score,
        auto,
        reason,
        depth,
        outline,
        triangles: tris.to_vec(),
    }
}

fn centroid(t: &[[f64; 2]; 3]) -> [f64; 2] {
    [
        (t[0][0] + t[1][0] + t[2][0]) / 3.0,
        (t[0][1] + t[1][1] + t[2][1]) / 3.0,
    ]
}

/// Bounding rectangle u0, v0, u1, v1 of some triangles.
fn bbox<'a>(tris: impl Iterator<Item = &'a [[f64; 2]; 3]>) -> [f64; 4] {
    let (mut a, mut b) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for t in tris {
        for q in t {
            for k in 0..2 {
                a[k] = a[k].min(q[k]);
                b[k] = b[k].max(q[k]);
            }
        }
    }
    [a[0], a[1], b[0], b[1]]
}

/// Is this Delaunay triangle part of a gap? Its empty circumcircle (the Delaunay property)
/// is wider than the threshold. The seed's test, all three edges longer than the threshold,
/// misses the rim of every dense hole: the fan triangles there join two neighbouring rim
/// points by one short edge. The empty-disc test is the alpha-shape criterion (Edelsbrunner &
/// Mücke 1994) with alpha = threshold / 2, and it agrees with the seed's inside the gap.
fn hole_test(v: &[[f64; 2]; 3], t2: f64) -> bool {
    let (a2, b2, c2) = (dist2(v[0], v[1]), dist2(v[1], v[2]), dist2(v[2], v[0]));
    let area = tri_area(v);
    if area <= 1e-15 {
        return a2.max(b2).max(c2) > t2;
    }
    // Circumradius R = abc / (4 area); the disc's diameter 2R against the threshold.
    let r2 = a2 * b2 * c2 / (16.0 * area * area);
    4.0 * r2 > t2
}

fn tri_area(t: &[[f64; 2]; 3]) -> f64 {
    0.5 * ((t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]))
        .abs()
}

/// The opening's edges from the rim points along each side of the bounding rectangle `a..b`.
/// The rectangle passes through the rim points deepest in the wall, up to a point spacing
/// beyond the edge (the wall's last samples lie anywhere within a spacing of it), which made
/// every window 3-6 % too large, more where a few wall samples are missing along the edge
/// (notches one or two spacings deep). Each side instead takes the rim points within four
/// spacings of it (corners left out) and the 90th percentile of their coordinate towards
/// the opening: the samples nearest the edge, robust to notches and to a stray point.
/// The sides are measured below `straight` only.
fn rim_edges(
    tris: &[[[f64; 2]; 3]],
    a: [f64; 2],
    b: [f64; 2],
    straight: f64,
    spacing: f64,
) -> ([f64; 2], [f64; 2]) {
    let mut verts: Vec<[f64; 2]> = tris.iter().flatten().copied().collect();
    verts.sort_by(|x, y| x[0].total_cmp(&y[0]).then(x[1].total_cmp(&y[1])));
    verts.dedup();
    let band = 4.0 * spacing;
    let (mut ra, mut rb) = (a, b);
    // Axis k's low and high sides; the other axis j must be away from the corners.
    for k in 0..2 {
        let j = 1 - k;
        let top = if k == 0 { straight.min(b[j]) } else { b[j] };
        let away = |q: &[f64; 2]| q[j] > a[j] + band && q[j] < top - band;
        let mut low: Vec<f64> = verts
            .iter()
            .filter(|q| away(q) && q[k] < a[k] + band)
            .map(|q| q[k])
            .collect();
        let mut high: Vec<f64> = verts
            .iter()
            .filter(|q| away(q) && q[k] > b[k] - band)
            .map(|q| -q[k])
            .collect();
        for (side, out, sign) in [(&mut low, &mut ra[k], 1.0), (&mut high, &mut rb[k], -1.0)] {
            if side.len() >= 3 {
                side.sort_by(f64::total_cmp);
                *out = sign * side[(side.len() * 9 / 10).min(side.len() - 1)];
            }
        }
    }
    if ra[0] >= rb[0] || ra[1] >= rb[1] {
        return (a, b);
    }
    (ra, rb)
}

/// The regularised outline (see the module documentation).
fn regularise(
    tris: &[[[f64; 2]; 3]],
    a: [f64; 2],
    b: [f64; 2],
    rectangularity: f64,
    p: &OpeningParams,
) -> Vec<[f64; 2]> {
    if rectangularity >= p.rect_fit {
        return vec![[a[0], a[1]], [b[0], a[1]], [b[0], b[1]], [a[0], b[1]]];
    }
    let uc = 0.5 * (a[0] + b[0]);
    let levels = p.levels.max(2);
    let h = (b[1] - a[1]) / levels as f64;
    // Half-widths at the band boundaries, the bottom and the top included (just inside them):
    // the widest extent of the triangles cut there. Placing them at the bands' middles gave an
    // arch a flat top as wide as the arch a band below its apex (1-2 % too much area).
    let heights: Vec<f64> = (0..=levels)
        .map(|k| (a[1] + k as f64 * h).clamp(a[1] + 0.02 * h, b[1] - 0.02 * h))
        .collect();
    let mut hw = vec![0.0f64; heights.len()];
    for t in tris {
        for (w, &y) in hw.iter_mut().zip(&heights) {
            for i in 0..3 {
                let (p0, p1) = (t[i], t[(i + 1) % 3]);
                if (p0[1] - y) * (p1[1] - y) <= 0.0 && p0[1] != p1[1] {
                    let x = p0[0] + (y - p0[1]) * (p1[0] - p0[0]) / (p1[1] - p0[1]);
                    *w = w.max((x - uc).abs());
                }
            }
        }
    }
    let ys = (0..=levels).map(|k| a[1] + k as f64 * h);
    let right: Vec<[f64; 2]> = hw.iter().zip(ys).map(|(w, y)| [uc + w, y]).collect();
    let mut out = vec![[uc - hw[0], a[1]]];
    out.extend(right.iter().copied());
    out.extend(right.iter().rev().map(|q| [2.0 * uc - q[0], q[1]]));
    out.pop();
    out.dedup_by(|x, y| dist2(*x, *y) < 1e-12);
    out
}

/// The openings the selection asks for, as model openings.
/// With `auto_depth`, each opening takes its candidate's measured reveal depth.
pub fn choose(
    shell: &Shell,
    cands: &[Vec<Candidate>],
    sel: &Selection,
    auto_depth: bool,
) -> Result<Vec<Opening>> {
    let mut out = Vec::new();
    let mut push = |fi: usize, c: &Candidate| {
        let f = &shell.model.faces[fi];
        let fr = Frame::of_polygon(&f.polygon);
        // Overlapping picks: keep the first.
        let taken = out.iter().any(|o: &Opening| {
            o.face == fi && {
                let q: Vec<[f64; 2]> = o.outline.iter().map(|&v| fr.to_2d(v)).collect();
                let (u0, u1) = q
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                        (a.min(x[0]), b.max(x[0]))
                    });
                u0 < c.rect[2] && u1 > c.rect[0]
            }
        });
        if !taken {
            out.push(Opening {
                face: fi,
                name: format!("{}_window{}", f.name, c.id),
                outline: c.outline.iter().map(|&q| fr.to_3d(q)).collect(),
                depth: if auto_depth { c.depth } else { None },
            });
        }
    };
    match sel {
        Selection::None => {}
        Selection::Auto => {
            for (fi, cs) in cands.iter().enumerate() {
                for c in cs.iter().filter(|c| c.auto) {
                    push(fi, c);
                }
            }
        }
        Selection::Explicit(list) => {
            for (wall, ids) in list {
                let fi = shell.model.faces.iter().position(|f| &f.name == wall).ok_or_else(|| {
                    Error::Usage(format!(
                        "--windows names '{wall}', which is not a wall of this reconstruction; walls: {}",
                        shell.model.faces.iter().filter(|f| f.kind == FaceKind::Wall).map(|f| f.name.as_str()).collect::<Vec<_>>().join(", ")
                    ))
                })?;
                for id in ids {
                    let c = cands[fi].iter().find(|c| c.id == *id).ok_or_else(|| {
                        Error::Usage(format!(
                            "--windows {wall}:{id}: {wall} has {} candidates",
                            cands[fi].len()
                        ))
                    })?;
                    push(fi, c);
                }
            }
        }
    }
    Ok(out)
}
