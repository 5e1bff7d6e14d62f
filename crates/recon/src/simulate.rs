//! A terrestrial laser scanner simulator: scans of known `.rad` rooms for testing the
//! reconstruction against ground truth.
//!
//! Model (what phase-based TLS such as a Leica RTC360 or a FARO Focus does, simplified):
//! - each station sweeps azimuth 0-360 degrees and elevation -90..+90 degrees in steps of
//!   `resolution` (the azimuth step grows as 1/cos(elevation), giving an even angular density
//!   instead of the real instrument's pole crowding, which voxel down-sampling removes anyway);
//! - the first opaque surface returns a point at the true range plus Gaussian noise of
//!   `noise` metres (2-5 mm is typical of these instruments at room ranges), up to `max_range`;
//! - glass (`glass` material, and `trans`) returns nothing: the beam continues through it, so
//!   windows appear as holes and whatever lies beyond is scanned as exterior points;
//! - except for `stray` returns: a beam that crosses a pane returns, with probability `stray`,
//!   a point between 0.05 and 5 m beyond it (uniform in range). Real scans of glazing show a
//!   few such points: dirt and frames behind the pane, reflections, the first leaves of a tree;
//!   with glazing flush in the wall (no reveals to scan) they are the only returns through
//!   the window;
//! - surfaces without a material (`void`) are invisible, occlusion is exact (one BVH).
//!
//! Every station gets its own deterministic random stream per azimuth column, so a seed gives
//! the same cloud whatever the thread count. Points record their station index.

use super::cloud::PointCloud;
use crate::error::{Error, Result};
use crate::geometry::{Bvh, Object, Ray, Shape, Vec3};
use crate::scene::{Primitive, Scene};
use rand::{Rng, SeedableRng};
use rand_distr_free::normal;
use rayon::prelude::*;

/// Scanner settings.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanOptions {
    pub stations: Vec<[f64; 3]>,
    /// Angular step in degrees.
    pub resolution: f64,
    /// Standard deviation of the range noise in metres.
    pub noise: f64,
    pub max_range: f64,
    /// Probability that a beam crossing glass returns a stray point beyond it (0-1).
    pub stray: f64,
    pub seed: u64,
}

impl Default for ScanOptions {
    fn default() -> Self {
        ScanOptions {
            stations: vec![],
            resolution: 0.25,
            noise: 0.003,
            max_range: 50.0,
            stray: 0.0,
            seed: 1,
        }
    }
}

/// Gaussian samples without another dependency (Box-Muller).
mod rand_distr_free {
    use rand::Rng;
    pub fn normal<R: Rng>(rng: &mut R) -> f64 {
        let u1: f64 = rng.random::<f64>().max(1e-300);
        let u2: f64 = rng.random();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// Scan `scene` from the stations in `opts`.
pub fn scan(scene: &Scene, opts: &ScanOptions) -> Result<PointCloud> {
    let mut objects = Vec::new();
    let mut passes = Vec::new();
    // Scene index of each BVH object, so a bad polygon is reported at its file:line.
    let mut origin = Vec::new();
    for (i, o) in scene.surfaces() {
        let Primitive::Polygon { vertices } = &o.kind else {
            return Err(Error::unsupported(
                o.loc.clone(),
                format!(
                    "surface type '{}' ('{}') in the scan simulator; expected polygons",
                    o.type_name(),
                    o.id
                ),
            ));
        };
        let Some(m) = scene.material_of(i) else {
            continue;
        };
        let glass = matches!(
            scene.objects[m].kind,
            Primitive::Glass { .. } | Primitive::Trans { .. }
        );
        objects.push(Object {
            shape: Shape::Polygon {
                vertices: vertices.clone(),
            },
            id: objects.len() as u32,
        });
        passes.push(glass);
        origin.push(i);
    }
    if objects.is_empty() {
        return Err(Error::Usage("the scene has no surfaces to scan".into()));
    }
    if opts.stations.is_empty() {
        return Err(Error::Usage("no scanner stations given".into()));
    }
    if !(0.0..=1.0).contains(&opts.stray) {
        return Err(Error::Usage(format!(
            "stray return probability {}; expected 0-1",
            opts.stray
        )));
    }
    if !(opts.resolution > 0.001 && opts.resolution <= 45.0) {
        return Err(Error::Usage(format!(
            "resolution {} degrees; expected 0.001-45",
            opts.resolution
        )));
    }
    let bvh = Bvh::build(&objects).map_err(|e| {
        let o = &scene.objects[origin[e.index]];
        Error::parse(
            o.loc.clone(),
            format!("{} '{}': {}", o.type_name(), o.id, e.error),
        )
    })?;
    let step = opts.resolution.to_radians();
    let rows = (std::f64::consts::PI / step).round() as usize;
    let mut cloud = PointCloud {
        stations: opts.stations.clone(),
        station_of: Some(Vec::new()),
        ..Default::default()
    };
    for (si, st) in opts.stations.iter().enumerate() {
        let org = Vec3::from(*st);
        let pts: Vec<Vec<[f64; 3]>> = (0..rows)
            .into_par_iter()
            .map(|row| {
                let mut rng = rand_pcg::Pcg64::seed_from_u64(
                    opts.seed ^ ((si as u64) << 40) ^ (row as u64).wrapping_mul(0x9E37_79B9),
                );
                let el = -std::f64::consts::FRAC_PI_2 + (row as f64 + 0.5) * step;
                let n_az = ((std::f64::consts::TAU * el.cos() / step).round() as usize).max(1);
                let mut out = Vec::with_capacity(n_az);
                for k in 0..n_az {
                    let az = (k as f64 + 0.5) * std::f64::consts::TAU / n_az as f64;
                    let dir = Vec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
                    let mut ray = Ray::new(org, dir);
                    let mut travelled = 0.0;
                    // Pass through at most a few panes (double glazing, a second window).
                    for _ in 0..4 {
                        let Some(hit) = bvh.intersect(&ray, 1e-6, opts.max_range - travelled)
                        else {
                            break;
                        };
                        if passes[hit.object as usize] {
                            travelled += hit.t;
                            // The draw is made only when stray returns are asked for, so
                            // scans without them keep their random stream (and their points).
                            if opts.stray > 0.0 && rng.random::<f64>() < opts.stray {
                                let beyond = 0.05 + 4.95 * rng.random::<f64>();
                                let r = travelled + beyond + opts.noise * normal(&mut rng);
                                out.push((org + dir * r).to_array());
                                break;
                            }
                            ray = Ray::new(hit.point + dir * 1e-6, dir);
                            continue;
                        }
                        let r = travelled + hit.t + opts.noise * normal(&mut rng);
                        out.push((org + dir * r).to_array());
                        break;
                    }
                }
                out
            })
            .collect();
        for p in pts.into_iter().flatten() {
            cloud.points.push(p);
            if let Some(s) = cloud.station_of.as_mut() {
                s.push(si as u16);
            }
        }
    }
    Ok(cloud)
}

/// Station positions written into a `.rad` file as `# rrecon station x y z` comments.
pub fn stations_in_text(text: &str) -> Vec<[f64; 3]> {
    text.lines()
        .filter_map(|l| l.trim().strip_prefix("# rrecon station"))
        .filter_map(|r| {
            let v: Vec<f64> = r
                .split_whitespace()
                .filter_map(|w| w.parse().ok())
                .collect();
            (v.len() == 3).then(|| [v[0], v[1], v[2]])
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::rooms::RoomSpec;
    use super::*;

    #[test]
    fn scan_of_the_box_room_lies_on_its_surfaces_and_not_beyond_glass() {
        let r = RoomSpec::named("rect").unwrap();
        let opts = ScanOptions {
            stations: r.stations.clone(),
            resolution: 2.0,
            noise: 0.0,
            ..Default::default()
        };
        let c = scan(&r.scene().unwrap(), &opts).unwrap();
        assert!(c.len() > 10_000, "{}", c.len());
        let same = scan(&r.scene().unwrap(), &opts).unwrap();
        assert_eq!(c, same);
        // Every point is on the floor, ceiling, a wall, or a reveal (inside the wall
        // thickness), never beyond (no exterior geometry in this scene).
        for p in &c.points {
            let [x, y, z] = *p;
            let on = |v: f64, a: f64| (v - a).abs() < 1e-6;
            let shell =
                on(z, 0.0) || on(z, 2.7) || on(x, 0.0) || on(x, 5.0) || on(y, 0.0) || on(y, 4.0);
            let reveal = x > -0.26 && x < 5.26 && y > -0.26 && y < 4.26;
            assert!(shell || reveal, "{p:?}");
        }
        assert!(c.points.iter().any(|p| p[1] < -0.01), "reveals are scanned");
    }

    /// Flush glazing returns nothing, except the stray returns asked for, each on a beam
    /// through a window and beyond it.
    #[test]
    fn stray_returns_lie_beyond_the_glass_and_only_there() {
        let r = RoomSpec::named("flush").unwrap();
        let opts = ScanOptions {
            stations: r.stations.clone(),
            resolution: 1.0,
            noise: 0.0,
            stray: 0.05,
            ..Default::default()
        };
        let scene = r.scene().unwrap();
        let outside = |p: &[f64; 3]| p[0] < -1e-6 || p[1] < -1e-6;
        let none = scan(
            &scene,
            &ScanOptions {
                stray: 0.0,
                ..opts.clone()
            },
        )
        .unwrap();
        assert!(
            !none.points.iter().any(outside),
            "flush glazing: nothing beyond"
        );
        let c = scan(&scene, &opts).unwrap();
        let stations = c.station_of.as_ref().unwrap();
        let mut strays = 0;
        for (p, &s) in c.points.iter().zip(stations) {
            if !outside(p) {
                continue;
            }
            strays += 1;
            // Where the beam crossed the wall: the south wall y = 0 (window x 1.2-2.8, z
            // 0.85-2.15) or the west wall x = 0 (arch y 2.3-3.4, z 0.9-2.45).
            let st = Vec3::from(r.stations[s as usize]);
            let d = Vec3::from(*p) - st;
            let (k, lo, hi) = if p[1] < -1e-6 {
                (1, [1.2, 0.85], [2.8, 2.15])
            } else {
                (0, [2.3, 0.9], [3.4, 2.45])
            };
            let t = -st[k] / d[k];
            let q = st + d * t;
            let (u, z) = (if k == 1 { q.x } else { q.y }, q.z);
            assert!(
                u > lo[0] - 1e-6 && u < hi[0] + 1e-6 && z > lo[1] - 1e-6 && z < hi[1] + 1e-6,
                "{p:?} came through the wall at {u} {z}"
            );
            assert!((Vec3::from(*p) - q).length() >= 0.05 - 1e-9);
        }
        // A twentieth of the beams through two windows of 3.7 m2 at about 2-3 m.
        assert!((30..3000).contains(&strays), "{strays}");
        assert_eq!(
            c,
            scan(&scene, &opts).unwrap(),
            "the same seed, the same strays"
        );
    }
}
