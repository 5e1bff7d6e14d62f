//! BVH build time and ray throughput on random triangle soups (10k, 100k, 1M triangles) with
//! random incoherent rays, on 1 and 2 threads (rayon).
//!
//! Run: `cargo bench --bench bvh` (plain `main`, `harness = false`). Prints one line per case;
//! nothing is asserted (timings depend on the machine).

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

/// `n` random triangles in a 10 m cube, sized so that a ray meets one every metre or so.
fn soup(n: usize, seed: u64) -> Vec<Object> {
    let mut r = Pcg64::seed_from_u64(seed);
    let size = 10.0 / (n as f64).cbrt() * 1.5;
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
    println!("triangles  build_s  threads  closest_Mrays/s  occluded_Mrays/s  hit_fraction");
    for n in [10_000, 100_000, 1_000_000] {
        let objs = soup(n, n as u64);
        let t = Instant::now();
        let bvh = Bvh::build(&objs).expect("valid soup");
        let build = t.elapsed().as_secs_f64();
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
                "{n:>9}  {build:>7.3}  {threads:>7}  {:>15.2}  {:>16.2}  {:>12.3}",
                nrays as f64 / closest / 1e6,
                nrays as f64 / occl / 1e6,
                hits as f64 / nrays as f64
            );
        }
    }
}
