//! Past parsing: any text that parses as a `.rad` scene (inline commands refused) either
//! compiles for the tracer (materials through modifier chains, `.cal` patterns, surfaces,
//! one BVH) or is rejected with an error, never a panic; a scene that compiles traces a
//! few short paths (sky coefficients, two bounces, four samples, one thread) from its
//! centre and from a fixed point without a panic. Issue #19 found a BVH panic on huge
//! coordinates here.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::formats::sensors::SensorRay;
use rdaylight::rdc::{Config, Sampling, Tracer};
use rdaylight::scene::{LoadOptions, parse_str, refuse_exec};

fuzz_target!(|data: &[u8]| {
    refuse_exec();
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let opts = LoadOptions {
        allow_exec: false,
        ..LoadOptions::default()
    };
    // No folder to look in: `.cal` and data files named by the scene are not found (or
    // found in the working folder and on RAYPATH, only read).
    let dir = std::env::temp_dir().join("rdaylight-fuzz-empty");
    let Ok(scene) = parse_str(text, "fuzz.rad", &dir, &opts) else {
        return;
    };
    let sampling = Sampling {
        ab: 2,
        ad: 4,
        lw: 1e-3,
        ..Sampling::default()
    };
    let config = Config {
        threads: Some(1),
        ..Config::sky_coefficients(1, sampling)
    };
    let Ok(tracer) = Tracer::new(&config, &scene) else {
        return;
    };
    let mut rays = vec![SensorRay::new([0.0, 0.0, 0.5], [0.0, 0.0, 1.0])];
    if let Some(b) = scene.bounding_box() {
        let c = [0, 1, 2].map(|k| 0.5 * (b.min[k] + b.max[k]));
        rays.push(SensorRay::new(c, [0.3, -0.2, 0.9]));
    }
    if let Ok(rows) = tracer.compute(&rays) {
        assert_eq!(rows.len(), rays.len());
    }
});
