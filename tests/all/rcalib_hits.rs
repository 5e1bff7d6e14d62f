//! The hit-rate table of `rcalib explain` on hidden-effect cases: every hidden effect of
//! [`hidden_effects`] in every room and climate. Slow (minutes): `cargo test --release
//! --test all rcalib_hits:: -- --ignored --nocapture`, or `benches/rcalib_hits.sh`.

use rdaylight::calib::cases::*;
use rdaylight::calib::score::DEFAULT_SENSOR_SIGMA;
use rdaylight::calib::session::Options;
use rdaylight::calib::simulate::Settings;
use rdaylight::formats::weather::Weather;

fn london() -> Weather {
    Weather::read_path(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/weather/GBR_London.Gatwick.037760_IWEC.epw"
    ))
    .unwrap()
}

#[test]
#[ignore]
fn hit_rate_table() {
    let only = std::env::var("RCALIB_ONLY").ok();
    let cache = std::env::temp_dir().join("rcalib-hits-cache");
    let mut settings = Settings::model();
    if let Some(mf) = std::env::var("RCALIB_MF").ok().and_then(|s| s.parse().ok()) {
        settings.mf = mf;
    }
    let opts = Options {
        cache: Some(cache.clone()),
        settings: settings.clone(),
        ..Options::default()
    };
    let steps: usize = std::env::var("RCALIB_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(30);
    println!(
        "| room | climate | hidden | ranked first / selected | hit | RMSE_rel before | after apply | noise-only | after/noise | fit vs applied | simulation error | s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    let (mut hits, mut passes, mut total) = (0, 0, 0);
    // RCALIB_ONLY, RCALIB_ROOM and RCALIB_CLIMATE: comma-separated substrings of the
    // effect, room and climate names to keep (quick subsets of the table).
    let keep = |var: &Option<String>, name: &str| {
        var.as_deref()
            .is_none_or(|o| o.split(',').any(|x| name.contains(x)))
    };
    let only_room = std::env::var("RCALIB_ROOM").ok();
    let only_climate = std::env::var("RCALIB_CLIMATE").ok();
    for kind in RoomKind::ALL {
        for climate in [Climate::London, Climate::Sunny] {
            if !keep(&only_room, kind.name()) || !keep(&only_climate, climate.name()) {
                continue;
            }
            for (name, hidden) in hidden_effects(kind) {
                if !keep(&only, &name) {
                    continue;
                }
                let w = match climate {
                    Climate::London => london(),
                    Climate::Sunny => sunny_weather(),
                };
                let case = generate(
                    &name,
                    kind,
                    w,
                    hidden,
                    steps,
                    1,
                    &Options {
                        settings: Settings::truth(),
                        cache: Some(cache.clone()),
                        ..Options::default()
                    },
                )
                .unwrap();
                let o = evaluate(&case, &opts, DEFAULT_SENSOR_SIGMA).unwrap();
                total += 1;
                hits += o.hit as usize;
                passes += o.passes(1.3) as usize;
                println!(
                    "| {} | {} | {} | {} / {} | {} | {:.1} | {:.1} | {:.1} | {:.2} | {:.1} | {:.1} | {:.1} |",
                    kind.name(),
                    climate.name(),
                    name,
                    o.ranking.first().cloned().unwrap_or_default(),
                    if o.specs.is_empty() {
                        "none".to_string()
                    } else {
                        o.specs.join(" ")
                    },
                    if o.hit { "yes" } else { "no" },
                    o.rmse_before,
                    o.rmse_after,
                    o.rmse_noise,
                    o.rmse_after / o.rmse_noise,
                    o.rmse_fit_vs_apply,
                    o.rmse_sim,
                    o.seconds
                );
                if std::env::var("RCALIB_ORACLE").is_ok() && !o.hidden.is_empty() {
                    let r = oracle_rmse(&case, &opts, 1.01).unwrap();
                    println!(
                        "|   oracle: hidden effects x 1.01 applied: RMSE_rel {r:.1} ({:.2} x noise-only)",
                        r / o.rmse_noise
                    );
                }
                if std::env::var("RCALIB_WORST").is_ok() {
                    for w in &o.worst {
                        println!("|   worst: {w}");
                    }
                }
            }
        }
    }
    println!("\nhits {hits}/{total}; hit and after <= 1.3 x noise: {passes}/{total}");
    assert!(total > 0, "no case matched RCALIB_ONLY/ROOM/CLIMATE");
    // The README's figures (57/60 found, 52/60 within 1.3x of the noise-only error) with a
    // margin of two or three cases for Monte Carlo noise; only the full table (all 60
    // cases at the default 30 steps) is held to them, a subset is a diagnostic.
    let subset = only.is_some() || only_room.is_some() || only_climate.is_some();
    if !subset && steps == 30 {
        assert_eq!(total, 60, "the table has 3 rooms x 2 climates x 10 cases");
        assert!(
            hits >= 55,
            "hidden effect found in {hits}/60; README: 57/60"
        );
        assert!(
            passes >= 50,
            "after apply within 1.3x of the noise in {passes}/60; README: 52/60"
        );
    }
}

/// How well the coefficient model reproduces the truth when given the hidden effect's true
/// parameters: RMSE_rel of `Model::predict(hidden)` against the noise-free truth
/// simulation, overall and split into steps with and without direct sun at the sensor.
/// A fit can be no better than this. `RCALIB_ONLY` etc. as for the table.
#[test]
#[ignore]
fn fidelity_table() {
    let only = std::env::var("RCALIB_ONLY").ok();
    let cache = std::env::temp_dir().join("rcalib-hits-cache");
    let opts = Options {
        cache: Some(cache.clone()),
        reflectance: true,
        ..Options::default()
    };
    let keep = |var: &Option<String>, name: &str| {
        var.as_deref()
            .is_none_or(|o| o.split(',').any(|x| name.contains(x)))
    };
    let only_room = std::env::var("RCALIB_ROOM").ok();
    let only_climate = std::env::var("RCALIB_CLIMATE").ok();
    println!(
        "| room | climate | hidden | model vs truth RMSE_rel % | mean bias % | sun steps | other |"
    );
    println!("|---|---|---|---|---|---|---|");
    let (mut worst, mut cases) = (0.0f64, 0);
    for kind in RoomKind::ALL {
        for climate in [Climate::London, Climate::Sunny] {
            if !keep(&only_room, kind.name()) || !keep(&only_climate, climate.name()) {
                continue;
            }
            for (name, hidden) in hidden_effects(kind) {
                if !keep(&only, &name) {
                    continue;
                }
                let w = match climate {
                    Climate::London => london(),
                    Climate::Sunny => sunny_weather(),
                };
                let case = generate(
                    &name,
                    kind,
                    w,
                    hidden.clone(),
                    30,
                    1,
                    &Options {
                        settings: Settings::truth(),
                        cache: Some(cache.clone()),
                        ..Options::default()
                    },
                )
                .unwrap();
                let m = case.model(&case.model_text, &opts).unwrap();
                let pred = m.predict(&hidden);
                let (mut all, mut sun, mut other, mut bias) = (vec![], vec![], vec![], 0.0);
                for ((p, t), o) in pred.iter().zip(&case.truth_values).zip(&m.obs) {
                    if *t < 1.0 {
                        continue;
                    }
                    let e = p / t - 1.0;
                    bias += e;
                    all.push(e);
                    if m.comps.sun_direct[o.sensor * m.nsteps() + o.step] > 0.0 {
                        sun.push(e);
                    } else {
                        other.push(e);
                    }
                }
                let rms = |v: &[f64]| {
                    100.0 * (v.iter().map(|e| e * e).sum::<f64>() / v.len().max(1) as f64).sqrt()
                };
                worst = worst.max(rms(&all));
                cases += 1;
                println!(
                    "| {} | {} | {} | {:.1} | {:+.1} | {:.1} ({}) | {:.1} ({}) |",
                    kind.name(),
                    climate.name(),
                    name,
                    rms(&all),
                    100.0 * bias / all.len().max(1) as f64,
                    rms(&sun),
                    sun.len(),
                    rms(&other),
                    other.len()
                );
            }
        }
    }
    // With the hidden effect's true parameters the coefficient model must reproduce the
    // converged truth to within the Monte Carlo error of the model's settings (README:
    // 0.7-2.3 % RMS of converged runs) plus what the effect models approximate; 10 % in
    // any case is a broken model, not noise.
    assert!(cases > 0, "no case matched RCALIB_ONLY/ROOM/CLIMATE");
    println!("\nworst model vs truth RMSE_rel: {worst:.1} % ({cases} cases)");
    assert!(worst < 10.0, "model vs truth RMSE_rel up to {worst:.1} %");
}

/// `explain` on 20 sensors x 50 steps (the office with a 4 x 5 sensor grid, sunny site,
/// hidden obstruction): building the model with its reflectance sensitivities from an empty
/// cache (tracing), again from the cache, the explain fits and their refinement. Prints the
/// timings (they depend on the machine, so nothing asserts them) and asserts the work done:
/// every reading modelled, the cached model the traced one, the obstruction found.
#[test]
#[ignore]
fn explain_timing_20_sensors_50_steps() {
    use rdaylight::calib::effects::Effect;
    use rdaylight::formats::sensors::{Sensor, SensorRay};
    let (text, _) = room(RoomKind::Office);
    let mut sensors = Vec::new();
    for y in [1.0, 2.5, 4.0, 5.5, 7.0] {
        for x in [1.0, 2.3, 3.7, 5.0] {
            sensors.push(Sensor {
                id: format!("s{:02}", sensors.len() + 1),
                ray: SensorRay::new([x, y, 0.8], [0.0, 0.0, 1.0]),
            });
        }
    }
    let cache = tempfile::tempdir().unwrap();
    let case = generate_with_sensors(
        "timing",
        &text,
        sensors,
        sunny_weather(),
        vec![Effect::Obstruction {
            azimuth: 200.0,
            half_width: 45.0,
            altitude: 30.0,
        }],
        50,
        1,
        &Options {
            settings: Settings::truth(),
            cache: Some(cache.path().to_path_buf()),
            ..Options::default()
        },
    )
    .unwrap();
    let opts = Options {
        cache: Some(cache.path().to_path_buf()),
        reflectance: true,
        ..Options::default()
    };
    let t0 = std::time::Instant::now();
    let m = case.model(&case.model_text, &opts).unwrap();
    let cold = t0.elapsed().as_secs_f64();
    let t1 = std::time::Instant::now();
    let m2 = case.model(&case.model_text, &opts).unwrap();
    let warm = t1.elapsed().as_secs_f64();
    let t2 = std::time::Instant::now();
    let ex = rdaylight::calib::explain::explain(&m2, &[], DEFAULT_SENSOR_SIGMA);
    let fit = t2.elapsed().as_secs_f64();
    let t3 = std::time::Instant::now();
    let scene = case.model_scene().unwrap();
    let ex =
        rdaylight::calib::explain::refined(&m2, ex, DEFAULT_SENSOR_SIGMA, REFINE_ROUNDS, &|e| {
            rdaylight::calib::explain::simulate_applied(
                &scene,
                &m2,
                &case.weather,
                &case.readings,
                &opts,
                e,
            )
        })
        .unwrap();
    let refine = t3.elapsed().as_secs_f64();
    assert_eq!((m.nsens(), m.nsteps()), (20, case.readings.len() / 20));
    assert_eq!(m.obs.len(), case.readings.len());
    assert!(m.nsteps() > 0 && m.nsteps() <= 50, "{} steps", m.nsteps());
    let (p1, p2) = (m.predict(&[]), m2.predict(&[]));
    assert!(
        p1.iter()
            .zip(&p2)
            .all(|(a, b)| (a - b).abs() <= 1e-9 * a.abs().max(1.0)),
        "the cached model differs from the traced one"
    );
    assert!(
        ex.specs.iter().any(|s| s.starts_with("obstruction")),
        "hidden obstruction not selected: {:?}",
        ex.specs
    );
    println!(
        "timing: {} sensors x {} steps ({} readings): model build {cold:.1} s from an empty \
         cache, {warm:.1} s cached; explain fits {fit:.1} s; {REFINE_ROUNDS} refinement \
         rounds (re-simulations) {refine:.1} s; selected {:?}",
        m.nsens(),
        m.nsteps(),
        m.obs.len(),
        ex.specs
    );
}
