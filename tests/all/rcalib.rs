//! rcalib: input errors, and hidden-effect cases end to end (explain names the hidden
//! effect, the control reports nothing, the applied model is within 1.3 x the noise-only
//! error). The full hit-rate table is `tests/all/rcalib_hits.rs` (ignored; minutes).
//!
//! Readings are simulated from the truth at converged settings ([`Settings::truth`]: 0.5 %
//! per sensor) with the sensor noise; the noise-only error is the readings against
//! those noise-free values. The applied model is re-simulated at the model's settings
//! (1 % per sensor), so what separates it from the noise-only error is the fit and the
//! model's own simulation error (the hit-rate table prints both).

use rdaylight::calib::cases::*;
use rdaylight::calib::effects::Effect;
use rdaylight::calib::room::SurfaceClass;
use rdaylight::calib::score::DEFAULT_SENSOR_SIGMA;
use rdaylight::calib::session::Options;
use rdaylight::calib::simulate::Settings;
use rdaylight::calib::tmscan;
use rdaylight::formats::weather::Weather;
use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn london() -> Weather {
    Weather::read_path(repo().join("examples/weather/GBR_London.Gatwick.037760_IWEC.epw")).unwrap()
}

/// The daylight-coefficient cache of these tests, seeded from the committed
/// `tests/data/rcalib-cache/` (the coefficients of the cases `make test` runs, about 11 min
/// of tracing on 2 cores otherwise); `make rcalib-cache` regenerates the fixture from an
/// empty cache ([`crate::common::seeded_cache`]).
fn cache() -> PathBuf {
    crate::common::seeded_cache("rcalib-test-cache", &repo().join("tests/data/rcalib-cache"))
}

fn rcalib() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rcalib"))
}

/// Run a case and check the acceptance rule of issue 7: the hidden effect found, and the
/// applied model within `factor` x the noise-only error (1.3 in the issue; a looser factor
/// is given, with the reason, where the fitted parameters are right but the coefficient
/// model's approximations leave more: see the hit-rate table of tests/all/rcalib_hits.rs).
fn check(kind: RoomKind, w: Weather, name: &str, hidden: Vec<Effect>, factor: f64) {
    let case = generate(
        name,
        kind,
        w,
        hidden,
        24,
        3,
        &Options {
            settings: Settings::truth(),
            cache: Some(cache()),
            ..Options::default()
        },
    )
    .unwrap();
    let opts = Options {
        cache: Some(cache()),
        ..Options::default()
    };
    let o = evaluate(&case, &opts, DEFAULT_SENSOR_SIGMA).unwrap();
    eprintln!("{name}: {o:?}");
    assert!(
        o.hit,
        "{name}: hidden {:?}, selected {:?}, ranking {:?}",
        o.hidden, o.specs, o.ranking
    );
    assert!(
        o.rmse_after <= factor * o.rmse_noise,
        "{name}: RMSE_rel after apply {:.1} % vs noise-only {:.1} %",
        o.rmse_after,
        o.rmse_noise
    );
    if !o.hidden.is_empty() {
        assert!(
            o.rmse_before > 2.0 * o.rmse_noise,
            "{name}: the hidden effect is visible"
        );
    }
}

#[test]
fn transmittance_in_the_office_under_london_skies() {
    check(
        RoomKind::Office,
        london(),
        "transmittance",
        vec![Effect::Transmittance { scale: 0.7 }],
        // Measured 1.03x (0.707 for 0.7; a floor scale of 0.955 also kept).
        1.3,
    );
}

#[test]
fn control_reports_nothing_missing() {
    check(RoomKind::Office, london(), "control", vec![], 1.3);
}

#[test]
fn seed_transmittance_scan_selects_the_dirty_glass() {
    let case = generate(
        "tmscan",
        RoomKind::Office,
        london(),
        vec![Effect::Transmittance { scale: 0.7 }],
        24,
        3,
        &Options {
            settings: Settings::truth(),
            cache: Some(cache()),
            ..Options::default()
        },
    )
    .unwrap();
    let opts = Options {
        cache: Some(cache()),
        ..Options::default()
    };
    let m = case.model(&case.model_text, &opts).unwrap();
    let (rows, best) = tmscan::scan(&m);
    assert_eq!(rows.len(), 15);
    assert!(rows.iter().all(|r| (0.0..=1.0).contains(&r.transmissivity)));
    // 0.96 x 0.7 = 0.672: window_neg_3 (0.96/1.375 = 0.698) or window_neg_4 (0.64).
    assert!(
        ["window_neg_3", "window_neg_4"].contains(&rows[best].name.as_str()),
        "{:?}",
        rows[best]
    );
    assert!(
        rows[best].mae < rows[7].mae / 3.0,
        "base {:?} best {:?}",
        rows[7],
        rows[best]
    );
}

/// The other rooms' hidden-effect cases (`make test-full`; issue 21): each traces its own
/// room's coefficients for minutes on 2 cores (the combined case took 490 s under load).
/// `make test` keeps the office cases above (a hidden effect found, the control clean, the
/// seed's scan), which share one room's coefficient cache.
mod full {
    use super::*;

    #[test]
    fn obstruction_of_the_two_window_room_under_sunny_skies() {
        check(
            RoomKind::TwoWindow,
            sunny_weather(),
            "obstruction",
            vec![Effect::Obstruction {
                azimuth: 200.0,
                half_width: 45.0,
                altitude: 30.0,
            }],
            // Fitted 199.5,44.5,29.4: 4.1 % against 3.4 % noise-only, 1.21x (the model's own
            // simulation error of this scene: 2.3 %).
            1.3,
        );
    }

    #[test]
    fn dark_walls_in_the_deep_room() {
        check(
            RoomKind::Deep,
            sunny_weather(),
            "walls",
            vec![Effect::Reflectance {
                class: SurfaceClass::Walls,
                scale: 0.5,
            }],
            // Fitted 0.520 for 0.5: 3.6 % against 3.3 % noise-only, 1.09x (was 4.0x when the
            // inter-reflected sun was traced per step at a fixed -ad 2048: 10-20 % noise at
            // the deep sensors).
            1.3,
        );
    }

    #[test]
    fn faulty_sensor_in_the_two_window_room() {
        check(
            RoomKind::TwoWindow,
            london(),
            "sensor-fault",
            vec![Effect::SensorFault {
                factors: vec![(4, 0.6)],
            }],
            1.3,
        );
    }

    #[test]
    fn combined_transmittance_and_obstruction() {
        check(
            RoomKind::TwoWindow,
            sunny_weather(),
            "transmittance+obstruction",
            vec![
                Effect::Transmittance { scale: 0.75 },
                Effect::Obstruction {
                    azimuth: 160.0,
                    half_width: 40.0,
                    altitude: 28.0,
                },
            ],
            // Fitted 159.5,38.5,29.4 and 0.761 for 160,40,28 and 0.75: 4.2 % against 3.4 %
            // noise-only, 1.26x.
            1.3,
        );
    }
}

/// Files for the CLI error tests: two sensors, two weather steps, readings `body`.
fn inputs(dir: &Path, body: &str) -> Vec<String> {
    std::fs::write(
        dir.join("s.csv"),
        "id,x,y,z,dx,dy,dz\na,1,1,0.8,0,0,1\nb,3,4,0.8,0,0,1\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("w.wea"),
        "place London_GBR\nlatitude 51.15\nlongitude 0.18\ntime_zone 0\nsite_elevation 62\n\
         weather_data_file_units 1\n6 21 12.5 500 120\n6 21 13.5 450 130\n",
    )
    .unwrap();
    std::fs::write(dir.join("m.csv"), body).unwrap();
    [
        "compare",
        repo().join("examples/room/room.rad").to_str().unwrap(),
        "--sensors",
        dir.join("s.csv").to_str().unwrap(),
        "--weather",
        dir.join("w.wea").to_str().unwrap(),
        "--measured",
        dir.join("m.csv").to_str().unwrap(),
        "--no-cache",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

#[test]
fn bad_readings_are_reported_with_their_csv_line() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "month,day,hour,sensor,lux\n6,21,12.5,a,100\n6,21,12.5,zz,1\n",
            "m.csv:3: unknown sensor id 'zz'",
        ),
        (
            "month,day,hour,sensor,lux\n6,21,9.5,a,100\n",
            "m.csv:2: time 6 21 9.5 is not a time step",
        ),
        (
            "month,day,hour,sensor,lux\n6,21,12.5,a,-4\n",
            "m.csv:2: negative illuminance -4 for lux; expected a value >= 0",
        ),
        (
            "month,day,hour,sensor,lux\n6,21,12.5,a,\n",
            "m.csv:2: expected a number for lux, found a missing value",
        ),
    ];
    for (body, want) in cases {
        let out = rcalib().args(inputs(dir.path(), body)).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains(want), "want '{want}' in: {err}");
        assert_eq!(err.lines().count(), 1, "one line: {err}");
        assert!(out.stdout.is_empty());
    }
}

#[test]
fn cli_compare_on_the_bundled_case_and_after_the_known_fix() {
    let dir = tempfile::tempdir().unwrap();
    let ex = repo().join("examples/calib");
    let common = |scene: &Path| -> Vec<String> {
        vec![
            "compare".into(),
            scene.display().to_string(),
            "--sensors".into(),
            ex.join("sensors.csv").display().to_string(),
            "--weather".into(),
            ex.join("weather.wea").display().to_string(),
            "--measured".into(),
            ex.join("measured.csv").display().to_string(),
            "--cache".into(),
            cache().display().to_string(),
        ]
    };
    let report = dir.path().join("r.html");
    let json = dir.path().join("r.json");
    let mut args = common(&ex.join("truth.rad"));
    args.extend([
        "--before".to_string(),
        ex.join("model.rad").display().to_string(),
        "--report".into(),
        report.display().to_string(),
        "--json".into(),
        json.display().to_string(),
    ]);
    let out = rcalib().args(&args).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // "RMSE_rel A % -> B %": the truth model is far closer than the model.
    let line = text.lines().find(|l| l.starts_with("RMSE_rel")).unwrap();
    let nums: Vec<f64> = line
        .split_whitespace()
        .filter_map(|w| w.parse().ok())
        .collect();
    assert!(nums[1] < nums[0] / 2.0, "{line}");
    let html = std::fs::read_to_string(&report).unwrap();
    assert!(
        html.matches("<svg").count() >= 12,
        "before and after figures side by side"
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["comparisons"].as_array().unwrap().len(), 2);
}

/// Issue 22: spectral readings that cover only some sensors. Without `--control` the
/// control is the sensor nearest a window among those with readings (not the window
/// sensor without any, whose window options would all score MAE 0); naming a sensor
/// without readings is refused with the ones that have them.
#[test]
fn spectral_control_is_a_sensor_with_readings() {
    let dir = tempfile::tempdir().unwrap();
    let src = repo().join("examples/calib-spectral");
    for f in ["model.rad", "sensors.csv", "weather.wea"] {
        std::fs::copy(src.join(f), dir.path().join(f)).unwrap();
    }
    let measured = std::fs::read_to_string(src.join("measured.csv")).unwrap();
    let kept: String = measured
        .lines()
        .filter(|l| !l.contains(",control,"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(dir.path().join("measured.csv"), kept).unwrap();
    let run = |extra: &[&str]| {
        rcalib()
            .current_dir(dir.path())
            .args(["spectral", "model.rad", "--sensors", "sensors.csv"])
            .args(["--weather", "weather.wea", "--measured", "measured.csv"])
            .args(["--cache"])
            .arg(cache())
            .args(extra)
            .output()
            .unwrap()
    };
    let out = run(&[]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("at control sensor s01"), "{text}");
    // Options differ in MAE (no tie of zeros).
    assert!(!text.contains(" 0.0000e0 "), "{text}");
    let out = run(&["--control", "control"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        err.contains("no spectral readings") && err.contains("s01, s03, s05, s09"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
}
