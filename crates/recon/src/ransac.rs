//! Plane detection by efficient RANSAC (Schnabel, Wahl & Klein 2007, "Efficient RANSAC for
//! point-cloud shape detection", Computer Graphics Forum 26(2)), with the seed's parameters
//! (chapter 4, Table 4.2) as defaults.
//!
//! As in the paper: minimal sets are drawn *locally* (the first point at random, the other
//! two among its neighbours, which is what the octree levels achieve: points of one plane are
//! near each other), a candidate must agree with the three points' normals (`normal_threshold`
//! is the cosine), candidates are scored on a random subset first and only the best are scored
//! on all remaining points, the score is the largest connected component of the inliers on a
//! bitmap of cell `bitmap_resolution` in the plane, and the best candidate is extracted once
//! the probability of having overlooked a better one, `(1 - m / (3 N))^t` for a candidate of
//! `m` points among `N` after `t` draws (3 = the paper's localisation factor for a handful of
//! octree levels), falls below `overlook_probability`. Extraction stops when no candidate
//! reaches `min_support`.
//!
//! Refinement: the extracted plane is refitted by least squares (PCA) to its component, its
//! inliers are collected again with the refitted plane (`refine_factor` x `epsilon`, so range
//! noise larger than `epsilon` does not leave a parallel ghost plane behind), and the
//! component recomputed.

use super::preprocess::{covariance, kdtree, knn, smallest_eigenvector};
use rand::{Rng, SeedableRng};
use rdaylight_base::vec3::{cross, dot, sub};
use std::collections::{HashMap, VecDeque};

/// RANSAC parameters (defaults: seed Table 4.2).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RansacParams {
    /// Minimum points per plane (seed: 1,000-4,000).
    pub min_support: usize,
    /// Inlier distance (seed: 0.005 m).
    pub epsilon: f64,
    /// Connectivity bitmap cell (seed: 0.02 m).
    pub bitmap_resolution: f64,
    /// Minimum |cos| between point normal and plane normal (seed: 0.8).
    pub normal_threshold: f64,
    /// Probability of overlooking a better candidate (seed: 0.001).
    pub overlook_probability: f64,
    /// Distance factor for collecting the final inliers of a refitted plane.
    pub refine_factor: f64,
    pub seed: u64,
}

impl Default for RansacParams {
    fn default() -> Self {
        RansacParams {
            min_support: 1000,
            epsilon: 0.005,
            bitmap_resolution: 0.02,
            normal_threshold: 0.8,
            overlook_probability: 0.001,
            refine_factor: 3.0,
            seed: 1,
        }
    }
}

/// A detected plane `n · x = d` and its inliers (indices into the cloud).
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    pub normal: [f64; 3],
    pub d: f64,
    pub inliers: Vec<usize>,
}

impl Plane {
    pub fn distance(&self, p: &[f64; 3]) -> f64 {
        dot(self.normal, *p) - self.d
    }
}

/// Two unit vectors spanning the plane of normal `n`.
pub fn plane_basis(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let a = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = cross(n, a);
    let l = dot(u, u).sqrt();
    let u = u.map(|x| x / l);
    (u, cross(n, u))
}

/// Points of `cand` that are within `eps` and normal-compatible.
fn inliers(
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    idx: &[usize],
    n: [f64; 3],
    d: f64,
    eps: f64,
    cos: f64,
) -> Vec<usize> {
    idx.iter()
        .copied()
        .filter(|&i| (dot(n, points[i]) - d).abs() < eps && dot(n, normals[i]).abs() > cos)
        .collect()
}

/// The largest 8-connected component of `idx` on a bitmap of cell `res` in the plane.
fn largest_component(points: &[[f64; 3]], idx: &[usize], n: [f64; 3], res: f64) -> Vec<usize> {
    if idx.is_empty() {
        return vec![];
    }
    let (u, v) = plane_basis(n);
    let mut cells: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for &i in idx {
        let p = points[i];
        let key = (
            (dot(p, u) / res).floor() as i64,
            (dot(p, v) / res).floor() as i64,
        );
        cells.entry(key).or_default().push(i);
    }
    let mut seen: HashMap<(i64, i64), bool> = HashMap::new();
    let mut best: Vec<usize> = vec![];
    // Sorted: HashMap order changes from run to run, and it decided which of two equal
    // components won and the order of the plane's points (issue #19).
    let mut keys: Vec<(i64, i64)> = cells.keys().copied().collect();
    keys.sort_unstable();
    for k in keys {
        if seen.contains_key(&k) {
            continue;
        }
        let mut comp = vec![];
        let mut q = VecDeque::from([k]);
        seen.insert(k, true);
        while let Some(c) = q.pop_front() {
            comp.extend_from_slice(&cells[&c]);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    let nb = (c.0 + dx, c.1 + dy);
                    if cells.contains_key(&nb) && !seen.contains_key(&nb) {
                        seen.insert(nb, true);
                        q.push_back(nb);
                    }
                }
            }
        }
        if comp.len() > best.len() {
            best = comp;
        }
    }
    best
}

/// Least-squares plane through some points, normal turned towards `hint`.
fn refit(points: &[[f64; 3]], idx: &[usize], hint: [f64; 3]) -> ([f64; 3], f64) {
    let (c, cov) = covariance(idx.iter().map(|&i| points[i]));
    let (mut n, _) = smallest_eigenvector(cov);
    if dot(n, hint) < 0.0 {
        n = n.map(|x| -x);
    }
    (n, dot(n, c))
}

/// Detect planes; `normals` must be unit normals of `points`.
pub fn detect(points: &[[f64; 3]], normals: &[[f64; 3]], p: &RansacParams) -> Vec<Plane> {
    let n_all = points.len();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(p.seed);
    let tree = kdtree(points);
    let mut assigned = vec![false; n_all];
    let mut remaining: Vec<usize> = (0..n_all).collect();
    let mut planes = Vec::new();
    let subset_size = 3000;
    while remaining.len() >= p.min_support {
        let n_rem = remaining.len();
        let subset: Vec<usize> = if n_rem <= subset_size {
            remaining.clone()
        } else {
            (0..subset_size)
                .map(|_| remaining[rng.random_range(0..n_rem)])
                .collect()
        };
        let scale = n_rem as f64 / subset.len() as f64;
        // (estimated score, normal, d)
        let mut cands: Vec<(f64, [f64; 3], f64)> = Vec::new();
        let mut best_full: Option<(Vec<usize>, [f64; 3], f64)> = None;
        let mut drawn = 0usize;
        loop {
            for _ in 0..50 {
                drawn += 1;
                let i0 = remaining[rng.random_range(0..n_rem)];
                let nn = knn(&tree, &points[i0], 48);
                let free: Vec<usize> = nn
                    .iter()
                    .map(|x| x.1)
                    .filter(|&j| !assigned[j] && j != i0)
                    .collect();
                if free.len() < 2 {
                    continue;
                }
                let i1 = free[rng.random_range(0..free.len())];
                let i2 = free[rng.random_range(0..free.len())];
                if i1 == i2 {
                    continue;
                }
                let c = cross(sub(points[i1], points[i0]), sub(points[i2], points[i0]));
                let l = dot(c, c).sqrt();
                if l < 1e-9 {
                    continue;
                }
                let n = c.map(|x| x / l);
                if [i0, i1, i2]
                    .iter()
                    .any(|&k| dot(n, normals[k]).abs() < p.normal_threshold)
                {
                    continue;
                }
                let d = dot(n, points[i0]);
                let est = inliers(
                    points,
                    normals,
                    &subset,
                    n,
                    d,
                    p.epsilon,
                    p.normal_threshold,
                )
                .len() as f64
                    * scale;
                cands.push((est, n, d));
            }
            // Score the most promising candidates on everything.
            cands.sort_by(|a, b| b.0.total_cmp(&a.0));
            cands.truncate(4);
            for &(est, n, d) in &cands {
                if best_full
                    .as_ref()
                    .is_some_and(|b| (b.0.len() as f64) >= est * 1.2)
                {
                    continue;
                }
                let inl = inliers(
                    points,
                    normals,
                    &remaining,
                    n,
                    d,
                    p.epsilon,
                    p.normal_threshold,
                );
                let comp = largest_component(points, &inl, n, p.bitmap_resolution);
                if best_full.as_ref().is_none_or(|b| comp.len() > b.0.len()) {
                    best_full = Some((comp, n, d));
                }
            }
            let m = best_full.as_ref().map_or(0, |b| b.0.len()) as f64;
            let miss = (1.0 - m / (3.0 * n_rem as f64)).powf(drawn as f64);
            if (m > 0.0 && miss < p.overlook_probability) || drawn > 4000 {
                break;
            }
        }
        let Some((comp, n, _)) = best_full else { break };
        if comp.len() < p.min_support {
            break;
        }
        // Refinement: refit, recollect with a wider band, keep the component.
        let (n2, d2) = refit(points, &comp, n);
        let inl = inliers(
            points,
            normals,
            &remaining,
            n2,
            d2,
            p.epsilon * p.refine_factor,
            p.normal_threshold,
        );
        let comp2 = largest_component(points, &inl, n2, p.bitmap_resolution);
        let comp = if comp2.len() >= comp.len() {
            comp2
        } else {
            comp
        };
        let (n3, d3) = refit(points, &comp, n2);
        for &i in &comp {
            assigned[i] = true;
        }
        remaining.retain(|&i| !assigned[i]);
        planes.push(Plane {
            normal: n3,
            d: d3,
            inliers: comp,
        });
    }
    planes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_noisy_planes_are_found_to_a_millimetre() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        let mut pts = Vec::new();
        let mut nor = Vec::new();
        for _ in 0..6000 {
            let (a, b): (f64, f64) = (rng.random(), rng.random());
            pts.push([4.0 * a, 3.0 * b, 0.002 * (rng.random::<f64>() - 0.5)]);
            nor.push([0.0, 0.0, 1.0]);
            pts.push([4.0 * a, 0.0015 * (rng.random::<f64>() - 0.5), 2.5 * b]);
            nor.push([0.0, 1.0, 0.0]);
        }
        // 6,000 points on 12 m2 are ~4.5 cm apart: the bitmap cell must bridge that.
        let params = RansacParams {
            bitmap_resolution: 0.1,
            ..Default::default()
        };
        let planes = detect(&pts, &nor, &params);
        assert_eq!(
            planes.len(),
            2,
            "{:?}",
            planes.iter().map(|p| p.inliers.len()).collect::<Vec<_>>()
        );
        for p in &planes {
            assert!(p.inliers.len() > 5800);
            assert!(p.d.abs() < 1e-3 && p.normal.iter().any(|c| c.abs() > 0.99999));
        }
    }
}
