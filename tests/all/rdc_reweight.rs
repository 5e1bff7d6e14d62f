//! `rdc --reweight`: path re-weighting records (`rdaylight::trace::reweight`).
//!
//! - all factors 1 reproduce the normal output of the same run (to floating-point
//!   re-association), and recording changes nothing in that output;
//! - walls at 0.8 x reflectance by re-weighting agree with re-tracing the scene with the
//!   walls' colour scaled, within 4 standard errors measured from repeated seeds;
//! - an analytic zero-variance case: a downward sensor over an infinite diffuse ground of
//!   reflectance rho sees `pi rho s` for every factor s.

use crate::common;

use common::{ours, run, run_ok, tmpdir};
use rdaylight::formats::matrix::{Matrix, ReadOptions};
use rdaylight::trace::reweight::Reweighting;
use std::f64::consts::PI;
use std::path::Path;

/// A 4 x 3 x 2.7 m room with an open 2 x 1.2 m window in the south wall (y = 0),
/// the walls' grey reflectance `wall`.
fn room(wall: f64) -> String {
    let mut s = format!(
        "void plastic wall 0 0 5 {wall} {wall} {wall} 0 0\n\
         void plastic floor 0 0 5 0.2 0.2 0.2 0 0\n\
         void plastic ceiling 0 0 5 0.8 0.8 0.8 0 0\n"
    );
    let mut poly = |m: &str, id: &str, pts: &[[f64; 3]]| {
        s.push_str(&format!("{m} polygon {id} 0 0 {}", pts.len() * 3));
        for p in pts {
            s.push_str(&format!(" {} {} {}", p[0], p[1], p[2]));
        }
        s.push('\n');
    };
    let (x, y, z) = (4.0, 3.0, 2.7);
    poly(
        "floor",
        "f",
        &[[0., 0., 0.], [0., y, 0.], [x, y, 0.], [x, 0., 0.]],
    );
    poly(
        "ceiling",
        "c",
        &[[0., 0., z], [x, 0., z], [x, y, z], [0., y, z]],
    );
    poly(
        "wall",
        "n",
        &[[0., y, 0.], [0., y, z], [x, y, z], [x, y, 0.]],
    );
    poly(
        "wall",
        "w",
        &[[0., 0., 0.], [0., 0., z], [0., y, z], [0., y, 0.]],
    );
    poly(
        "wall",
        "e",
        &[[x, 0., 0.], [x, y, 0.], [x, y, z], [x, 0., z]],
    );
    // South wall around the window (x 1..3, z 0.9..2.1), four pieces facing +y.
    poly(
        "wall",
        "s1",
        &[[0., 0., 0.], [x, 0., 0.], [x, 0., 0.9], [0., 0., 0.9]],
    );
    poly(
        "wall",
        "s2",
        &[[0., 0., 2.1], [x, 0., 2.1], [x, 0., z], [0., 0., z]],
    );
    poly(
        "wall",
        "s3",
        &[[0., 0., 0.9], [1., 0., 0.9], [1., 0., 2.1], [0., 0., 2.1]],
    );
    poly(
        "wall",
        "s4",
        &[[3., 0., 0.9], [x, 0., 0.9], [x, 0., 2.1], [3., 0., 2.1]],
    );
    s
}

const SENSORS: &str = "1 1 0.8 0 0 1\n2 2 0.8 0 0 1\n3 2.5 0.8 0 0 1\n2 1.5 1.5 0 -1 0\n";

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_string_lossy().into_owned()
}

fn matrix(bytes: &[u8]) -> Matrix {
    Matrix::from_reader(bytes, "rdc output", &ReadOptions::default()).unwrap()
}

/// Per-sensor totals over all columns (channel 0).
fn totals(values: &[f64], nrows: usize, ncomp: usize) -> Vec<f64> {
    let row = values.len() / nrows;
    (0..nrows)
        .map(|r| values[r * row..(r + 1) * row].iter().step_by(ncomp).sum())
        .collect()
}

fn dc(scene: &str, seed: u64, extra: &[&str]) -> Vec<u8> {
    dc_ad(scene, seed, 2048, extra)
}

fn dc_ad(scene: &str, seed: u64, ad: usize, extra: &[&str]) -> Vec<u8> {
    let s = seed.to_string();
    let ad = ad.to_string();
    let mut args = vec![
        "-I", "-m", "1", "-ab", "4", "-ad", &ad, "-lw", "1e-4", "-fad", "-s", &s,
    ];
    args.extend_from_slice(extra);
    args.push(scene);
    run_ok(ours("rdc").args(&args), SENSORS.as_bytes())
}

#[test]
fn unit_factors_reproduce_the_run_and_recording_changes_nothing() {
    let dir = tmpdir();
    let scene = write(dir.path(), "room.rad", &room(0.5));
    let rw = dir.path().join("room.rw");
    let plain = dc(&scene, 3, &[]);
    let with = dc(&scene, 3, &["--reweight", rw.to_str().unwrap()]);
    // The header records the command line; the numbers must be identical.
    let (a, b) = (matrix(&plain), matrix(&with));
    assert_eq!(a.data, b.data, "recording changed the output");
    let r = Reweighting::read(rw.to_str().unwrap()).unwrap();
    // Tracked in order of first use by a surface.
    assert_eq!(r.materials, ["floor", "ceiling", "wall"]);
    assert_eq!((r.nrows(), r.ncols, r.ncomp), (4, 146, 3));
    let one = r.apply(&[1.0, 1.0, 1.0]).unwrap();
    assert_eq!(one.len(), a.data.len());
    let mut worst: f64 = 0.0;
    for (x, y) in one.iter().zip(&a.data) {
        worst = worst.max((x - y).abs() / y.abs().max(1e-300));
        assert!((x - y).abs() <= 1e-12 * y.abs().max(1e-12), "{x} vs {y}");
    }
    let (terms, sigs) = r.size();
    eprintln!(
        "unit factors: worst relative difference {worst:.1e}; {terms} terms, {sigs} signatures"
    );
    // Named materials only: the others are fixed; the all-zero factor keeps only paths
    // that met no wall (direct view plus floor/ceiling bounces).
    let rw2 = dir.path().join("walls.rw");
    dc(
        &scene,
        3,
        &[
            "--reweight",
            rw2.to_str().unwrap(),
            "--reweight-materials",
            "wall",
        ],
    );
    let w = Reweighting::read(rw2.to_str().unwrap()).unwrap();
    assert_eq!(w.materials, ["wall"]);
    let full = r.apply(&[1.0, 1.0, 0.0]).unwrap();
    let walls = w.apply(&[0.0]).unwrap();
    for (x, y) in full.iter().zip(&walls) {
        assert!((x - y).abs() <= 1e-12 * x.abs().max(1e-12));
    }
}

#[test]
fn scaled_walls_agree_with_retracing_within_seed_spread() {
    let dir = tmpdir();
    let base = write(dir.path(), "base.rad", &room(0.5));
    let dark = write(dir.path(), "dark.rad", &room(0.4));
    let k = 8;
    let mut rew: Vec<Vec<f64>> = Vec::new();
    let mut ret: Vec<Vec<f64>> = Vec::new();
    let mut orig: Vec<Vec<f64>> = Vec::new();
    for seed in 0..k {
        let rw = dir.path().join(format!("r{seed}.rw"));
        let out = dc_ad(
            &base,
            100 + seed,
            8192,
            &["--reweight", rw.to_str().unwrap()],
        );
        orig.push(totals(&matrix(&out).data, 4, 3));
        let r = Reweighting::read(rw.to_str().unwrap()).unwrap();
        let scales: Vec<f64> = r
            .materials
            .iter()
            .map(|m| if m == "wall" { 0.8 } else { 1.0 })
            .collect();
        rew.push(totals(&r.apply(&scales).unwrap(), 4, 3));
        ret.push(totals(
            &matrix(&dc_ad(&dark, 200 + seed, 8192, &[])).data,
            4,
            3,
        ));
    }
    let stats = |v: &[Vec<f64>], s: usize| {
        let n = v.len() as f64;
        let m = v.iter().map(|x| x[s]).sum::<f64>() / n;
        let var = v.iter().map(|x| (x[s] - m).powi(2)).sum::<f64>() / (n - 1.0);
        (m, var / n)
    };
    for s in 0..4 {
        let (mr, vr) = stats(&rew, s);
        let (mt, vt) = stats(&ret, s);
        let (mo, vo) = stats(&orig, s);
        let se = (vr + vt).sqrt();
        eprintln!(
            "sensor {s}: re-weighted {mr:.5} re-traced {mt:.5} (diff {:+.2} %, {:.2} SE); walls 0.5: {mo:.5}",
            100.0 * (mr / mt - 1.0),
            (mr - mt) / se
        );
        assert!(
            (mr - mt).abs() < 4.0 * se,
            "sensor {s}: {mr} vs {mt} (SE {se})"
        );
        // The check has teeth: the wall change moves the desk sensors by many SEs (the
        // vertical sensor 3 faces the window and sees mostly sky).
        if s < 3 {
            assert!(
                (mo - mt).abs() > 4.0 * (vo + vt).sqrt(),
                "sensor {s}: no wall effect"
            );
        }
    }
}

#[test]
fn ground_furnace_is_pi_rho_s_for_every_factor() {
    let dir = tmpdir();
    let scene = write(
        dir.path(),
        "ground.rad",
        "void plastic ground 0 0 5 0.5 0.3 0.2 0 0\n\
         ground polygon g 0 0 12 -1e4 -1e4 0 1e4 -1e4 0 1e4 1e4 0 -1e4 1e4 0\n",
    );
    let rw = dir.path().join("g.rw");
    let out = run_ok(
        ours("rdc").args([
            "-I",
            "-m",
            "1",
            "-ab",
            "2",
            "-ad",
            "64",
            "-fad",
            "--reweight",
            rw.to_str().unwrap(),
            &scene,
        ]),
        b"0 0 1 0 0 -1\n",
    );
    let r = Reweighting::read(rw.to_str().unwrap()).unwrap();
    let rho = [0.5, 0.3, 0.2];
    let row = matrix(&out).data;
    for s in [0.0, 0.5, 1.0, 1.7] {
        let c = r.apply(&[s]).unwrap();
        for (ch, &p) in rho.iter().enumerate() {
            let total: f64 = c.iter().skip(ch).step_by(3).sum();
            assert!(
                (total - PI * p * s).abs() < 1e-6,
                "s {s} channel {ch}: {total}"
            );
            if s == 1.0 {
                let t0: f64 = row.iter().skip(ch).step_by(3).sum();
                assert!((t0 - PI * p).abs() < 1e-6);
            }
        }
    }
}

#[test]
fn bad_reweight_requests_are_usage_errors() {
    let dir = tmpdir();
    let scene = write(dir.path(), "room.rad", &room(0.5));
    let rw = dir.path().join("x.rw");
    let rw = rw.to_str().unwrap();
    let cases: [(&[&str], &str); 3] = [
        (&["-I", "--reweight", rw], "--reweight needs coefficients"),
        (
            &[
                "-I",
                "-m",
                "1",
                "--reweight",
                rw,
                "--reweight-materials",
                "wall,glass",
            ],
            "no reflecting or transmitting material named 'glass'",
        ),
        (
            &["-I", "-m", "1", "--reweight-materials", "wall"],
            "needs --reweight FILE",
        ),
    ];
    for (args, want) in cases {
        let mut a = args.to_vec();
        a.push(&scene);
        let o = run(ours("rdc").args(&a), SENSORS.as_bytes());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(err.contains(want), "{err}");
        assert!(!Path::new(rw).exists(), "half-written {rw}");
    }
}

#[test]
fn sun_coefficients_through_tracked_glass_scale_linearly() {
    // A pane over an upward sensor: every sun coefficient crosses it once, so the factor of
    // the glass multiplies every column; the unscaled file reproduces the run.
    let dir = tmpdir();
    let scene = write(
        dir.path(),
        "pane.rad",
        "void glass pane 0 0 3 0.9 0.8 0.7\n\
         pane polygon p 0 0 12 -100 -100 1 100 -100 1 100 100 1 -100 100 1\n",
    );
    let rw = dir.path().join("s.rw");
    let out = run_ok(
        ours("rdc").args([
            "-I",
            "--suns",
            "1",
            "-ad",
            "4",
            "-fad",
            "--reweight",
            rw.to_str().unwrap(),
            &scene,
        ]),
        b"0 0 0 0 0 1\n",
    );
    let base = matrix(&out).data;
    assert!(base.iter().sum::<f64>() > 0.0);
    let r = Reweighting::read(rw.to_str().unwrap()).unwrap();
    assert_eq!(r.materials, ["pane"]);
    for s in [1.0, 0.5] {
        for (x, y) in r.apply(&[s]).unwrap().iter().zip(&base) {
            assert!(
                (x - s * y).abs() <= 1e-12 * y.abs().max(1e-12),
                "{x} vs {s} x {y}"
            );
        }
    }
}

#[test]
fn suns_ab_reweighted_walls_equal_retracing_without_roulette() {
    // `--suns-ab` records each sun's next-event estimate with the path's tracked bounces
    // plus the vertex's own. Without roulette (-lw 0) a matte room's paths do not depend
    // on the walls' reflectance, so re-tracing the room with the walls at 0.8 x follows
    // the very same paths: the re-weighted coefficients must equal it to rounding.
    let dir = tmpdir();
    let scene = write(dir.path(), "room.rad", &room(0.5));
    let darker = write(dir.path(), "darker.rad", &room(0.4));
    let rw = dir.path().join("suns.rw");
    let args = |scene: &str, extra: &[&str]| -> Vec<f64> {
        let mut a = vec![
            "-I",
            "--suns",
            "1",
            "--suns-ab",
            "-ab",
            "4",
            "-ad",
            "256",
            "-lw",
            "0",
            "-fad",
            "-s",
            "5",
        ];
        a.extend_from_slice(extra);
        a.push(scene);
        matrix(&run_ok(ours("rdc").args(&a), SENSORS.as_bytes())).data
    };
    let base = args(
        &scene,
        &[
            "--reweight",
            rw.to_str().unwrap(),
            "--reweight-materials",
            "wall",
        ],
    );
    let retraced = args(&darker, &[]);
    let r = Reweighting::read(rw.to_str().unwrap()).unwrap();
    let one = r.apply(&[1.0]).unwrap();
    let scaled = r.apply(&[0.8]).unwrap();
    let (mut moved, mut worst) = (0.0f64, 0.0f64);
    for ((b, o), (s, t)) in base.iter().zip(&one).zip(scaled.iter().zip(&retraced)) {
        assert!((b - o).abs() <= 1e-12 * b.abs().max(1e-12), "{b} vs {o}");
        assert!(
            (s - t).abs() <= 1e-5 * t.abs().max(1e-12),
            "re-weighted {s} vs re-traced {t}"
        );
        if *b > 0.0 {
            moved = moved.max(1.0 - s / b);
            worst = worst.max((s - t).abs() / t.abs().max(1e-300));
        }
    }
    eprintln!(
        "walls x 0.8: up to {:.1} % less sun light; worst difference {worst:.1e}",
        100.0 * moved
    );
    // The walls matter: the back of the room loses light with them.
    assert!(moved > 0.05, "{moved}");
}
