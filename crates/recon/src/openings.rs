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
//! Ranking (the seed's user picks them with a lasso; we score what the user looks at): area,
//! rectangularity (region area over its bounding rectangle), whether the scanner saw *through*
//! the hole (points behind the wall plane inside the candidate's rectangle: reveals and the
//! outside), and whether something in front explains the gap (occlusion shadows of furniture:
//! points up to 1.5 m in front). `--auto` takes candidates of at least `auto_min_area` with
//! evidence behind and little in front.
//!
//! Reveal depth: the 98th percentile of the depths of the points behind the wall (within 1 m)
//! around the candidate, i.e. where the reveal meets the frame.
//!
//! Regularisation: a region whose rectangularity is at least `rect_fit` becomes its bounding
//! rectangle in the wall frame (u horizontal, v up); otherwise the seed's more robust
//! symmetric prior: a polygon symmetric about the region's vertical mid-line whose half-width
//! at each of `levels` heights is the widest extent of the region there (this keeps arches).

use super::cloud::PointCloud;
use super::model::{FaceKind, Frame, Opening};
use super::shell::Shell;
use crate::error::{Error, Result};
use crate::geometry::Vec3;
use spade::{DelaunayTriangulation, Point2, Triangulation};
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
            // Rectangles measure 0.96-0.99 on simulated scans at 4 cm spacing; a semicircular
            // arch over a 1.2 x 1.1 m rectangle measures 0.92.
            rect_fit: 0.94,
            levels: 16,
            margin: 0.02,
        }
    }
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
    /// Points behind the wall inside the rectangle, per expected point of its perimeter band.
    pub behind: f64,
    /// Points in front (occluders) inside the rectangle, per expected point of its area.
    pub front: f64,
    pub score: f64,
    pub auto: bool,
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

fn in_polygon(poly: &[[f64; 2]], q: [f64; 2]) -> bool {
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

/// Candidates of every wall of the shell (empty lists for floors and ceilings).
pub fn detect_all(
    shell: &Shell,
    cloud: &PointCloud,
    spacing: f64,
    p: &OpeningParams,
) -> Vec<Vec<Candidate>> {
    shell
        .model
        .faces
        .iter()
        .map(|f| {
            if f.kind != FaceKind::Wall {
                return vec![];
            }
            detect_wall(&f.polygon, cloud, spacing, p)
        })
        .collect()
}

/// Candidates of one wall polygon (counter-clockwise seen from inside).
pub fn detect_wall(
    polygon: &[Vec3],
    cloud: &PointCloud,
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
    let mut front = Vec::new();
    for pt in &cloud.points {
        let v = Vec3::from(*pt);
        let h = fr.height(v);
        if h.abs() > 2.0 {
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
        } else if h < 0.0 {
            behind.push([q[0], q[1], -h]);
        } else if h < 1.5 {
            front.push(q);
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
    let t2 = p.edge_threshold * p.edge_threshold;
    let mut hole: HashMap<usize, [[f64; 2]; 3]> = HashMap::new();
    for f in tri.inner_faces() {
        let v = f.vertices().map(|v| {
            let q = v.position();
            [q.x, q.y]
        });
        if hole_test(&v, t2) {
            let c = [
                (v[0][0] + v[1][0] + v[2][0]) / 3.0,
                (v[0][1] + v[1][1] + v[2][1]) / 3.0,
            ];
            if in_polygon(&wall, c) {
                hole.insert(f.fix().index(), v);
            }
        }
    }
    // Regions: edge-connected hole triangles.
    let mut region: HashMap<usize, usize> = HashMap::new();
    let mut regions: Vec<Vec<usize>> = Vec::new();
    let mut keys: Vec<usize> = hole.keys().copied().collect();
    keys.sort();
    for &start in &keys {
        if region.contains_key(&start) {
            continue;
        }
        let r = regions.len();
        let mut stack = vec![start];
        region.insert(start, r);
        let mut members = vec![];
        while let Some(fi) = stack.pop() {
            members.push(fi);
            let Some(f) = tri.inner_faces().find(|f| f.fix().index() == fi) else {
                continue;
            };
            for e in f.adjacent_edges() {
                if let Some(nb) = e.rev().face().as_inner() {
                    let ni = nb.fix().index();
                    if hole.contains_key(&ni) && !region.contains_key(&ni) {
                        region.insert(ni, r);
                        stack.push(ni);
                    }
                }
            }
        }
        regions.push(members);
    }
    let density = cloud_density(spacing);
    let mut cands = Vec::new();
    for members in regions {
        let tris: Vec<[[f64; 2]; 3]> = members.iter().map(|i| hole[i]).collect();
        let area: f64 = tris.iter().map(tri_area).sum();
        if area < p.min_area {
            continue;
        }
        let (mut a, mut b) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for t in &tris {
            for q in t {
                for k in 0..2 {
                    a[k] = a[k].min(q[k]);
                    b[k] = b[k].max(q[k]);
                }
            }
        }
        let rect_area = (b[0] - a[0]) * (b[1] - a[1]);
        let rectangularity = if rect_area > 0.0 {
            area / rect_area
        } else {
            0.0
        };
        let grow = 2.0 * spacing;
        let inside = |q: &&[f64; 3]| {
            q[0] > a[0] - grow && q[0] < b[0] + grow && q[1] > a[1] - grow && q[1] < b[1] + grow
        };
        let perim = 2.0 * ((b[0] - a[0]) + (b[1] - a[1]));
        // Depth: the deepest reveal points (98th percentile of depths within 1 m).
        let mut depths: Vec<f64> = behind
            .iter()
            .filter(inside)
            .map(|q| q[2])
            .filter(|&d| d <= 1.0)
            .collect();
        depths.sort_by(f64::total_cmp);
        let depth =
            (depths.len() >= 10).then(|| depths[(depths.len() * 98 / 100).min(depths.len() - 1)]);
        let n_behind = behind.iter().filter(inside).count() as f64;
        let n_front = front
            .iter()
            .filter(|q| q[0] > a[0] && q[0] < b[0] && q[1] > a[1] && q[1] < b[1])
            .count() as f64;
        let behind_score = n_behind / (perim / spacing.max(1e-3)).max(1.0);
        let front_score = n_front / (area * density).max(1.0);
        let outline = regularise(&tris, a, b, rectangularity, p);
        let touches_floor = a[1] < lo[1] + 0.05;
        let score = area.sqrt()
            * rectangularity.max(0.2)
            * if behind_score > 0.2 { 1.0 } else { 0.3 }
            * if front_score < 0.2 { 1.0 } else { 0.2 }
            * if touches_floor { 0.5 } else { 1.0 };
        let auto =
            area >= p.auto_min_area && behind_score > 0.2 && front_score < 0.2 && !touches_floor;
        cands.push(Candidate {
            id: 0,
            area,
            rect: [a[0], a[1], b[0], b[1]],
            rectangularity,
            behind: behind_score,
            front: front_score,
            score,
            auto,
            depth,
            outline,
            triangles: tris,
        });
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

/// Points per square metre of a cloud sampled every `spacing` metres.
fn cloud_density(spacing: f64) -> f64 {
    1.0 / (spacing * spacing).max(1e-6)
}

fn tri_area(t: &[[f64; 2]; 3]) -> f64 {
    0.5 * ((t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[2][0] - t[0][0]) * (t[1][1] - t[0][1]))
        .abs()
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
    // Half-width per band: the widest region extent there, from the triangles cut by the band.
    let mut hw = vec![0.0f64; levels];
    for t in tris {
        let (tv0, tv1) = (
            t.iter().map(|q| q[1]).fold(f64::INFINITY, f64::min),
            t.iter().map(|q| q[1]).fold(f64::NEG_INFINITY, f64::max),
        );
        for (k, w) in hw.iter_mut().enumerate() {
            let (y0, y1) = (a[1] + k as f64 * h, a[1] + (k + 1) as f64 * h);
            if tv1 < y0 || tv0 > y1 {
                continue;
            }
            let ym = (0.5 * (y0 + y1)).clamp(tv0, tv1);
            // Extent of the triangle at height ym.
            let mut xs = vec![];
            for i in 0..3 {
                let (p0, p1) = (t[i], t[(i + 1) % 3]);
                if (p0[1] - ym) * (p1[1] - ym) <= 0.0 && p0[1] != p1[1] {
                    xs.push(p0[0] + (ym - p0[1]) * (p1[0] - p0[0]) / (p1[1] - p0[1]));
                }
            }
            for x in xs {
                *w = w.max((x - uc).abs());
            }
        }
    }
    let mut right = vec![];
    for (k, w) in hw.iter().enumerate() {
        let y = a[1] + (k as f64 + 0.5) * h;
        right.push([uc + w, y]);
    }
    let mut out = vec![[uc - hw[0], a[1]], [uc + hw[0], a[1]]];
    out.extend(right.iter().copied());
    out.push([uc + hw[levels - 1], b[1]]);
    out.push([uc - hw[levels - 1], b[1]]);
    out.extend(right.iter().rev().map(|q| [2.0 * uc - q[0], q[1]]));
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
