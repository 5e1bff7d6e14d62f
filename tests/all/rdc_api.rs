//! The typed in-memory API (`rdc::Config` + `rdc::Tracer`) gives the same numbers as the
//! `rdc` binary: library users (rcalib, annual glare) and pipelines see one engine, and the
//! command line maps onto exactly the config a library user would write.

use crate::common;

use clap::Parser;
use rdaylight::cli::rdc::{Options, radiance_args};
use rdaylight::formats::matrix::{Matrix, MatrixReader, ReadOptions};
use rdaylight::formats::sensors::SensorRay;
use rdaylight::rdc::{Config, Sampling, Target, Tracer};
use rdaylight::scene::{self, LoadOptions};

#[test]
fn prepared_compute_equals_binary_output() {
    let room = common::repo().join("examples/room/room.rad");
    let room = room.to_str().unwrap();
    let args = ["-I", "-ab", "2", "-ad", "64", "-m", "1", "-s", "7", "-fad"];
    let sensors = "1 1 0.8 0 0 1\n3 1.5 0.8 0 0 1\n5 2 0.8 0 0 1\n";
    let out = common::run_ok(common::ours("rdc").args(args).arg(room), sensors.as_bytes());
    let mut reader = MatrixReader::new(&out[..], "<rdc>", &ReadOptions::default()).unwrap();
    let m = Matrix::read_all(&mut reader).unwrap();

    let mut cli = vec!["rdc"];
    cli.extend(args);
    cli.push(room);
    let opts = Options::parse_from(radiance_args(&cli));
    let config = Config {
        sampling: Sampling {
            ab: 2,
            ad: 64,
            ..Sampling::default()
        },
        target: Target::sky(1),
        irradiance: true,
        seed: 7,
        ..Config::default()
    };
    assert_eq!(opts.to_config().unwrap(), config);
    let scene = scene::load(&[room], &LoadOptions::default()).unwrap();
    let prepared = Tracer::new(&config, &scene).unwrap();
    let rays: Vec<SensorRay> = sensors
        .lines()
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            SensorRay::new([v[0], v[1], v[2]], [v[3], v[4], v[5]])
        })
        .collect();
    let rows = prepared.compute(&rays).unwrap();
    assert_eq!(prepared.ncols(), 146);
    assert_eq!(m.nrows, 3);
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r.values.len(), 146 * 3);
        let sum: f64 = r.values.iter().sum();
        assert!(sum > 0.0, "sensor {i}: no light");
        for (j, v) in r.values.iter().enumerate() {
            let w = m.get(i, j / 3)[j % 3];
            assert!(
                (v - w).abs() <= 1e-12 * w.abs().max(1.0),
                "({i},{j}): {v} vs {w}"
            );
        }
    }
}
