//! `rdc --suns ... --suns-ab`: sun coefficients with inter-reflection (every surface a path
//! meets looks at every sun), and `--target-se ... --se-row` (sampling each sensor until
//! its row sum is known to a relative error).
//!
//! - The sun-coefficient column of a step equals a point-in-time run of the same scene with
//!   a unit-radiance sun `source` at that step's position, same seed and settings: the two
//!   walk the same paths and do the same next-event estimation, so they agree to rounding.
//! - Against real `rtrace -I -aa 0` on that scene, within the two runs' Monte Carlo error
//!   (4 combined standard errors; Radiance's from ours scaled to its sample count).
//! - `--se-row` stops each sensor at the target, and refuses to run without a target.

use crate::common;

use rdaylight::calib::cases::{RoomKind, room};
use rdaylight::calib::simulate::step_skies;
use rdaylight::formats::weather::Weather;

/// One London step with the sun in front of the window (1 April 10:30, DNI 830 W/m2).
const WEA: &str = "place LONDON/GATWICK_GBR\nlatitude 51.15\nlongitude 0.180000\n\
time_zone -0\nsite_elevation 62\nweather_data_file_units 1\n4 1 10.500 830 97\n";

struct Case {
    dir: tempfile::TempDir,
    sensors: String,
    sun: [f64; 3],
}

fn case() -> Case {
    let dir = tempfile::tempdir().unwrap();
    let (text, sensors) = room(RoomKind::Deep);
    std::fs::write(dir.path().join("room.rad"), &text).unwrap();
    std::fs::write(dir.path().join("one.wea"), WEA).unwrap();
    let w = Weather::read_path(dir.path().join("one.wea").to_str().unwrap()).unwrap();
    let sun = step_skies(&w, &[0], 1)[0].sun_dir;
    std::fs::write(
        dir.path().join("sun.rad"),
        format!(
            "{text}\nvoid light unit_sun 0 0 3 1 1 1\nunit_sun source sun 0 0 4 {} {} {} 0.533\n",
            sun[0], sun[1], sun[2]
        ),
    )
    .unwrap();
    let sensors: String = sensors
        .iter()
        .map(|s| {
            let (o, d) = (s.ray.org, s.ray.dir);
            format!("{} {} {} {} {} {}\n", o[0], o[1], o[2], d[0], d[1], d[2])
        })
        .collect();
    Case { dir, sensors, sun }
}

/// Green channel of each row of an ascii rdc/rtrace output without header.
fn green(out: &[u8]) -> Vec<f64> {
    String::from_utf8_lossy(out)
        .lines()
        .filter_map(|l| l.split_whitespace().nth(1)?.parse().ok())
        .collect()
}

fn rdc(c: &Case, args: &[&str]) -> Vec<u8> {
    let mut cmd = common::ours("rdc");
    cmd.current_dir(c.dir.path()).args(args);
    common::run_ok(&mut cmd, c.sensors.as_bytes())
}

#[test]
fn sun_column_equals_a_traced_unit_sun() {
    let c = case();
    let common_args = [
        "-I", "-h", "-ab", "6", "-ad", "512", "-lw", "1e-4", "-s", "3",
    ];
    let mut a: Vec<&str> = common_args.to_vec();
    a.extend(["--suns", "one.wea", "--suns-ab", "room.rad"]);
    let coef = green(&rdc(&c, &a));
    // Sun coefficients do not sample the window panes (portals serve sky light), so the
    // unit sun is traced without them too: then both runs draw the same paths.
    let mut b: Vec<&str> = common_args.to_vec();
    b.extend(["-dj", "0", "--no-portals", "sun.rad"]);
    let value = green(&rdc(&c, &b));
    assert_eq!(coef.len(), 10);
    assert_eq!(value.len(), 10);
    for (i, (x, y)) in coef.iter().zip(&value).enumerate() {
        assert!(*y > 0.0, "sensor {i}: no light");
        assert!(
            (x - y).abs() <= 1e-5 * y,
            "sensor {i}: --suns-ab {x} vs unit sun source {y}"
        );
    }
    // The direct-only coefficients are smaller wherever inter-reflection adds light: the
    // deep sensors see no sun directly at all.
    let mut d: Vec<&str> = common_args.to_vec();
    d.extend(["--suns", "one.wea", "room.rad"]);
    let direct = green(&rdc(&c, &d));
    assert!(direct[9] == 0.0 && coef[9] > 0.0, "{direct:?} {coef:?}");
    assert!(c.sun[2] > 0.0);
}

#[test]
fn row_target_stops_each_sensor_at_its_error() {
    let c = case();
    let se = c.dir.path().join("se.txt");
    let se_arg = se.to_str().unwrap().to_string();
    rdc(
        &c,
        &[
            "-I",
            "-h",
            "-ab",
            "6",
            "-ad",
            "256",
            "-lw",
            "1e-5",
            "--suns",
            "one.wea",
            "--suns-ab",
            "--target-se",
            "0.02",
            "--se-row",
            "--max-samples",
            "65536",
            "--se-out",
            &se_arg,
            "room.rad",
        ],
    );
    let text = std::fs::read_to_string(&se).unwrap();
    let rows: Vec<(f64, f64)> = text
        .lines()
        .filter_map(|l| {
            let mut w = l.split_whitespace();
            Some((w.next()?.parse().ok()?, w.next()?.parse().ok()?))
        })
        .collect();
    assert_eq!(rows.len(), 10, "{text}");
    for (i, (rel, n)) in rows.iter().enumerate() {
        // Either the target is met or the cap is reached.
        assert!(
            *rel <= 0.02 || *n >= 65536.0,
            "sensor {i}: {rel} after {n} samples"
        );
    }
    // The window sensors need far fewer samples than the back of the room.
    assert!(rows[0].1 < rows[9].1, "{rows:?}");
    // --se-row without a target is a usage error.
    let out = common::ours("rdc")
        .current_dir(c.dir.path())
        .args(["-I", "--se-row", "room.rad"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--se-row needs --target-se"));
}

#[test]
fn agrees_with_rtrace_within_monte_carlo_error() {
    if !common::have_radiance("rtrace") {
        return;
    }
    let c = case();
    // Ours, sampled to 1 % per sensor; its own relative standard errors come back.
    let se = c.dir.path().join("se.txt");
    let se_arg = se.to_str().unwrap().to_string();
    let ours = green(&rdc(
        &c,
        &[
            "-I",
            "-h",
            "-ab",
            "4",
            "-ad",
            "1024",
            "-lw",
            "1e-6",
            "--suns",
            "one.wea",
            "--suns-ab",
            "--target-se",
            "0.01",
            "--se-row",
            "--max-samples",
            "262144",
            "--se-out",
            &se_arg,
            "room.rad",
        ],
    ));
    let rel_se: Vec<f64> = std::fs::read_to_string(&se)
        .unwrap()
        .lines()
        .filter_map(|l| l.split_whitespace().next()?.parse().ok())
        .collect();
    // Radiance: pure Monte Carlo (-aa 0), the sun aimed at its centre (-dj 0), one run
    // (rtrace has no seed option, and runs started within the same second repeat each
    // other). Its standard error is taken as ours scaled to its sample count: both
    // estimators average cosine-distributed hemisphere paths.
    const RADIANCE_AD: f64 = 16384.0;
    let oct = c.dir.path().join("sun.oct");
    let mut oc = common::radiance("oconv");
    oc.current_dir(c.dir.path()).arg("sun.rad");
    let o = oc.output().unwrap();
    assert!(o.status.success());
    std::fs::write(&oct, o.stdout).unwrap();
    let mut cmd = common::radiance("rtrace");
    cmd.current_dir(c.dir.path()).args([
        "-I+", "-h", "-ab", "4", "-ad", "16384", "-aa", "0", "-lw", "1e-7", "-dj", "0", "-ov",
        "sun.oct",
    ]);
    let radiance = green(&common::run_ok(&mut cmd, c.sensors.as_bytes()));
    let samples: Vec<f64> = std::fs::read_to_string(&se)
        .unwrap()
        .lines()
        .filter_map(|l| l.split_whitespace().nth(1)?.parse().ok())
        .collect();
    // Only the first six sensors (up to 5 m deep): further back rtrace at -ad 4096 is
    // too noisy for a useful comparison in test time.
    for i in 0..6 {
        let mean = radiance[i];
        let se_radiance = rel_se[i] * ours[i] * (samples[i] / RADIANCE_AD).sqrt();
        let se_ours = rel_se[i] * ours[i];
        let tol = 4.0 * (se_radiance.powi(2) + se_ours.powi(2)).sqrt();
        eprintln!(
            "sensor {i}: ours {:.4e} rtrace {:.4e} ({:+.2} %), tolerance {:.2} %",
            ours[i],
            mean,
            100.0 * (ours[i] / mean - 1.0),
            100.0 * tol / mean
        );
        assert!(
            (ours[i] - mean).abs() <= tol,
            "sensor {i}: ours {} rtrace {mean}, tolerance {tol}",
            ours[i]
        );
    }
}
