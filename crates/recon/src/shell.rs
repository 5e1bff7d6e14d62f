//! The watertight shell: PolyFit-style hypothesis and selection, solved exactly.
//!
//! PolyFit (Nan & Wonka 2017) chooses arrangement facets by data fit, coverage and complexity
//! under the constraint that every edge joins zero or two chosen facets, with a MIP solver.
//! We choose *cells* instead: each cell of the arrangement ([`super::arrangement`]) is inside
//! or outside the room, and the surface is the set of facets between an inside and an outside
//! cell. Every such surface is closed and consistently oriented by construction (it bounds a
//! volume), so the edge constraint holds without being imposed, and the normals point into the
//! room. The energy per facet between cells a (on the plane's positive side) and b:
//!
//! | labels (a, b) | cost |
//! |---|---|
//! | same (no surface) | S+ + S-: the facet's support is not explained |
//! | (in, out): surface faces +n | w S- + λ ρ U |
//! | (out, in): surface faces -n | w S+ + λ ρ U |
//!
//! where S+ / S- count the plane's inliers in the facet whose (scanner-oriented) normals face
//! +n / -n, U is the facet area not covered by points (occupancy grid of cell `coverage_cell`),
//! and ρ the point density, so coverage is measured in points as in PolyFit. Facets on the
//! bounding box pay λ ρ area when the room touches them. With w ≥ 2 every term is submodular
//! (2 (S+ + S-) ≤ w (S+ + S-) + 2 λ ρ U), so an s-t minimum cut finds the global optimum
//! exactly ([`super::mincut`]) in milliseconds, where PolyFit needs a MIP. PolyFit's model
//! complexity term (sharp edges) is not pairwise and is left out; the coverage term and the
//! GLoD0 plane filter below keep the shell simple.
//!
//! GLoD0 plane filter (the permanent shell only, seed chapter 2): before the arrangement,
//! near-duplicate planes are merged; walls (|n_z| < 0.5) must reach within `floor_reach` of
//! the floor and span at least `min_wall_height`; floors and ceilings must hold at least
//! `min_horizontal_share` of the points of the largest plane facing the same way. Furniture
//! planes (desk tops, cabinet sides, reveals) fail these tests.

use super::arrangement::{self, Pl};
use super::mincut::Energy;
use super::model::{Face, FaceKind, Frame, Model, Welder};
use super::ransac::Plane;
use crate::geometry::{Vec3, polygon_area};
use std::collections::{HashMap, HashSet};

/// Shell selection settings.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ShellParams {
    /// Weight of an inlier seen from the wrong side (≥ 2 keeps the energy submodular).
    pub wrong_side: f64,
    /// Weight of uncovered area, in points at the cloud's density.
    pub coverage: f64,
    /// Occupancy grid cell for coverage, metres.
    pub coverage_cell: f64,
    /// Planes closer than this (and within `merge_angle_deg`) are merged, metres.
    pub merge_distance: f64,
    pub merge_angle_deg: f64,
    pub floor_reach: f64,
    pub min_wall_height: f64,
    pub min_horizontal_share: f64,
}

impl Default for ShellParams {
    fn default() -> Self {
        ShellParams {
            wrong_side: 2.0,
            coverage: 1.0,
            coverage_cell: 0.1,
            merge_distance: 0.05,
            merge_angle_deg: 8.0,
            floor_reach: 0.4,
            min_wall_height: 1.2,
            min_horizontal_share: 0.2,
        }
    }
}

/// A plane of the shell, oriented into the room.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ShellPlane {
    pub normal: [f64; 3],
    pub d: f64,
    pub support: usize,
    /// Whether it passed the GLoD0 filter and entered the arrangement.
    pub permanent: bool,
    #[serde(skip)]
    pub inliers: Vec<usize>,
}

/// The selected shell.
#[derive(Debug, Clone)]
pub struct Shell {
    pub model: Model,
    /// For each model face, its plane in [`Shell::planes`].
    pub face_plane: Vec<Option<usize>>,
    pub planes: Vec<ShellPlane>,
    pub cells: usize,
    pub facets: usize,
    pub inside_cells: usize,
}

fn v3(a: [f64; 3]) -> Vec3 {
    Vec3::from(a)
}

/// Orient planes by their inliers' normals, merge duplicates, mark permanent ones.
pub fn prepare_planes(
    planes: &[Plane],
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    p: &ShellParams,
) -> Vec<ShellPlane> {
    let mut out: Vec<ShellPlane> = Vec::new();
    for pl in planes {
        let n = v3(pl.normal);
        let vote: f64 = pl
            .inliers
            .iter()
            .map(|&i| v3(normals[i]).dot(n).signum())
            .sum();
        let s = if vote < 0.0 { -1.0 } else { 1.0 };
        let cand = ShellPlane {
            normal: (n * s).to_array(),
            d: pl.d * s,
            support: pl.inliers.len(),
            permanent: false,
            inliers: pl.inliers.clone(),
        };
        let cos = p.merge_angle_deg.to_radians().cos();
        let dup = out.iter_mut().find(|o| {
            let on = v3(o.normal);
            on.dot(v3(cand.normal)) > cos && {
                // Distance between the planes measured at the candidate's centroid.
                let c = cand
                    .inliers
                    .iter()
                    .fold(Vec3::ZERO, |a, &i| a + v3(points[i]))
                    / cand.inliers.len().max(1) as f64;
                (on.dot(c) - o.d).abs() < p.merge_distance
            }
        });
        match dup {
            Some(o) => {
                o.inliers.extend_from_slice(&cand.inliers);
                let (c, cov) = super::preprocess::covariance(o.inliers.iter().map(|&i| points[i]));
                let (mut n2, _) = super::preprocess::smallest_eigenvector(cov);
                if v3(n2).dot(v3(o.normal)) < 0.0 {
                    n2 = n2.map(|x| -x);
                }
                o.normal = n2;
                o.d = v3(n2).dot(v3(c));
                o.support = o.inliers.len();
            }
            None => out.push(cand),
        }
    }
    // GLoD0 filter.
    let floor_z = out
        .iter()
        .filter(|o| o.normal[2] > 0.9)
        .max_by_key(|o| o.support)
        .map(|o| o.inliers.iter().map(|&i| points[i][2]).sum::<f64>() / o.support.max(1) as f64);
    let max_up = out
        .iter()
        .filter(|o| o.normal[2] > 0.5)
        .map(|o| o.support)
        .max()
        .unwrap_or(0);
    let max_down = out
        .iter()
        .filter(|o| o.normal[2] < -0.5)
        .map(|o| o.support)
        .max()
        .unwrap_or(0);
    for o in &mut out {
        o.permanent = if o.normal[2] > 0.5 {
            o.support as f64 >= p.min_horizontal_share * max_up as f64
        } else if o.normal[2] < -0.5 {
            o.support as f64 >= p.min_horizontal_share * max_down as f64
        } else {
            let (lo, hi) = o
                .inliers
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &i| {
                    (lo.min(points[i][2]), hi.max(points[i][2]))
                });
            let reach = floor_z.is_none_or(|f| lo <= f + p.floor_reach);
            reach && hi - lo >= p.min_wall_height
        };
    }
    out
}

fn point_in_convex(poly: &[[f64; 2]], q: [f64; 2]) -> bool {
    let n = poly.len();
    (0..n).all(|i| {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        (b[0] - a[0]) * (q[1] - a[1]) - (b[1] - a[1]) * (q[0] - a[0]) >= -1e-12
    })
}

/// Select the shell (see the module documentation).
pub fn select(
    planes: Vec<ShellPlane>,
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    p: &ShellParams,
) -> Shell {
    let perm: Vec<usize> = (0..planes.len()).filter(|&i| planes[i].permanent).collect();
    let pls: Vec<Pl> = perm
        .iter()
        .map(|&i| Pl {
            n: v3(planes[i].normal),
            d: planes[i].d,
        })
        .collect();
    let (mut lo, mut hi) = (Vec3::splat(f64::INFINITY), Vec3::splat(f64::NEG_INFINITY));
    for &i in &perm {
        for &k in &planes[i].inliers {
            lo = lo.min(v3(points[k]));
            hi = hi.max(v3(points[k]));
        }
    }
    let margin = Vec3::splat(0.5);
    let arr = arrangement::build(&pls, lo - margin, hi + margin);
    // Per plane: inliers in the plane frame with their side, and the occupancy grid.
    let g = p.coverage_cell;
    let mut frames = Vec::new();
    let mut occupied: Vec<HashSet<(i64, i64)>> = Vec::new();
    let mut proj: Vec<Vec<([f64; 2], bool)>> = Vec::new();
    for (j, &i) in perm.iter().enumerate() {
        let fr = Frame::new(pls[j].n * pls[j].d, pls[j].n);
        let pts: Vec<([f64; 2], bool)> = planes[i]
            .inliers
            .iter()
            .map(|&k| (fr.to_2d(v3(points[k])), v3(normals[k]).dot(pls[j].n) > 0.0))
            .collect();
        occupied.push(
            pts.iter()
                .map(|(q, _)| ((q[0] / g).floor() as i64, (q[1] / g).floor() as i64))
                .collect(),
        );
        proj.push(pts);
        frames.push(fr);
    }
    let total_pts: usize = proj.iter().map(|v| v.len()).sum();
    let total_cov: f64 = occupied.iter().map(|o| o.len() as f64 * g * g).sum();
    let rho = if total_cov > 0.0 {
        total_pts as f64 / total_cov
    } else {
        1.0
    };
    let mut e = Energy::new(arr.cells);
    for f in &arr.facets {
        let area = polygon_area(&f.polygon);
        match f.plane {
            None => e.add_unary(f.pos, 0.0, p.coverage * rho * area),
            Some(j) => {
                let fr = &frames[j];
                let poly: Vec<[f64; 2]> = f.polygon.iter().map(|&v| fr.to_2d(v)).collect();
                let (mut sp, mut sn) = (0.0, 0.0);
                for (q, side) in &proj[j] {
                    if point_in_convex(&poly, *q) {
                        if *side { sp += 1.0 } else { sn += 1.0 }
                    }
                }
                let covered = occupied[j]
                    .iter()
                    .filter(|c| {
                        point_in_convex(&poly, [(c.0 as f64 + 0.5) * g, (c.1 as f64 + 0.5) * g])
                    })
                    .count() as f64
                    * g
                    * g;
                let unc = (area - covered).max(0.0);
                let same = sp + sn;
                let w = p.wrong_side.max(2.0);
                // Plane facets always have a cell on both sides (the box holds them).
                let Some(neg) = f.neg else { continue };
                // (pos, neg) labels: E00, E01, E10, E11.
                e.add_pair(
                    f.pos,
                    neg,
                    [
                        same,
                        w * sp + p.coverage * rho * unc,
                        w * sn + p.coverage * rho * unc,
                        same,
                    ],
                );
            }
        }
    }
    let (inside, _) = e.minimise();
    // Boundary facets, oriented into the room, grouped by plane and facing.
    let mut groups: HashMap<(Option<usize>, bool), Vec<Vec<Vec3>>> = HashMap::new();
    for f in &arr.facets {
        let a = inside[f.pos];
        let b = f.neg.map(|n| inside[n]).unwrap_or(false);
        if a == b {
            continue;
        }
        let mut poly = f.polygon.clone();
        if !a {
            poly.reverse();
        }
        groups.entry((f.plane, a)).or_default().push(poly);
    }
    let scale = (hi - lo).max_abs().max(1.0);
    let mut faces: Vec<(Face, Option<usize>)> = Vec::new();
    let mut keys: Vec<_> = groups.keys().copied().collect();
    keys.sort_by_key(|k| (k.0.map_or(usize::MAX, |x| x), k.1));
    for key in keys {
        for poly in merge_coplanar(&groups[&key], 1e-7 * scale) {
            let n = crate::geometry::triangulate::newell_normal(&poly).normalize();
            faces.push((
                Face {
                    name: String::new(),
                    kind: FaceKind::of_normal(n),
                    polygon: poly,
                },
                key.0.map(|j| perm[j]),
            ));
        }
    }
    // Names: floors and ceilings by area, walls counter-clockwise from south seen from above.
    let centre = faces
        .iter()
        .flat_map(|f| f.0.polygon.iter())
        .fold(Vec3::ZERO, |a, &b| a + b)
        / faces
            .iter()
            .map(|f| f.0.polygon.len())
            .sum::<usize>()
            .max(1) as f64;
    let az = |f: &Face| {
        let c = f.polygon.iter().fold(Vec3::ZERO, |a, &b| a + b) / f.polygon.len() as f64 - centre;
        let a = c.y.atan2(c.x) + std::f64::consts::FRAC_PI_2;
        if a < 0.0 {
            a + std::f64::consts::TAU
        } else {
            a
        }
    };
    faces.sort_by(|x, y| {
        let kx = (
            x.0.kind as u8,
            if x.0.kind == FaceKind::Wall {
                az(&x.0)
            } else {
                -polygon_area(&x.0.polygon)
            },
        );
        let ky = (
            y.0.kind as u8,
            if y.0.kind == FaceKind::Wall {
                az(&y.0)
            } else {
                -polygon_area(&y.0.polygon)
            },
        );
        kx.partial_cmp(&ky).unwrap_or(std::cmp::Ordering::Equal)
    });
    let mut counts: HashMap<FaceKind, usize> = HashMap::new();
    for (f, _) in &mut faces {
        let c = counts.entry(f.kind).or_default();
        f.name = if *c == 0 && f.kind != FaceKind::Wall {
            f.kind.name().to_string()
        } else {
            format!("{}{}", f.kind.name(), c)
        };
        *c += 1;
    }
    let inside_cells = inside.iter().filter(|&&x| x).count();
    let (faces, face_plane): (Vec<Face>, Vec<Option<usize>>) = faces.into_iter().unzip();
    Shell {
        model: Model {
            faces,
            openings: vec![],
            reveal_depth: 0.0,
        },
        face_plane,
        planes,
        cells: arr.cells,
        facets: arr.facets.len(),
        inside_cells,
    }
}

/// Union of coplanar, equally oriented convex polygons that share whole edges: interior
/// edges (used in both directions) cancel, the rest chain into loops; straight-through
/// vertices are dropped (T-junction repair puts back the ones a neighbour needs).
pub fn merge_coplanar(polys: &[Vec<Vec3>], tol: f64) -> Vec<Vec<Vec3>> {
    let mut w = Welder::new(tol);
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    for p in polys {
        let ids: Vec<usize> = p.iter().map(|&v| w.id(v)).collect();
        for k in 0..ids.len() {
            let (a, b) = (ids[k], ids[(k + 1) % ids.len()]);
            if a != b {
                *edges.entry((a, b)).or_default() += 1;
            }
        }
    }
    let mut next: HashMap<usize, Vec<usize>> = HashMap::new();
    for (&(a, b), _) in edges
        .iter()
        .filter(|((a, b), _)| !edges.contains_key(&(*b, *a)))
    {
        next.entry(a).or_default().push(b);
    }
    // The edges came out of a HashMap in an order that changes from run to run; where a
    // vertex has several outgoing edges, which one `pop` takes decides the loops, so sort
    // them (issue #19: `rrecon --auto --seed 3` differed on every run).
    for v in next.values_mut() {
        v.sort_unstable();
    }
    let mut loops = Vec::new();
    let mut starts: Vec<usize> = next.keys().copied().collect();
    starts.sort();
    for s in starts {
        while next.get(&s).is_some_and(|v| !v.is_empty()) {
            let mut lp = vec![s];
            let mut cur = s;
            while let Some(n) = next.get_mut(&cur).and_then(|v| v.pop()) {
                if n == s {
                    break;
                }
                lp.push(n);
                cur = n;
                if lp.len() > 100_000 {
                    break;
                }
            }
            let pts: Vec<Vec3> = lp.iter().map(|&i| w.point(i)).collect();
            let pts = drop_collinear(&pts, tol);
            if pts.len() >= 3 {
                loops.push(pts);
            }
        }
    }
    loops
}

fn drop_collinear(p: &[Vec3], tol: f64) -> Vec<Vec3> {
    let n = p.len();
    (0..n)
        .filter(|&i| {
            let (a, b, c) = (p[(i + n - 1) % n], p[i], p[(i + 1) % n]);
            (b - a).cross(c - b).length() > tol * (c - a).length().max(tol)
        })
        .map(|i| p[i])
        .collect()
}
