//! rcalib's forward model step by step against real Radiance (issue 22):
//! `radiance-fixtures/calib/` holds, for 11 London steps (clear, intermediate, overcast,
//! faint sun) and 8 sensors of the example office, `gendaylit -W dni dhi` + `rtrace -I`
//! illuminances at converged settings, two independent runs each
//! (`make_calib_fixtures.sh`).
//!
//! - `truths_converge_far_below_the_differences_tested`: the two runs of every step agree
//!   to well within the 3.7-4.6 % reported (measured: per-step mean of the per-sensor
//!   run differences at most 0.3 %).
//! - `per_step_table_within_the_known_bound` (traces the coefficients into a fresh cache, 12 s in the
//!   test profile on 2 cores) prints the per-step, per-sensor error of the simulator
//!   with each sky and asserts the one that matches gendaylit: gendaylit's sky with every
//!   bin averaged over the directions the scene's paths take into it
//!   ([`step_skies_seen`]). Measured (office, `Settings::truth`), step means: gendaymtx's
//!   sky +0.5 to +2.2 %; gendaylit's averaged per bin's solid angle -0.7 to -4.3 %; averaged
//!   over the escapes -0.29 to +0.21 % (MF 1, sensors -1.8 to +3.0 %) and -0.16 to +0.18 %
//!   (MF 4, sensors within 1.2 %).
use rdaylight_calib::inputs::load_sensors;
use rdaylight_calib::simulate::{
    Components, Settings, Simulator, StepSkyModel, step_skies_seen, step_skies_with, subset_wea,
};
use rdaylight_formats::scene::{LoadOptions, load};
use rdaylight_formats::weather::Weather;
use std::path::{Path, PathBuf};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../radiance-fixtures/calib")
}

/// One truth row: scene, step (1-based), sensor (1-based), the two runs in lux.
struct Truth {
    scene: String,
    step: usize,
    sensor: usize,
    runs: [f64; 2],
}

fn truths() -> Vec<Truth> {
    let text = std::fs::read_to_string(fixtures().join("truth.tsv")).unwrap();
    text.lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split('\t').collect();
            let n = |k: usize| f[k].parse::<f64>().unwrap();
            Truth {
                scene: f[0].to_string(),
                step: n(1) as usize,
                sensor: n(7) as usize,
                runs: [n(8), n(9)],
            }
        })
        .collect()
}

#[test]
fn truths_converge_far_below_the_differences_tested() {
    let t = truths();
    let scenes: std::collections::BTreeSet<&str> = t.iter().map(|r| r.scene.as_str()).collect();
    for scene in scenes {
        for step in 1..=11 {
            let rows: Vec<&Truth> = t
                .iter()
                .filter(|r| r.scene == scene && r.step == step)
                .collect();
            assert_eq!(rows.len(), 8, "{scene} step {step}");
            let mean = rows
                .iter()
                .map(|r| (r.runs[0] - r.runs[1]) / (0.5 * (r.runs[0] + r.runs[1])))
                .sum::<f64>()
                / 8.0;
            // Measured: at most 0.3 % (office); the effect under test is 3.7-4.6 %.
            assert!(
                mean.abs() < 0.005,
                "{scene} step {step}: runs differ by {mean}"
            );
        }
    }
}

/// Traces the coefficients into a fresh cache (12 s in the test profile on 2 cores), so a
/// change to the tracer or the sky cannot hide behind cached numbers; prints the table.
#[test]
fn per_step_table_within_the_known_bound() {
    let cache = tempfile::tempdir().unwrap();
    // gendaylit's sky seen as the scene's paths see it must match real gendaylit + rtrace
    // per step. Bound: the truths' own noise (their two runs' step means differ by up to
    // 0.3 %, the coefficients are sampled to 0.5 % per sensor) plus a 0.7 % budget; the
    // measured worst step is 0.29 % (MF 1). Per sensor 4 %: one escape profile serves all
    // sensors, and at MF 1 a 12 deg bin hides how each sees the horizon (measured worst
    // +3.0 %, sensor 5; 1.2 % at MF 4).
    let mut worst: f64 = 0.0;
    let mut worst_sensor: f64 = 0.0;
    let dir = fixtures();
    let t = truths();
    for scene_name in ["office", "office_open"] {
        let file = match scene_name {
            "office" => dir.join("../scenes/office.rad"),
            _ => dir.join("office_open.rad"),
        };
        if !t.iter().any(|r| r.scene == scene_name) {
            continue;
        }
        let scene = load(&[file.to_str().unwrap()], &LoadOptions::from_env()).unwrap();
        let sensors = load_sensors(dir.join("sensors.pts").to_str().unwrap()).unwrap();
        let w = Weather::read_path(dir.join("steps.wea").to_str().unwrap()).unwrap();
        let idx: Vec<usize> = (0..w.steps.len()).collect();
        let mf = std::env::var("MF")
            .ok()
            .and_then(|m| m.parse().ok())
            .unwrap_or(1);
        let settings = Settings {
            mf,
            ..Settings::truth()
        };
        let sim = Simulator::new(
            settings,
            Some(cache.path().to_path_buf()),
            &sensors,
            subset_wea(&w, &idx),
        )
        .unwrap();
        let d = sim.dcs(&scene).unwrap();
        let seen = sim.seen_sky(&scene).unwrap();
        for (name, seen_model) in [
            ("gendaymtx", None),
            ("gendaylit (solid-angle mean per bin)", Some(false)),
            ("gendaylit (mean over the escapes)", Some(true)),
        ] {
            eprintln!("{scene_name}, {name} sky, MF {mf}: per-sensor error %, step mean");
            let skies = match seen_model {
                None => step_skies_with(&w, &idx, mf, StepSkyModel::Gendaymtx),
                Some(false) => step_skies_with(&w, &idx, mf, StepSkyModel::Gendaylit),
                Some(true) => step_skies_seen(&w, &idx, mf, &seen),
            };
            let ours = Components::new(&d, &skies).total();
            for (k, sk) in skies.iter().enumerate() {
                let mut line = format!(
                    "{:2}/{:2} {:5.2} dni {:3} dhi {:3} eps {:.3}:",
                    sk.month, sk.day, sk.hour, sk.dni, sk.dhi, sk.clearness
                );
                let mut mean = 0.0;
                for r in t
                    .iter()
                    .filter(|r| r.scene == scene_name && r.step == k + 1)
                {
                    let truth = 0.5 * (r.runs[0] + r.runs[1]);
                    let e = ours[(r.sensor - 1) * skies.len() + k] / truth - 1.0;
                    mean += e / sensors.len() as f64;
                    if seen_model == Some(true) && scene_name == "office" {
                        worst_sensor = worst_sensor.max(e.abs());
                    }
                    line += &format!(" {:+.1}", 100.0 * e);
                }
                eprintln!("{line} | {:+.2}", 100.0 * mean);
                if seen_model == Some(true) && scene_name == "office" {
                    worst = worst.max(mean.abs());
                }
            }
        }
    }
    assert!(worst < 0.01, "worst step mean {:.2} %", 100.0 * worst);
    assert!(
        worst_sensor < 0.04,
        "worst sensor {:.2} %",
        100.0 * worst_sensor
    );
}
