//! BVH build time and ray throughput on random triangle soups (10k, 100k, 1M triangles) with
//! random incoherent rays, on 1 and 2 threads (rayon).
//!
//! Run: `cargo bench --bench bvh` (plain `main`, `harness = false`). Prints one line per case;
//! nothing is asserted (timings depend on the machine).
//!
//! `obvhs_f32` is the baseline: obvhs' own CWBVH over its `f32` `Triangle`s with its own
//! intersection, same preset, same rays, one thread; the gap to our closest-hit column is the
//! cost of the `f64` exact layer (enum dispatch, `f64` Möller–Trumbore, recentring, clipping).

use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;
use rdaylight::geometry::{Bvh, Object, Ray, Shape, Vec3};

fn unit(r: &mut Pcg64) -> Vec3 {
    loop {
        let p = Vec3::new(
            r.random_range(-1.0..1.0),
            r.random_range(-1.0..1.0),
            r.random_range(-1.0..1.0),
        );
        let l = p.length();
        if l > 0.1 && l <= 1.0 {
            return p / l;
        }
    }
}

/// `n` random triangles in a 10 m cube, each about half the mean spacing across, so that
/// boxes overlap little (a denser soup measures overlap, not the BVH).
fn soup(n: usize, seed: u64) -> Vec<Object> {
    let mut r = Pcg64::seed_from_u64(seed);
    let size = 10.0 / (n as f64).cbrt() * 0.5;
    (0..n)
        .map(|i| {
            let c = Vec3::new(
                r.random_range(-5.0..5.0),
                r.random_range(-5.0..5.0),
                r.random_range(-5.0..5.0),
            );
            let vertices = (0..3)
                .map(|_| (c + unit(&mut r) * size).to_array())
                .collect();
            Object {
                shape: Shape::Polygon { vertices },
                id: i as u32,
            }
        })
        .collect()
}

fn main() {
    let nrays = 1_000_000;
    let mut r = Pcg64::seed_from_u64(99);
    let rays: Vec<Ray> = (0..nrays)
        .map(|_| {
            let o = Vec3::new(
                r.random_range(-5.0..5.0),
                r.random_range(-5.0..5.0),
                r.random_range(-5.0..5.0),
            );
            Ray::new(o, unit(&mut r))
        })
        .collect();
    println!(
        "triangles  build_s  threads  closest_Mrays/s  occluded_Mrays/s  hit_fraction  obvhs_f32_Mrays/s"
    );
    for n in [10_000, 100_000, 1_000_000] {
        let objs = soup(n, n as u64);
        let t = Instant::now();
        let bvh = Bvh::build(&objs).expect("valid soup");
        let build = t.elapsed().as_secs_f64();
        let baseline = obvhs_baseline(&objs, &rays);
        drop(objs);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("thread pool");
            let (closest, hits) = pool.install(|| {
                let t = Instant::now();
                let hits: usize = rays
                    .par_iter()
                    .with_min_len(4096)
                    .map(|ray| bvh.intersect(ray, 0.0, f64::INFINITY).is_some() as usize)
                    .sum();
                (t.elapsed().as_secs_f64(), hits)
            });
            let occl = pool.install(|| {
                let t = Instant::now();
                let blocked: usize = rays
                    .par_iter()
                    .with_min_len(4096)
                    .map(|ray| bvh.occluded(ray, 2.0) as usize)
                    .sum();
                std::hint::black_box(blocked);
                t.elapsed().as_secs_f64()
            });
            println!(
                "{n:>9}  {build:>7.3}  {threads:>7}  {:>15.2}  {:>16.2}  {:>12.3}  {:>17.2}",
                nrays as f64 / closest / 1e6,
                nrays as f64 / occl / 1e6,
                hits as f64 / nrays as f64,
                baseline
            );
        }
    }
}

/// Mrays/s of obvhs alone (f32 triangles, closest hit, one thread).
fn obvhs_baseline(objs: &[Object], rays: &[Ray]) -> f64 {
    use obvhs::{
        BvhBuildParams, cwbvh::builder::build_cwbvh_from_tris, ray::Ray as FRay, ray::RayHit,
        triangle::Triangle,
    };
    let tris: Vec<Triangle> = objs
        .iter()
        .map(|o| match &o.shape {
            Shape::Polygon { vertices } => {
                let f = |i: usize| Vec3::from(vertices[i]).to_f32().into();
                Triangle {
                    v0: f(0),
                    v1: f(1),
                    v2: f(2),
                }
            }
            _ => unreachable!("the soup has only triangles"),
        })
        .collect();
    let bvh = build_cwbvh_from_tris(
        &tris,
        BvhBuildParams::medium_build(),
        &mut std::time::Duration::default(),
    );
    let t = Instant::now();
    let mut hits = 0usize;
    for r in rays {
        let ray = FRay::new_inf(r.org.to_f32().into(), r.dir.to_f32().into());
        let mut h = RayHit::none();
        if bvh.ray_traverse(ray, &mut h, |ray, id| {
            tris[bvh.primitive_indices[id] as usize].intersect(ray)
        }) {
            hits += 1;
        }
    }
    std::hint::black_box(hits);
    rays.len() as f64 / t.elapsed().as_secs_f64() / 1e6
}
