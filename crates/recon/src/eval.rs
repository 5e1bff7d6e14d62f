//! Evaluation against a known model (seed chapter 4.3.5): Chamfer and Hausdorff distances
//! between the two surfaces, window area and position errors, watertightness.
//!
//! Both surfaces are sampled uniformly by area (`samples` points each; the seed uses 80,000)
//! and each sample's distance to the *other surface* is computed exactly (closest point on
//! its triangles, Ericson, "Real-Time Collision Detection" 5.1.5) rather than to the other
//! sample set, so that the numbers measure geometry and not sampling density.
//! - Chamfer distance: the mean of the two directed mean distances (metres); the seed's Table
//!   4.4 reports the mean of squared distances, given here as `chamfer_sq` (m²).
//! - Hausdorff distance: the larger of the two directed maxima.
//!
//! Windows are glazing polygons; each true window is matched to the reconstructed one with the
//! nearest centroid.

use super::model::{FaceKind, NamedPolygon, Role};
use crate::geometry::{Vec3, polygon_area, triangulate};
use crate::scene::{Primitive, Scene};
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

/// Geometric comparison of a reconstruction with the truth.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Comparison {
    pub chamfer: f64,
    pub chamfer_sq: f64,
    pub hausdorff: f64,
    pub windows_true: usize,
    pub windows_found: usize,
    pub window_area_true: f64,
    pub window_area_found: f64,
    /// (found - true) / true, total glazing area.
    pub window_area_error: f64,
    /// Mean centroid distance of matched windows, metres.
    pub window_position_error: f64,
}

type Tri = [Vec3; 3];

fn triangles(polys: &[NamedPolygon]) -> Vec<Tri> {
    let mut out = Vec::new();
    for p in polys {
        if let Ok(ts) = triangulate(&p.vertices) {
            for t in ts {
                out.push([p.vertices[t[0]], p.vertices[t[1]], p.vertices[t[2]]]);
            }
        }
    }
    out
}

fn sample(tris: &[Tri], n: usize, seed: u64) -> Vec<Vec3> {
    let areas: Vec<f64> = tris
        .iter()
        .map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
        .collect();
    let total: f64 = areas.iter().sum();
    let mut cum = Vec::with_capacity(areas.len());
    let mut acc = 0.0;
    for a in &areas {
        acc += a;
        cum.push(acc);
    }
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let x = rng.random::<f64>() * total;
            let i = cum.partition_point(|&c| c < x).min(tris.len() - 1);
            let (mut r1, mut r2): (f64, f64) = (rng.random(), rng.random());
            if r1 + r2 > 1.0 {
                r1 = 1.0 - r1;
                r2 = 1.0 - r2;
            }
            let t = tris[i];
            t[0] + (t[1] - t[0]) * r1 + (t[2] - t[0]) * r2
        })
        .collect()
}

/// Closest point on triangle `abc` to `p` (Ericson 5.1.5).
fn closest(p: Vec3, [a, b, c]: Tri) -> Vec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Distances from each point to the nearest triangle.
fn distances(points: &[Vec3], tris: &[Tri]) -> Vec<f64> {
    points
        .par_iter()
        .map(|&p| {
            tris.iter()
                .map(|&t| (closest(p, t) - p).length_squared())
                .fold(f64::INFINITY, f64::min)
                .sqrt()
        })
        .collect()
}

/// Area centroid of a planar polygon (its triangles' centroids weighted by area).
fn centroid(v: &[Vec3]) -> Vec3 {
    let tris = triangles(&[NamedPolygon {
        name: String::new(),
        role: Role::Glazing,
        vertices: v.to_vec(),
    }]);
    let (mut c, mut a) = (Vec3::ZERO, 0.0);
    for t in tris {
        let w = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
        c += (t[0] + t[1] + t[2]) * (w / 3.0);
        a += w;
    }
    if a > 0.0 {
        c / a
    } else {
        v.iter().fold(Vec3::ZERO, |s, &b| s + b) / v.len().max(1) as f64
    }
}

/// Compare `found` with `truth` using `samples` points per surface.
pub fn compare(truth: &[NamedPolygon], found: &[NamedPolygon], samples: usize) -> Comparison {
    let (tt, tf) = (triangles(truth), triangles(found));
    let mut c = Comparison::default();
    if !tt.is_empty() && !tf.is_empty() {
        let (st, sf) = (sample(&tt, samples, 11), sample(&tf, samples, 12));
        let (dt, df) = (distances(&st, &tf), distances(&sf, &tt));
        let mean = |d: &[f64]| d.iter().sum::<f64>() / d.len() as f64;
        let mean_sq = |d: &[f64]| d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64;
        let max = |d: &[f64]| d.iter().copied().fold(0.0, f64::max);
        c.chamfer = 0.5 * (mean(&dt) + mean(&df));
        c.chamfer_sq = 0.5 * (mean_sq(&dt) + mean_sq(&df));
        c.hausdorff = max(&dt).max(max(&df));
    }
    let glz = |ps: &[NamedPolygon]| -> Vec<(Vec3, f64)> {
        ps.iter()
            .filter(|p| p.role == Role::Glazing)
            .map(|p| (centroid(&p.vertices), polygon_area(&p.vertices)))
            .collect()
    };
    let (wt, wf) = (glz(truth), glz(found));
    c.windows_true = wt.len();
    c.windows_found = wf.len();
    c.window_area_true = wt.iter().map(|w| w.1).sum();
    c.window_area_found = wf.iter().map(|w| w.1).sum();
    if c.window_area_true > 0.0 {
        c.window_area_error = (c.window_area_found - c.window_area_true) / c.window_area_true;
    }
    if !wf.is_empty() && !wt.is_empty() {
        c.window_position_error = wt
            .iter()
            .map(|(p, _)| {
                wf.iter()
                    .map(|(q, _)| (*q - *p).length())
                    .fold(f64::INFINITY, f64::min)
            })
            .sum::<f64>()
            / wt.len() as f64;
    }
    c
}

/// The polygons of a `.rad` scene with roles: glazing when the material is `glass` (or named
/// `glazing`), reveal when named so, otherwise a shell face classified by its normal.
pub fn polygons_of_scene(scene: &Scene) -> Vec<NamedPolygon> {
    let mut out = Vec::new();
    for (i, o) in scene.surfaces() {
        let Primitive::Polygon { vertices } = &o.kind else {
            continue;
        };
        let m = scene.material_of(i).map(|m| &scene.objects[m]);
        let v: Vec<Vec3> = vertices.iter().map(|&a| Vec3::from(a)).collect();
        let role = match m {
            Some(m) if matches!(m.kind, Primitive::Glass { .. }) || m.id == "glazing" => {
                Role::Glazing
            }
            Some(m) if m.id == "reveal" => Role::Reveal,
            Some(m) if m.id == "furniture" => continue,
            _ => Role::Shell(FaceKind::of_normal(
                crate::geometry::triangulate::newell_normal(&v).normalize(),
            )),
        };
        out.push(NamedPolygon {
            name: o.id.clone(),
            role,
            vertices: v,
        });
    }
    out
}
