//! Preprocessing (seed chapter 4.3.1.1): crop, voxel down-sampling to about 100,000 points,
//! statistical outlier removal, and normals by PCA over 16 neighbours oriented towards the
//! interior.
//!
//! - Voxel down-sampling replaces the points of each occupied cube by their centroid (which
//!   also averages range noise); the cube size is found by a few secant steps on the
//!   surface law `count ∝ size⁻²` so that about `target` points remain. The seed down-samples
//!   randomly; voxels give an even density, which the window detector relies on.
//! - Statistical outlier removal (Rusu et al. 2008, PCL's `StatisticalOutlierRemoval`): a point
//!   whose mean distance to its `k` nearest neighbours exceeds the global mean by more than
//!   `std_ratio` standard deviations, and twice the median, is dropped.
//! - Normals: eigenvector of the smallest eigenvalue of the neighbourhood covariance (Hoppe et
//!   al. 1992), flipped towards the station that saw the point (a scanner always sees a
//!   surface from its interior side), else towards the nearest station, else towards the
//!   centre of the bounding box.

use super::cloud::{Bounds, PointCloud};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use std::num::NonZero;

/// A k-d tree over a cloud's points.
pub fn kdtree(points: &[[f64; 3]]) -> ImmutableKdTree<f64, 3> {
    ImmutableKdTree::new_from_slice(points)
}

/// Indices of the `k` nearest neighbours of `q` (including itself when it is a point).
pub fn knn(tree: &ImmutableKdTree<f64, 3>, q: &[f64; 3], k: usize) -> Vec<(f64, usize)> {
    tree.nearest_n::<SquaredEuclidean>(q, NonZero::new(k.max(1)).unwrap_or(NonZero::<usize>::MIN))
        .into_iter()
        .map(|n| (n.distance.sqrt(), n.item as usize))
        .collect()
}

/// Keep the points inside `b`.
pub fn crop(cloud: &mut PointCloud, b: &Bounds) {
    let keep: Vec<usize> = (0..cloud.len())
        .filter(|&i| b.contains(&cloud.points[i]))
        .collect();
    cloud.retain_indices(&keep);
}

/// A voxel's integer coordinates packed into 63 bits (21 bits per axis: two million voxels
/// a side, 20 km at 1 cm, before keys wrap).
fn voxel_key(p: &[f64; 3], s: f64) -> u64 {
    let k = p.map(|v| ((v / s).floor() as i64 & 0x1F_FFFF) as u64);
    k[0] << 42 | k[1] << 21 | k[2]
}

/// Sorted voxel keys with the point index, in parallel (a sort is several times faster than
/// hashing a million points).
fn sorted_keys(points: &[[f64; 3]], s: f64) -> Vec<(u64, u32)> {
    let mut keys: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| (voxel_key(p, s), i as u32))
        .collect();
    keys.par_sort_unstable();
    keys
}

fn count_voxels(points: &[[f64; 3]], s: f64) -> usize {
    let keys = sorted_keys(points, s);
    1 + keys.windows(2).filter(|w| w[0].0 != w[1].0).count()
}

/// Down-sample to about `target` points (nothing happens below it); returns the voxel size.
pub fn voxel_downsample(cloud: &mut PointCloud, target: usize) -> Option<f64> {
    if cloud.len() <= target || target == 0 || cloud.len() > u32::MAX as usize {
        return None;
    }
    let b = Bounds::of(&cloud.points)?;
    let sz = b.size();
    // Surface area of the bounding box as the first guess of the scanned area.
    let area = 2.0 * (sz[0] * sz[1] + sz[1] * sz[2] + sz[0] * sz[2]);
    let mut s = (area / target as f64).sqrt().max(1e-4);
    for _ in 0..6 {
        let c = count_voxels(&cloud.points, s) as f64;
        let ratio = c / target as f64;
        if (ratio - 1.0).abs() < 0.05 {
            break;
        }
        s *= ratio.sqrt();
    }
    let keys = sorted_keys(&cloud.points, s);
    let mut first = Vec::new();
    let mut centroids = Vec::new();
    let mut start = 0;
    while start < keys.len() {
        let mut end = start + 1;
        while end < keys.len() && keys[end].0 == keys[start].0 {
            end += 1;
        }
        let mut sum = [0.0; 3];
        for &(_, i) in &keys[start..end] {
            for (acc, v) in sum.iter_mut().zip(&cloud.points[i as usize]) {
                *acc += v;
            }
        }
        let n = (end - start) as f64;
        centroids.push(sum.map(|v| v / n));
        // The lowest index keeps the per-point data (sorting keeps it first within a key).
        first.push(keys[start].1 as usize);
        start = end;
    }
    cloud.retain_indices(&first);
    cloud.points = centroids;
    cloud.normals = None;
    Some(s)
}

/// Statistical outlier removal; returns how many points were dropped.
pub fn remove_outliers(cloud: &mut PointCloud, k: usize, std_ratio: f64) -> usize {
    take_outliers(cloud, k, std_ratio).len()
}

/// Statistical outlier removal that hands back what it removed: the window detector reads
/// the isolated returns beyond glazing as evidence of an opening ([`super::openings`]), and
/// they are exactly what this filter takes out.
pub fn take_outliers(cloud: &mut PointCloud, k: usize, std_ratio: f64) -> PointCloud {
    let mut removed = PointCloud {
        stations: cloud.stations.clone(),
        station_of: cloud.station_of.as_ref().map(|_| Vec::new()),
        ..Default::default()
    };
    if cloud.len() <= k + 1 {
        return removed;
    }
    let tree = kdtree(&cloud.points);
    let mean: Vec<f64> = cloud
        .points
        .par_iter()
        .map(|p| {
            let nn = knn(&tree, p, k + 1);
            nn.iter().skip(1).map(|n| n.0).sum::<f64>() / k as f64
        })
        .collect();
    let n = mean.len() as f64;
    let mu = mean.iter().sum::<f64>() / n;
    let sd = (mean.iter().map(|m| (m - mu).powi(2)).sum::<f64>() / n).sqrt();
    // Never below twice the median: after voxel down-sampling the neighbour distances hardly
    // vary, mu + 3 sd fell between a surface's inner points and its edge rows (which miss
    // the neighbours on one side), and whole rows around windows went, making them a row
    // (3-4 %) too large. An outlier lies many spacings from the surface.
    let mut sorted = mean.clone();
    sorted.sort_by(f64::total_cmp);
    let limit = (mu + std_ratio * sd).max(2.0 * sorted[sorted.len() / 2]);
    let (keep, drop): (Vec<usize>, Vec<usize>) = (0..mean.len()).partition(|&i| mean[i] <= limit);
    removed.points = drop.iter().map(|&i| cloud.points[i]).collect();
    if let (Some(s), Some(out)) = (&cloud.station_of, removed.station_of.as_mut()) {
        *out = drop.iter().map(|&i| s[i]).collect();
    }
    cloud.retain_indices(&keep);
    removed
}

/// Each station's angular step in radians, from its own points before down-sampling: the
/// median over (a sample of) them of the distance to the nearest point of the same station
/// over the range. On a surface the nearest sample lies one step away in the direction the
/// surface does not stretch, so this is the step whatever the incidence. `None` for a station
/// with fewer than 100 points, and for all when the points do not say which station saw
/// them. The window ranking needs it to tell a station that should have sampled a wall
/// densely from one whose samples are too far apart there anyway (visibility module).
pub fn angular_steps(cloud: &PointCloud) -> Vec<Option<f64>> {
    let Some(of) = &cloud.station_of else {
        return vec![None; cloud.stations.len()];
    };
    (0..cloud.stations.len())
        .into_par_iter()
        .map(|s| {
            let st = cloud.stations[s];
            let pts: Vec<[f64; 3]> = (0..cloud.len())
                .filter(|&i| of[i] as usize == s)
                .map(|i| cloud.points[i])
                .collect();
            if pts.len() < 100 {
                return None;
            }
            let tree = kdtree(&pts);
            let step = (pts.len() / 2000).max(1);
            let mut ratios: Vec<f64> = pts
                .par_iter()
                .step_by(step)
                .filter_map(|p| {
                    let r = (0..3).map(|k| (p[k] - st[k]).powi(2)).sum::<f64>().sqrt();
                    let d = knn(&tree, p, 2).get(1).map(|n| n.0)?;
                    (r > 0.1 && d > 0.0).then_some(d / r)
                })
                .collect();
            if ratios.is_empty() {
                return None;
            }
            ratios.sort_by(f64::total_cmp);
            Some(ratios[ratios.len() / 2])
        })
        .collect()
}

/// Unit eigenvector of the smallest eigenvalue of a symmetric 3x3 matrix, and the ratio of
/// the smallest eigenvalue to the sum (surface variation, 0 on a perfect plane).
pub fn smallest_eigenvector(c: [[f64; 3]; 3]) -> ([f64; 3], f64) {
    let m = nalgebra::Matrix3::from_fn(|i, j| c[i][j]);
    let e = m.symmetric_eigen();
    let mut k = 0;
    for i in 1..3 {
        if e.eigenvalues[i] < e.eigenvalues[k] {
            k = i;
        }
    }
    let v = e.eigenvectors.column(k);
    let sum = e
        .eigenvalues
        .iter()
        .map(|x| x.abs())
        .sum::<f64>()
        .max(1e-300);
    ([v[0], v[1], v[2]], e.eigenvalues[k].abs() / sum)
}

/// Centroid and covariance of some points.
pub fn covariance(points: impl Iterator<Item = [f64; 3]> + Clone) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut n = 0.0f64;
    let mut c = [0.0; 3];
    for p in points.clone() {
        n += 1.0;
        for k in 0..3 {
            c[k] += p[k];
        }
    }
    let c = c.map(|v| v / n.max(1.0));
    let mut m = [[0.0; 3]; 3];
    for p in points {
        let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += d[i] * d[j];
            }
        }
    }
    (c, m)
}

/// Where point `i`'s normal should face: its station, the nearest station, or the centre.
fn viewpoint(cloud: &PointCloud, i: usize, centre: [f64; 3]) -> [f64; 3] {
    let p = cloud.points[i];
    if let Some(s) = cloud.station_of.as_ref().and_then(|s| s.get(i))
        && let Some(st) = cloud.stations.get(*s as usize)
    {
        return *st;
    }
    let d2 = |a: &[f64; 3]| (0..3).map(|k| (a[k] - p[k]).powi(2)).sum::<f64>();
    cloud
        .stations
        .iter()
        .min_by(|a, b| d2(a).total_cmp(&d2(b)))
        .copied()
        .unwrap_or(centre)
}

/// PCA normals over `k` neighbours, oriented (see the module documentation).
pub fn estimate_normals(cloud: &mut PointCloud, k: usize) {
    let tree = kdtree(&cloud.points);
    let centre = Bounds::of(&cloud.points)
        .map(|b| [0, 1, 2].map(|i| 0.5 * (b.lo[i] + b.hi[i])))
        .unwrap_or([0.0; 3]);
    let pts = &cloud.points;
    let normals: Vec<[f64; 3]> = (0..pts.len())
        .into_par_iter()
        .map(|i| {
            let nn = knn(&tree, &pts[i], k);
            let (_, cov) = covariance(nn.iter().map(|n| pts[n.1]));
            let (mut n, _) = smallest_eigenvector(cov);
            let v = viewpoint(cloud, i, centre);
            let to_view: f64 = (0..3).map(|j| (v[j] - pts[i][j]) * n[j]).sum();
            if to_view < 0.0 {
                n = n.map(|x| -x);
            }
            n
        })
        .collect();
    cloud.normals = Some(normals);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voxel_sor_and_normals_on_a_noisy_floor() {
        // A 4 x 4 m floor sampled every 1 cm (160,000 points) and one far outlier.
        let mut c = PointCloud::default();
        for i in 0..400 {
            for j in 0..400 {
                c.points.push([i as f64 * 0.01, j as f64 * 0.01, 0.0]);
            }
        }
        c.points.push([2.0, 2.0, 1.0]);
        c.stations = vec![[2.0, 2.0, 1.5]];
        voxel_downsample(&mut c, 10_000).unwrap();
        assert!((9_000..11_000).contains(&c.len()), "{}", c.len());
        let n = c.len();
        let dropped = remove_outliers(&mut c, 8, 3.0);
        assert!((1..n / 100).contains(&dropped), "{dropped}");
        assert!(c.points.iter().all(|p| p[2] < 0.5), "the outlier is gone");
        estimate_normals(&mut c, 16);
        assert!(c.normals.unwrap().iter().all(|n| n[2] > 0.999));
    }

    /// The simulator's angular step comes back from each station's points.
    #[test]
    fn angular_steps_of_a_simulated_scan() {
        use super::super::rooms::RoomSpec;
        use super::super::simulate::{ScanOptions, scan};
        let r = RoomSpec::named("rect").unwrap();
        let opts = ScanOptions {
            stations: r.stations.clone(),
            resolution: 1.0,
            ..Default::default()
        };
        let c = scan(&r.scene().unwrap(), &opts).unwrap();
        let steps = angular_steps(&c);
        assert_eq!(steps.len(), 2);
        for s in steps {
            let s = s.unwrap().to_degrees();
            assert!((0.9..1.1).contains(&s), "{s} degrees");
        }
        let mut anonymous = c;
        anonymous.station_of = None;
        assert_eq!(angular_steps(&anonymous), vec![None, None]);
    }
}
