//! rmcop (issue 16, the seed's chapter 3): re-weighting against closed form and against
//! brute-force re-simulation, determinism per seed and thread count, shards merged to the
//! bytes of one run, and bad input.

use crate::common;

use common::{ours, repo, run, run_ok, tmpdir};
use rdaylight::formats::sensors::SensorRay;
use rdaylight::mcop::{StudyConfig, validate};
use rdaylight::rdc::{Config, Reweight, Sampling, Tracer};
use rdaylight::scene::{self, LoadOptions};
use rdaylight::trace::reweight::Reweighting;
use std::path::Path;

const EPW: &str = "examples/weather/GBR_London.Gatwick.037760_IWEC.epw";

fn path(p: &str) -> String {
    repo().join(p).to_string_lossy().into_owned()
}

/// Every `step`-th sensor of a sensor file, written to `dir`.
fn subset(file: &str, step: usize, dir: &Path) -> String {
    let all = std::fs::read_to_string(path(file)).unwrap();
    let text: String = all
        .lines()
        .step_by(step)
        .map(|l| format!("{l}\n"))
        .collect();
    let p = dir.join("sensors.pts");
    std::fs::write(&p, text).unwrap();
    p.to_string_lossy().into_owned()
}

/// One diffuse bounce in closed form: a sensor 1 m above a 2 km floor of reflectance rho,
/// facing down, under a sky of unit radiance in every patch, receives `pi rho` (the floor's
/// irradiance `pi` times `rho / pi` radiance times `pi`). Every path of the sum over patches
/// carries exactly `rho` times the cosine-sampling weight, so the row sum has no Monte Carlo
/// noise: re-weighting the floor by `s` must give `pi rho s` to rounding.
#[test]
fn one_diffuse_bounce_is_reweighted_exactly() {
    let rho = 0.3;
    let text = format!(
        "void plastic floor 0 0 5 {rho} {rho} {rho} 0 0\n\
         floor polygon ground 0 0 12 -1000 -1000 0 1000 -1000 0 1000 1000 0 -1000 1000 0\n"
    );
    let scene =
        scene::parse_str(&text, "bounce.rad", Path::new(""), &LoadOptions::default()).unwrap();
    let config = Config {
        seed: 3,
        threads: Some(1),
        reweight: Some(Reweight {
            path: None,
            materials: None,
        }),
        ..Config::sky_coefficients(
            1,
            Sampling {
                // The sensor's hemisphere rays take one level (rcontrib -I), the floor's
                // reflection the second.
                ab: 2,
                ad: 512,
                lw: 1e-5,
                ..Sampling::default()
            },
        )
    };
    let tracer = Tracer::new(&config, &scene).unwrap();
    assert_eq!(tracer.tracked_materials(), ["floor"]);
    let rows = tracer
        .compute(&[SensorRay::new([0.0, 0.0, 1.0], [0.0, 0.0, -1.0])])
        .unwrap();
    let mut rw = Reweighting::new(vec!["floor".into()], 146, 3);
    rw.push_row(&rows[0].terms);
    for s in [0.0, 0.5, 1.0, 2.0] {
        let c = rw.apply(&[s]).unwrap();
        let sum: f64 = c.chunks_exact(3).map(|x| x[1]).sum();
        let want = std::f64::consts::PI * rho * s;
        assert!(
            (sum - want).abs() <= 1e-6 * want.max(1e-9),
            "s {s}: {sum} vs {want}"
        );
    }
}

/// Re-weighting against re-simulating the same drawn materials (walls, floor, ceiling,
/// exterior ground and the glazing's transmittance all drawn, sigma 0.2 per material), 20
/// draws, against the re-simulations' own measured noise: the criterion of
/// `rdaylight::mcop::validate` (every draw's room TAI within 3 sqrt 2 sd, per-sensor RMS z
/// over its Student-t expectation at most 1.25, spread across draws within 10 %).
#[test]
fn reweighting_agrees_with_resimulation_within_the_noise() {
    let dir = tmpdir();
    let pts = subset("examples/room/sensors.pts", 15, dir.path());
    let sensors = rdaylight::formats::sensors::read_rays(
        std::io::BufReader::new(std::fs::File::open(&pts).unwrap()),
        &pts,
        rdaylight::formats::sensors::RayFormat::Ascii,
    )
    .unwrap();
    let scene = scene::load(&[path("examples/room/room.rad")], &LoadOptions::default()).unwrap();
    let weather = rdaylight::formats::weather::Weather::read_path(path(EPW)).unwrap();
    let cfg = StudyConfig {
        trace: rdaylight::glod::study::StudyConfig {
            sampling: Sampling {
                ab: 3,
                ad: 1024,
                lw: 1e-4,
                ..Sampling::default()
            },
            ..Default::default()
        },
        sigmas: vec![0.2],
        ..StudyConfig::default()
    };
    let v = validate::validate(
        &scene,
        &weather,
        &sensors,
        &cfg,
        20,
        6,
        &rdaylight::progress::QUIET,
    )
    .unwrap();
    let c = &v.classes[0];
    assert!(c.passed, "{}", validate::table(&v));
    // The draws really moved the room: sigma 0.2 on every material is tens of percent.
    assert!(c.max_room_diff_pct < 5.0, "{}", validate::table(&v));
}

fn study(dir: &Path, pts: &str, extra: &[&str]) -> std::process::Output {
    let mut c = ours("rmcop");
    c.args(["study", "-w", &path(EPW), "--pts", pts])
        .args(["-ab", "2", "-ad", "256", "-lw", "1e-3"])
        .args(["--draws", "30", "--levels", "0,4", "--sigmas", "0.1,0.2"])
        .args(extra)
        .arg(path("examples/furnished/room.rad"))
        .current_dir(dir);
    run(&mut c, b"")
}

/// Every file of an output directory, by name.
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

/// Equal names and bytes (a difference names the file, not its bytes).
fn same_files(a: &[(String, Vec<u8>)], b: &[(String, Vec<u8>)], what: &str) {
    let names = |v: &[(String, Vec<u8>)]| v.iter().map(|x| x.0.clone()).collect::<Vec<_>>();
    assert_eq!(names(a), names(b), "{what}: other files");
    for ((n, x), (_, y)) in a.iter().zip(b) {
        assert!(x == y, "{what}: {n} differs");
    }
}

/// The same seed gives the same bytes with 1 or 2 threads and in 1 or 3 shards merged; a
/// merge with a missing shard names it; another seed gives other numbers.
#[test]
fn shards_merge_to_the_bytes_of_one_run() {
    let dir = tmpdir();
    let d = dir.path();
    let pts = subset("examples/furnished/sensors.pts", 8, d);
    let one = study(d, &pts, &["-n", "1", "-o", "one"]);
    assert!(
        one.status.success(),
        "{}",
        String::from_utf8_lossy(&one.stderr)
    );
    let two = study(d, &pts, &["-n", "2", "-o", "two"]);
    assert!(two.status.success());
    assert_eq!(one.stdout, two.stdout);
    let want = files(&d.join("one"));
    same_files(&want, &files(&d.join("two")), "-n 2");
    assert!(want.iter().any(|(n, _)| n == "boxplot.svg"));
    assert!(want.iter().any(|(n, _)| n.starts_with("spread_GLoD4")));
    let mut recs = Vec::new();
    for k in 0..3 {
        let r = format!("r{k}.json");
        let shard = format!("{k}/3");
        let o = study(d, &pts, &["--shard", &shard, "--records", &r]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        recs.push(r);
    }
    let mut c = ours("rmcop");
    c.args(["merge", "-o", "merged"]).args(&recs).current_dir(d);
    let merged = run_ok(&mut c, b"");
    assert_eq!(merged, one.stdout);
    same_files(&want, &files(&d.join("merged")), "merged shards");
    // A missing shard is named.
    let mut c = ours("rmcop");
    c.args(["merge", "-o", "bad", &recs[0], &recs[2]])
        .current_dir(d);
    let o = run(&mut c, b"");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("1") && err.lines().count() == 1, "{err}");
    // Another seed: other draws.
    let other = study(d, &pts, &["-s", "2", "-o", "other"]);
    assert_ne!(other.stdout, one.stdout);
}

#[test]
fn bad_input_is_one_line_and_status_1() {
    let dir = tmpdir();
    let d = dir.path();
    let pts = subset("examples/furnished/sensors.pts", 40, d);
    for (args, says) in [
        (&["--sigmas", "0", "-o", "x"][..], "--sigmas"),
        (&["--draws", "0", "-o", "x"][..], "--draws"),
        (&["--levels", "7", "-o", "x"][..], "--levels"),
        (&["--class", "nothing", "-o", "x"][..], "--class"),
        (&["--materials", "nosuch", "-o", "x"][..], "nosuch"),
    ] {
        let o = study(d, &pts, args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains(says) && err.lines().count() == 1,
            "{args:?}: {err}"
        );
        assert!(!d.join("x").exists(), "{args:?}: output written");
    }
}
