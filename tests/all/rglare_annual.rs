//! `rglare annual` (imageless DGP from daylight coefficients) against the picture route:
//! for the 14 hours of `radiance-fixtures/glare/annual/hours.wea` (London Gatwick, spanning
//! the sun seen through the window, the sun in the field of view but hidden by the facade,
//! the sun behind the viewer, intermediate, overcast and dark skies), real rpict renders of
//! the furnished office under gendaylit skies, evaluated by real evalglare -d
//! (`make_annual_fixtures.sh` keeps evalglare's output). Also picture streams on stdin,
//! the summary's arithmetic and one-line errors.
//!
//! Tolerances come from the measured spread at this test's settings (32 × 32 view rays,
//! -ab 2 -ad 128 as the pictures' rpict -ab 2, E_v from the rays; see the table printed by
//! `cargo test --test all rglare_annual:: -- --nocapture` and `radiance-fixtures/glare/annual/
//! README.md`), not widened to pass:
//! - the sun disc is in view (ours) exactly when evalglare finds a source brighter than
//!   1e6 cd/m² (the sun's pixels, with evalglare's merged surroundings) — every hour;
//! - sun out of view (7 hours): mean |ΔDGP| ≤ [`MEAN_DDGP_SUN_OUT`], max ≤
//!   [`MAX_DDGP_SUN_OUT`], E_v within [`MAX_REL_EV_SUN_OUT`];
//! - sun in view: both DGP ≥ 0.45 (EN 17037's "intolerable" side) — the picture's sun is
//!   4 to 6 pixels of 0.225° (Ω 6.0e-5 to 9.1e-5 sr against the disc's 6.8e-5), so its E_v
//!   differs from the exact disc by up to a third and is not compared;
//! - the glare class (DGP < 0.35, < 0.40, < 0.45, ≥ 0.45) agrees in at least
//!   [`MIN_CLASS_AGREEMENT`] of the 14 hours.

use crate::common;

use std::path::Path;
use std::process::Command;

/// Measured at these settings: see the module documentation.
/// Seeds 0..=4 at these settings (path tracer with glass branching into its transmitted and
/// reflected rays, as Radiance's glass.c) gave mean |ΔDGP| 0.0049 to 0.0064, max |ΔDGP|
/// 0.0092 to 0.0186, max |ΔE_v| 2.3 % to 3.7 % and the same class in 13 of 14 hours (3/20
/// 12:30, DGP 0.398 for evalglare sits on the 0.40 class limit); the bounds are the worst
/// seed rounded up.
const MEAN_DDGP_SUN_OUT: f64 = 0.007;
const MAX_DDGP_SUN_OUT: f64 = 0.019;
const MAX_REL_EV_SUN_OUT: f64 = 0.04;
const MIN_CLASS_AGREEMENT: usize = 13;

const VIEW: [&str; 16] = [
    "-vta", "-vp", "3", "1.5", "1.2", "-vd", "0", "-1", "0", "-vu", "0", "0", "1", "-vh", "180",
    "-vv",
];

fn fixtures() -> &'static Path {
    // leaked once: the tests only read
    Box::leak(common::repo().join("radiance-fixtures").into_boxed_path())
}

#[derive(Debug, Clone, Copy)]
struct Row {
    month: u32,
    day: u32,
    hour: f64,
    dgp: f64,
    ev: f64,
    ev_sun: f64,
    nsrc: usize,
    sun: bool,
    dcglare: f64,
}

fn parse_rows(text: &str) -> Vec<Row> {
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            assert_eq!(f.len(), 9, "{l}");
            Row {
                month: f[0].parse().unwrap(),
                day: f[1].parse().unwrap(),
                hour: f[2].parse().unwrap(),
                dgp: f[3].parse().unwrap(),
                ev: f[4].parse().unwrap(),
                ev_sun: f[5].parse().unwrap(),
                nsrc: f[6].parse().unwrap(),
                sun: f[7] == "1",
                dcglare: f[8].parse().unwrap(),
            }
        })
        .collect()
}

fn annual(extra: &[&str]) -> Command {
    let mut c = common::ours("rglare");
    c.current_dir(fixtures())
        .arg("annual")
        .args(VIEW)
        .arg("180");
    c.args(extra);
    c
}

fn run_annual(extra: &[&str]) -> String {
    let out = annual(extra).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// evalglare -d of one hour: (DGP, E_v, the picture's sun source (Eglare) if any).
fn evalglare(name: &str) -> (f64, f64, Option<f64>) {
    let text = std::fs::read_to_string(fixtures().join("glare/annual").join(name)).unwrap();
    let last = text.lines().last().unwrap();
    let vals: Vec<f64> = last
        .split_once(':')
        .unwrap()
        .1
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    let mut sun = None;
    for l in text.lines().skip(1) {
        if l.contains(':') {
            break;
        }
        let f: Vec<f64> = l.split_whitespace().map(|v| v.parse().unwrap()).collect();
        // columns: No pixels x y L_s Omega_s Posindx L_b L_t E_v Edir Max_Lum Sigma xdir
        // ydir zdir Eglare ...
        if f[4] > 1e6 {
            sun = Some(sun.unwrap_or(0.0) + f[16]);
        }
    }
    (vals[0], vals[2], sun)
}

fn class(dgp: f64) -> usize {
    [0.35, 0.40, 0.45]
        .iter()
        .position(|&l| dgp < l)
        .unwrap_or(3)
}

#[test]
fn imageless_dgp_agrees_with_evalglare_on_rpict_pictures() {
    let text = run_annual(&[
        "-w",
        "glare/annual/hours.wea",
        "--rays",
        "32",
        "-ab",
        "2",
        "-ad",
        "128",
        "--eye-ad",
        "4096",
        "--occupied",
        "0-24",
        "scenes/furnished.rad",
    ]);
    assert!(text.contains("view rays above 2000 cd/m2 (fixed threshold)"));
    let rows = parse_rows(&text);
    assert_eq!(rows.len(), 14);
    let (mut n_out, mut sum_out, mut max_out, mut max_ev, mut same_class) =
        (0, 0.0, 0.0f64, 0.0f64, 0);
    println!(
        "hour            ours DGP  evalglare DGP    dDGP   ours Ev  evalglare Ev   dEv%  sun(ours/pic)  Ev_sun ours/pic"
    );
    for r in &rows {
        let name = format!("hour_{}_{}_{:.3}_evalglare.txt", r.month, r.day, r.hour);
        let (dgp, ev, sun) = evalglare(&name);
        let d = r.dgp - dgp;
        let dev = (r.ev - ev) / ev;
        println!(
            "{:>2}/{:>2} {:>5.1}      {:.3}        {:.3}     {:+.3}  {:>8.0}  {:>8.0}   {:+6.1}   {}/{}   {:.0}/{:.0}  {:.3}",
            r.month,
            r.day,
            r.hour,
            r.dgp,
            dgp,
            d,
            r.ev,
            ev,
            100.0 * dev,
            u8::from(r.sun),
            u8::from(sun.is_some()),
            r.ev_sun,
            sun.unwrap_or(0.0),
            r.dcglare
        );
        assert_eq!(
            r.sun,
            sun.is_some(),
            "{name}: sun in view (ours) vs the picture's sun source"
        );
        if class(r.dgp) == class(dgp) {
            same_class += 1;
        }
        if r.sun {
            assert!(
                r.dgp >= 0.45 && dgp >= 0.45,
                "{name}: sun in view, DGP {} vs {dgp}",
                r.dgp
            );
        } else {
            n_out += 1;
            sum_out += d.abs();
            max_out = max_out.max(d.abs());
            max_ev = max_ev.max(dev.abs());
        }
    }
    let mean_out = sum_out / n_out as f64;
    println!(
        "sun out of view ({n_out} h): mean |dDGP| {mean_out:.4}, max {max_out:.4}, max |dEv| {:.1} %; glare class agrees in {same_class}/14",
        100.0 * max_ev
    );
    assert!(n_out >= 5);
    assert!(mean_out <= MEAN_DDGP_SUN_OUT, "mean |dDGP| {mean_out}");
    assert!(max_out <= MAX_DDGP_SUN_OUT, "max |dDGP| {max_out}");
    assert!(max_ev <= MAX_REL_EV_SUN_OUT, "max |dEv| {max_ev}");
    assert!(
        same_class >= MIN_CLASS_AGREEMENT,
        "class agrees in {same_class}"
    );
}

#[test]
fn summary_matches_the_rows_and_the_occupancy() {
    let args = [
        "-w",
        "glare/annual/hours.wea",
        "--rays",
        "16",
        "-ab",
        "1",
        "-ad",
        "16",
        "--eye-ad",
        "256",
        "--occupied",
        "9-13",
        "-l",
        "0.5",
    ];
    let text = run_annual(&[&args[..], &["scenes/furnished.rad"]].concat());
    let rows = parse_rows(&text);
    let occ: Vec<&Row> = rows
        .iter()
        .filter(|r| (9.0..13.0).contains(&r.hour))
        .collect();
    assert!(text.contains(&format!("; {} steps\n", occ.len())), "{text}");
    let share =
        |f: &dyn Fn(f64) -> bool| occ.iter().filter(|r| f(r.dgp)).count() as f64 / occ.len() as f64;
    let auto = format!("# glare autonomy (DGP < 0.5): {:.4}", share(&|d| d < 0.5));
    assert!(text.contains(&auto), "{auto}\n{text}");
    let above = format!(
        "DGP > 0.35: {:.4}  > 0.40: {:.4}  > 0.45: {:.4}",
        share(&|d| d > 0.35),
        share(&|d| d > 0.40),
        share(&|d| d > 0.45)
    );
    assert!(text.contains(&above), "{above}\n{text}");
    // E_v includes the direct sun exactly when the sun is up and shining
    for r in &rows {
        assert!(r.ev >= r.ev_sun && r.ev > 0.0);
        assert!(r.dgp > 0.0 && r.dgp <= 1.0);
        assert!(!r.sun || r.nsrc >= 1);
    }
    // The DGP temporal map: the same rows with it, a page-sized figure, on the scale asked.
    let t = common::tmpdir();
    let map = |range: &str| {
        let png = t.path().join(format!("dgp-{range}.png"));
        let map_args = [
            "--temporal",
            png.to_str().unwrap(),
            "--temporal-range",
            range,
            "scenes/furnished.rad",
        ];
        let with = run_annual(&[&args[..], &map_args[..]].concat());
        assert_eq!(with, text, "--temporal changes no result");
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!((img.width(), img.height()), (1200, 700));
        img
    };
    assert_ne!(map("0.2,0.6"), map("0,1"), "the DGP scale is applied");
}

#[test]
fn same_seed_same_output_whatever_the_thread_count() {
    let base = [
        "-w",
        "glare/annual/hours.wea",
        "--rays",
        "12",
        "-ab",
        "1",
        "-ad",
        "8",
        "--eye-ad",
        "128",
        "scenes/furnished.rad",
    ];
    let a = run_annual(&[&base[..], &["-n", "1"]].concat());
    let b = run_annual(&[&base[..], &["-n", "2"]].concat());
    assert_eq!(a, b);
}

#[test]
fn picture_stream_on_stdin_gives_one_line_per_picture() {
    let g = fixtures().join("glare");
    let names = ["furnished_clear_window.hdr", "furnished_overcast_along.hdr"];
    let mut stream = Vec::new();
    let mut want = String::new();
    for n in names {
        stream.extend(std::fs::read(g.join(n)).unwrap());
        let out = common::run_ok(common::ours("rglare").arg(g.join(n)), b"");
        want.push_str(&String::from_utf8(out).unwrap());
    }
    let got = common::run_ok(&mut common::ours("rglare"), &stream);
    assert_eq!(String::from_utf8(got).unwrap(), want);
    assert_eq!(want.lines().count(), 2);
    // a stream cut inside its second picture is an error, not a silent single result
    let cut = &stream[..stream.len() - 100];
    let out = common::run(&mut common::ours("rglare"), cut);
    assert_eq!(out.status.code(), Some(1));
}

fn error_of(args: &[&str]) -> String {
    let out = common::ours("rglare")
        .current_dir(fixtures())
        .arg("annual")
        .args(args)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{args:?}");
    assert!(out.stdout.is_empty());
    let e = String::from_utf8(out.stderr).unwrap();
    assert_eq!(e.lines().count(), 1, "{e}");
    e
}

#[test]
fn bad_inputs_are_one_line_errors() {
    let view = ["-vta", "-vh", "180", "-vv", "180"];
    let e = error_of(&[&view[..], &["scenes/furnished.rad"]].concat());
    assert!(e.starts_with("rglare: no weather file (-w FILE)"), "{e}");
    let e = error_of(&["-w", "glare/annual/hours.wea", "scenes/furnished.rad"]);
    assert!(e.starts_with("rglare: no view: give -vf FILE"), "{e}");
    let e = error_of(
        &[
            &view[..],
            &[
                "-w",
                "glare/annual/hours.wea",
                "--rays",
                "2",
                "scenes/furnished.rad",
            ],
        ]
        .concat(),
    );
    assert!(e.contains("--rays 2: expected a grid of 4 to 512"), "{e}");
    let e = error_of(
        &[
            &view[..],
            &[
                "-w",
                "glare/annual/hours.wea",
                "--suns",
                "1",
                "scenes/furnished.rad",
            ],
        ]
        .concat(),
    );
    assert!(
        e.contains("--suns: rglare annual chooses the rdc runs itself"),
        "{e}"
    );
    let dir = common::tmpdir();
    let bad = dir.path().join("bad.wea");
    let text = std::fs::read_to_string(fixtures().join("glare/annual/hours.wea")).unwrap();
    std::fs::write(&bad, text.replacen("661", "x61", 1)).unwrap();
    let e = error_of(
        &[
            &view[..],
            &["-w", bad.to_str().unwrap(), "scenes/furnished.rad"],
        ]
        .concat(),
    );
    assert!(e.contains("bad.wea:7: "), "{e}");
    let e = error_of(&[&view[..], &["-w", "glare/annual/hours.wea", "nothere.rad"]].concat());
    assert!(e.contains("nothere.rad"), "{e}");
}

/// Open sky (an empty scene), eye looking at the zenith: E_v is the horizontal global
/// illuminance of gendaymtx's Perez sky, its direct part exactly `E_dn sin(altitude)` (the
/// exact disc, no glazing), the rest the diffuse horizontal illuminance up to the patch
/// and ray-grid discretisation: measured −1.28 % to +0.34 % at 32 × 32 rays (−0.55 % under
/// the uniform-ish overcast skies at 64 × 64: gendaymtx normalises each patch with its
/// centre's sin(altitude), not the patch's mean), so within 1.5 %.
#[test]
fn open_sky_looking_up_gives_the_horizontal_illuminance() {
    use rdaylight::formats::weather::Weather;
    use rdaylight::sky::matrix::time_steps;
    use rdaylight::sky::{PerezOptions, SkyPatches, perez_sky_vector};
    let dir = common::tmpdir();
    let empty = dir.path().join("empty.rad");
    std::fs::write(&empty, "# nothing: open sky\n").unwrap();
    let out = common::ours("rglare")
        .current_dir(fixtures())
        .args(["annual", "-w", "glare/annual/hours.wea"])
        .args([
            "-vta", "-vp", "0", "0", "1", "-vd", "0", "0", "1", "-vu", "0", "1", "0",
        ])
        .args([
            "-vh", "180", "-vv", "180", "--rays", "32", "-ab", "1", "-ad", "16",
        ])
        .arg(&empty)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows = parse_rows(&String::from_utf8(out.stdout).unwrap());
    let w = Weather::read_path(fixtures().join("glare/annual/hours.wea")).unwrap();
    let site = &w.site;
    let patches = SkyPatches::new(1);
    let mut worst: f64 = 0.0;
    for (r, s) in rows.iter().zip(time_steps(&w)) {
        let v = perez_sky_vector(&patches, &s, site, &PerezOptions::default());
        let st = v.state.unwrap();
        let alt = v.sun_position.altitude;
        let sun = if alt > 0.0 && st.dir_illum > 1e-4 {
            st.dir_illum * alt.sin()
        } else {
            0.0
        };
        assert!((r.ev_sun - sun).abs() <= 1e-6 * sun + 0.05, "{r:?}: {sun}");
        let diffuse = (r.ev - r.ev_sun - st.diff_illum) / st.diff_illum;
        println!(
            "{}/{} {}: diffuse E_v {:+.2} %",
            r.month,
            r.day,
            r.hour,
            100.0 * diffuse
        );
        worst = worst.max(diffuse.abs());
        assert_eq!(r.sun, sun > 0.0, "{r:?}");
    }
    println!("open sky: worst diffuse E_v error {:.2} %", 100.0 * worst);
    assert!(worst < 0.015, "{worst}");
}
