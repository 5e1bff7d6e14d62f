//! rcalib's forward model step by step against real Radiance (issue 22):
//! `radiance-fixtures/calib/` holds, for 11 London steps (clear, intermediate, overcast,
//! faint sun) and 8 sensors of the example office, `gendaylit -W dni dhi` + `rtrace -I`
//! illuminances at converged settings, two independent runs each
//! (`make_calib_fixtures.sh`).
//!
//! - `truths_converge_far_below_the_differences_tested`: the two runs of every step agree
//!   to well within the 3.7-4.6 % reported (measured: per-step mean of the per-sensor
//!   run differences at most 0.3 %).
//! - `per_step_table` (ignored: it traces the coefficients, ~1 CPU-minute in release) prints
//!   the per-step, per-sensor error of the simulator with each [`StepSkyModel`]. Measured
//!   (office, MF 1, `Settings::truth`): gendaymtx's sky +1.2 to +2.2 % per step (back
//!   sensors +3 to +6 %), faint-sun steps 0.6-1.0 % below the overcast ones; gendaylit's sky
//!   averaged per bin -0.7 to -4.3 %. Not yet within the noise: see the README there.
use rdaylight_calib::inputs::load_sensors;
use rdaylight_calib::simulate::{
    Components, Settings, Simulator, StepSkyModel, step_skies_with, subset_wea,
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

#[test]
#[ignore = "traces the coefficients (about a CPU-minute in release); prints the table"]
fn per_step_table_within_the_known_bound() {
    // The default (gendaymtx) step sky measured +0.5 to +2.2 % per step mean against real
    // gendaylit + rtrace (issue 22: gendaylit's ground jump at DNI > 0 and its horizon blend
    // are not modelled yet). This guards that state: a step mean beyond 3 % fails.
    let mut worst: f64 = 0.0;
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
        let skies = step_skies_with(&w, &idx, mf, StepSkyModel::Gendaymtx);
        let sim = Simulator::new(
            settings,
            Some(std::env::temp_dir().join("rcalib-forward-cache")),
            &sensors,
            subset_wea(&w, &idx),
            &skies,
        )
        .unwrap();
        let d = sim.dcs(&scene).unwrap();
        for model in [StepSkyModel::Gendaymtx, StepSkyModel::Gendaylit] {
            eprintln!("{scene_name}, {model:?} sky, MF {mf}: per-sensor error %, step mean");
            let skies = step_skies_with(&w, &idx, mf, model);
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
                    line += &format!(" {:+.1}", 100.0 * e);
                }
                eprintln!("{line} | {:+.2}", 100.0 * mean);
                if model == StepSkyModel::Gendaymtx && scene_name == "office" {
                    worst = worst.max(mean.abs());
                }
            }
        }
    }
    assert!(worst < 0.03, "worst step mean {:+.2} %", 100.0 * worst);
}
