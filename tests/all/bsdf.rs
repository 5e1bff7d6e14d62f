//! BSDF XML (LBNL WINDOW schema) and the `BSDF` material: the fixtures of
//! `radiance-fixtures/bsdf/make.sh` (real genblinds + rfluxmtx + wrapBSDF, bsdf2ttree) parse,
//! round-trip, and give the transmission matrix real `rmtxop` (Radiance's `cm_loadBTDF`,
//! what `dctimestep` multiplies) gives; Radiance's empty `WINDOW6BSDFt.xml` template is a
//! clean error.

use crate::common;

use rdaylight::bsdf::{self, Channel, DataStructure, Direction, ScatteringData};
use rdaylight::material::bsdf::transmission_matrix;

fn data(name: &str) -> std::path::PathBuf {
    common::repo().join("tests/data/bsdf").join(name)
}

const KLEMS: [&str; 2] = ["blinds45.xml", "shade10.xml"];

#[test]
fn klems_fixtures_parse_with_four_full_blocks_and_round_trip() {
    for f in KLEMS {
        let x = bsdf::load(&data(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert_eq!(x.layers.len(), 1);
        let l = &x.layers[0];
        assert_eq!(l.structure, DataStructure::Columns);
        assert_eq!(l.bases.len(), 1);
        assert_eq!(l.bases[0].name, "LBNL/Klems Full");
        assert_eq!(l.bases[0].len(), 145);
        let dirs: Vec<Direction> = l.components.iter().map(|c| c.direction).collect();
        for d in Direction::ALL {
            assert_eq!(dirs.iter().filter(|&&e| e == d).count(), 1, "{f}: {d:?}");
        }
        for c in &l.components {
            assert_eq!(c.channel, Channel::Visible);
            let ScatteringData::Klems(k) = &c.data else {
                panic!("{f}: not Klems")
            };
            assert_eq!((k.n_in, k.n_out), (145, 145));
        }
        assert!(l.material.thickness.unwrap() > 0.0);
        // Writing and reading back gives the same data (lines aside).
        let text = x.to_xml();
        let mut y = bsdf::parse(&text, "round-trip.xml").unwrap();
        for (a, b) in y.layers[0].components.iter_mut().zip(&l.components) {
            a.line = b.line;
        }
        assert_eq!(y, x, "{f}: round trip");
    }
}

#[test]
fn tensor_tree_fixture_parses() {
    let f = "lobe_tt.xml";
    let x = bsdf::load(&data(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
    let l = &x.layers[0];
    assert_eq!(l.structure, DataStructure::TensorTree3);
    assert!(!l.components.is_empty());
    for c in &l.components {
        let ScatteringData::Tree(t) = &c.data else {
            panic!("{f}: not a tree")
        };
        assert_eq!(t.rank, 3);
        assert_eq!(t.basis, "LBNL/Shirley-Chiu");
    }
}

#[test]
fn radiance_template_without_data_is_a_clean_error() {
    if !common::have_radiance("radiance_template_without_data_is_a_clean_error") {
        return;
    }
    let (_, lib) = common::radiance_dirs().unwrap();
    let t = lib.join("WINDOW6BSDFt.xml");
    let e = bsdf::load(&t).unwrap_err().to_string();
    assert!(
        e.contains("WINDOW6BSDFt.xml:20: expected an <IncidentDataStructure>"),
        "{e}"
    );
    assert_eq!(e.lines().count(), 1);
}

/// Our `T` against real `rmtxop file.xml` (Radiance's own BTDF-to-matrix conversion).
#[test]
fn transmission_matrix_matches_radiance_rmtxop() {
    if !common::have_radiance("transmission_matrix_matches_radiance_rmtxop") {
        return;
    }
    for f in KLEMS {
        let path = data(f);
        let x = bsdf::load(&path).unwrap();
        let t = transmission_matrix(&x, f).unwrap();
        let out = common::run_ok(common::radiance("rmtxop").arg("-fa").arg(&path), b"");
        let text = String::from_utf8(out).unwrap();
        let body = text.split("\n\n").nth(1).expect("rmtxop header then data");
        let v: Vec<f64> = body
            .split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect();
        assert_eq!(v.len(), 145 * 145 * 3, "{f}");
        assert_eq!((t.nrows, t.ncols), (145, 145));
        let mut worst = 0f64;
        for r in 0..145 {
            for c in 0..145 {
                let ours = t.get(r, c);
                for k in 0..3 {
                    let theirs = v[(r * 145 + c) * 3 + k];
                    // rmtxop prints 8 significant digits of float data.
                    let d = (ours[k] - theirs).abs() / theirs.abs().max(1e-6);
                    worst = worst.max(d);
                }
            }
        }
        // Measured: blinds45 below 1e-6; shade10 1.6e-5, on the elements equal to the matrix
        // minimum, which Radiance re-adds as its Lambertian part through a CIE
        // chromaticity round trip (ccy2rgb of its default white) in single precision.
        eprintln!("{f}: worst relative difference from rmtxop {worst:e}");
        assert!(worst < 5e-5, "{f}: worst relative difference {worst:e}");
    }
}

// ---------------------------------------------------------------------------------------
// The material: physical invariants, then a room against real rtrace -I.
// ---------------------------------------------------------------------------------------

use rdaylight::geometry::klems::{KlemsBasis, KlemsKind};
use rdaylight::material::bsdf::{KlemsBsdf, build_material};
use rdaylight::material::{SampleKind, ShadingOptions, Surface};
use rdaylight::radiometry::{Channels, photopic};

fn klems(f: &str) -> KlemsBsdf {
    let x = bsdf::load(&data(f)).unwrap();
    KlemsBsdf::from_xml(&x, f).unwrap()
}

/// For light arriving from outside (Radiance's back) through each Klems patch, the
/// hemispherical transmittance the material integrates (its row total plus its Lambertian
/// part) equals what the column of dctimestep's matrix says (`T = BTDF x lambda_in`, rows
/// outgoing).
#[test]
fn hemispherical_transmittance_matches_the_matrix_columns() {
    let basis = KlemsBasis::new(KlemsKind::Full);
    for f in KLEMS {
        let k = klems(f);
        let t = transmission_matrix(&bsdf::load(&data(f)).unwrap(), f).unwrap();
        let mut worst = 0f64;
        for c in 0..145 {
            // T = BTDF x lambda of the *incident* patch (cm_bsdf): the hemispherical
            // transmittance sum_r BTDF(r, c) lambda_r is sum_r T[r][c] lambda_r / lambda_c.
            let col: f64 = (0..145)
                .map(|r| photopic(t.get(r, c)) * basis.lambda(r) / basis.lambda(c))
                .sum();
            // The back-incident patch c seen from the back: its direction points away from
            // the surface on the back (z < 0) side, azimuth turned (bsdf_m.c `bi`).
            let p = basis.centre(c);
            let (_, tt) = k.hemispherical([-p[0], -p[1], -p[2]]);
            worst = worst.max((tt - col).abs() / col.max(1e-3));
        }
        assert!(worst < 1e-5, "{f}: worst relative difference {worst:e}");
    }
}

/// Sampling is unbiased against evaluation: the mean sample weight (what a path carries)
/// equals the integral of the evaluated BSDF x cos over the sphere (a uniform-direction
/// Monte Carlo estimate), separately for reflection and transmission, from both sides and
/// several view directions (Klems files and the tensor tree). No extra diffuse arguments;
/// `-st 0` so nothing is folded.
#[test]
fn sampling_matches_evaluation_and_conserves_energy() {
    use rand::{Rng, SeedableRng};
    let ch = Channels::rgb();
    let loc = rdaylight::Location::line(data("x.rad").to_str().unwrap(), 1);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
    for f in KLEMS.iter().chain(&["lobe_tt.xml"]) {
        let strings: Vec<String> = ["0", f, "0", "0", "1", "."]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let b = build_material(false, &strings, &[], &loc, "m", 0.0, &ch).unwrap();
        let s = Surface::flat([0.0, 1.0, 0.0]);
        for wo in [
            [0.0, 1.0, 0.0],
            [0.3, 0.8, 0.2],
            [0.1, -0.9, -0.3],
            [-0.5, -0.5, 0.5],
        ] {
            let n: f64 = wo[0] * wo[0] + wo[1] * wo[1] + wo[2] * wo[2];
            let wo = [wo[0] / n.sqrt(), wo[1] / n.sqrt(), wo[2] / n.sqrt()];
            let front = wo[1] > 0.0;
            let m = 200_000;
            let (mut sr, mut st) = (0.0, 0.0);
            for _ in 0..m {
                let smp = b.sample(wo, &s, rng.random(), rng.random(), rng.random());
                if let Some(smp) = smp {
                    let y = smp.weight.as_slice()[1] as f64;
                    if smp.kind.is_transmission() {
                        st += y;
                    } else {
                        sr += y;
                    }
                    assert!(matches!(
                        smp.kind,
                        SampleKind::SpecularReflect
                            | SampleKind::SpecularTransmit
                            | SampleKind::DiffuseReflect
                            | SampleKind::DiffuseTransmit
                    ));
                    // Transmitted samples leave on the other side, reflected on this one.
                    assert_eq!((smp.wi[1] > 0.0) == front, !smp.kind.is_transmission());
                }
            }
            let (sr, st) = (sr / m as f64, st / m as f64);
            let (mut er, mut et, mut er2, mut et2) = (0.0, 0.0, 0.0, 0.0);
            for _ in 0..m {
                // Uniform direction on the sphere: pdf 1/(4 pi); omega = 4 pi.
                let z: f64 = 2.0 * rng.random::<f64>() - 1.0;
                let phi = 2.0 * std::f64::consts::PI * rng.random::<f64>();
                let r = (1.0 - z * z).sqrt();
                let wi = [r * phi.cos(), z, r * phi.sin()];
                let v = b
                    .eval_direct(wo, wi, &s, 4.0 * std::f64::consts::PI)
                    .as_slice()[1] as f64;
                if (wi[1] > 0.0) == front {
                    er += v;
                    er2 += v * v;
                } else {
                    et += v;
                    et2 += v * v;
                }
            }
            let mf = m as f64;
            let (er, et) = (er / mf, et / mf);
            let se = |s2: f64, mean: f64| ((s2 / mf - mean * mean).max(0.0) / mf).sqrt();
            let (ser, set) = (se(er2, er), se(et2, et));
            eprintln!(
                "{f} wo {wo:.2?}: R sampled {sr:.4} evaluated {er:.4} (se {ser:.4}); T sampled {st:.4} evaluated {et:.4} (se {set:.4})"
            );
            // 5 standard errors of the evaluation estimate, plus the sampler's own noise
            // (its weights are the row totals: near-constant, tiny variance) of 0.002.
            assert!(
                (sr - er).abs() < 5.0 * ser + 2e-3,
                "{f} {wo:?}: R {sr} vs {er}"
            );
            assert!(
                (st - et).abs() < 5.0 * set + 2e-3,
                "{f} {wo:?}: T {st} vs {et}"
            );
            assert!(sr + st <= 1.01, "{f} {wo:?}: R + T = {}", sr + st);
        }
    }
    let _ = ShadingOptions::rtrace();
}

/// A pattern on a BSDF material (Radiance's `r->pcol`) multiplies everything but the
/// non-diffuse reflection (`m_bsdf.c`). Under a black pattern: no transmission at all,
/// evaluated or sampled; the reflection loses exactly a direction-independent (Lambertian)
/// part, and keeps a directional one. Under a coloured pattern the transmission is the
/// unpatterned one times the pattern, channel by channel, and sampling still matches
/// evaluation. `aBSDF`'s through peak (shadow rays) takes the pattern too.
#[test]
fn patterns_multiply_all_but_non_diffuse_reflection() {
    use rand::{Rng, SeedableRng};
    use rdaylight::material::Color;
    let ch = Channels::rgb();
    let loc = rdaylight::Location::line(data("x.rad").to_str().unwrap(), 1);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
    let tint = [0.2f32, 0.5, 0.9];
    let strings: Vec<String> = ["0", "blinds45.xml", "0", "0", "1", "."]
        .iter()
        .map(|s| s.to_string())
        .collect();
    // An extra front diffuse reflectance 0.05: a pattern multiplies it too.
    let b = build_material(false, &strings, &[0.05, 0.05, 0.05], &loc, "m", 0.0, &ch).unwrap();
    let black = b.with_pattern(Some(Color::black(3)));
    let tinted = b.with_pattern(Some(Color::from_slice(&tint)));
    let s = Surface::flat([0.0, 1.0, 0.0]);
    // aBSDF's through peak (what shadow rays keep) takes the pattern (compute_through).
    let shade: Vec<String> = ["shade10.xml", "0", "0", "1", "."]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let a = build_material(true, &shade, &[], &loc, "a", 0.15, &ch).unwrap();
    let peak = a
        .shadow_transmission([0.0, 1.0, 0.0], &s)
        .expect("the shade's through peak");
    let tinted_peak = a
        .with_pattern(Some(Color::from_slice(&tint)))
        .shadow_transmission([0.0, 1.0, 0.0], &s)
        .unwrap();
    for (c, &k) in tint.iter().enumerate() {
        assert!((tinted_peak.as_slice()[c] - peak.as_slice()[c] * k).abs() <= 1e-7);
    }
    let a_black = a.with_pattern(Some(Color::black(3)));
    assert!(
        a_black
            .shadow_transmission([0.0, 1.0, 0.0], &s)
            .is_none_or(|c| c.is_black())
    );
    let omega = 1e-3;
    for wo in [[0.0f64, 1.0, 0.0], [0.4, 0.7, 0.3], [0.2, -0.8, 0.4]] {
        let n: f64 = (wo[0] * wo[0] + wo[1] * wo[1] + wo[2] * wo[2]).sqrt();
        let wo = [wo[0] / n, wo[1] / n, wo[2] / n];
        let front = wo[1] > 0.0;
        let (mut removed, mut kept) = (Vec::new(), Vec::new());
        for _ in 0..2000 {
            let z: f64 = 2.0 * rng.random::<f64>() - 1.0;
            let phi = 2.0 * std::f64::consts::PI * rng.random::<f64>();
            let r = (1.0 - z * z).sqrt();
            let wi = [r * phi.cos(), z, r * phi.sin()];
            let cos = wi[1].abs();
            let full = b.eval_direct(wo, wi, &s, omega);
            let none = black.eval_direct(wo, wi, &s, omega);
            let col = tinted.eval_direct(wo, wi, &s, omega);
            if (wi[1] > 0.0) != front {
                assert!(
                    none.is_black(),
                    "{wo:?} {wi:?}: transmission under black {none:?}"
                );
                for (c, &k) in tint.iter().enumerate() {
                    let (f, t) = (full.as_slice()[c], col.as_slice()[c]);
                    assert!((t - f * k).abs() <= 1e-6 * f.max(1e-9), "{t} vs {f} x {k}");
                }
            } else {
                // (full - black) / (cos omega): the part the pattern removed, per unit
                // projected solid angle: the same for every light direction.
                removed.push((full.as_slice()[1] - none.as_slice()[1]) as f64 / (cos * omega));
                kept.push(none.as_slice()[1] as f64 / (cos * omega));
            }
        }
        let (lo, hi) = removed
            .iter()
            .fold((f64::INFINITY, 0f64), |(a, b), &x| (a.min(x), b.max(x)));
        assert!(
            lo > 0.05 / std::f64::consts::PI * 0.99 || !front,
            "{wo:?}: removed {lo}"
        );
        assert!(
            hi - lo <= 1e-4 * hi.max(1e-6),
            "{wo:?}: removed part varies {lo}..{hi}"
        );
        let (klo, khi) = kept
            .iter()
            .fold((f64::INFINITY, 0f64), |(a, b), &x| (a.min(x), b.max(x)));
        assert!(
            khi > 2.0 * klo.max(1e-9),
            "{wo:?}: kept reflection {klo}..{khi} is not directional"
        );
        // Sampling under the black pattern: transmitted samples carry nothing, and the
        // reflected ones carry what evaluation integrates.
        let m = 200_000;
        let (mut sr, mut er) = (0.0, 0.0);
        for _ in 0..m {
            if let Some(smp) = black.sample(wo, &s, rng.random(), rng.random(), rng.random()) {
                let y = smp.weight.as_slice()[1] as f64;
                if smp.kind.is_transmission() {
                    assert_eq!(y, 0.0, "{wo:?}: transmitted sample under a black pattern");
                } else {
                    sr += y;
                }
            }
            let z: f64 = 2.0 * rng.random::<f64>() - 1.0;
            let phi = 2.0 * std::f64::consts::PI * rng.random::<f64>();
            let r = (1.0 - z * z).sqrt();
            let wi = [r * phi.cos(), z, r * phi.sin()];
            er += black
                .eval_direct(wo, wi, &s, 4.0 * std::f64::consts::PI)
                .as_slice()[1] as f64;
        }
        let (sr, er) = (sr / m as f64, er / m as f64);
        eprintln!("pattern black, wo {wo:.2?}: reflection sampled {sr:.4}, evaluated {er:.4}");
        assert!(
            (sr - er).abs() <= 0.03 * er + 2e-3,
            "{wo:?}: sampled {sr} vs evaluated {er}"
        );
    }
}

/// The function file and transform arguments of a BSDF material (`m_bsdf.c`: thickness and
/// up vector are expressions of the function file, the transform turns the up vector): the
/// blinds with `uy` = 1 (along the window normal, illegal on its own) from `up.cal`, turned
/// onto +Z by `-rx 90`, are the room's window exactly: real rtrace gives the same bytes for
/// both scenes, and so do we. Turned the other way (`-rx -90`, up -Z: the slats upside
/// down), rtrace and we both read differently. An up vector that reads the ray is refused.
#[test]
fn function_file_and_transform_turn_the_up_vector_as_rtrace() {
    if !common::have_radiance("function_file_and_transform_turn_the_up_vector_as_rtrace") {
        return;
    }
    let t = common::tmpdir();
    let d = t.path();
    let base = room_with(d, "blinds45.xml");
    let text = std::fs::read_to_string(&base).unwrap();
    std::fs::write(d.join("up.cal"), "th = 0;\nux = 0;\nuy = 2 - 1;\nuz = 0;\n").unwrap();
    let variant = |name: &str, args: &str| {
        let p = d.join(name);
        let line = format!("void BSDF window_mat {args} 0 0");
        std::fs::write(
            &p,
            text.replace("void BSDF window_mat 6 0 blinds45.xml 0 0 1 . 0 0", &line),
        )
        .unwrap();
        p
    };
    let turned = variant("turned.rad", "8 th blinds45.xml ux uy uz up.cal -rx 90");
    let flipped = variant("flipped.rad", "8 th blinds45.xml ux uy uz up.cal -rx -90");
    let opts = ["-h", "-I", "-ab", "2", "-ad", "2048", "-lw", "1e-4"];
    // -u-: rtrace's correlated sampling, the same sequence every run (its default -u+
    // seeds from the clock), so equal scenes give equal bytes.
    let rtrace = |scene: &std::path::Path| {
        let oct = common::run_ok(common::radiance("oconv").current_dir(d).arg(scene), b"");
        std::fs::write(d.join("x.oct"), oct).unwrap();
        common::run_ok(
            common::radiance("rtrace")
                .current_dir(d)
                .args(["-u-", "-aa", "0", "-as", "0"])
                .args(opts)
                .arg("x.oct"),
            ROOM_SENSORS.as_bytes(),
        )
    };
    let ours = |scene: &std::path::Path| {
        common::run_ok(
            common::ours("rdc")
                .current_dir(d)
                .args(["-s", "3"])
                .args(opts)
                .arg(scene),
            ROOM_SENSORS.as_bytes(),
        )
    };
    let (r_base, r_turned, r_flipped) = (rtrace(&base), rtrace(&turned), rtrace(&flipped));
    assert_eq!(
        r_base, r_turned,
        "rtrace: the transform should turn uy onto +Z"
    );
    assert_ne!(r_base, r_flipped);
    let (o_base, o_turned, o_flipped) = (ours(&base), ours(&turned), ours(&flipped));
    assert_eq!(
        o_base, o_turned,
        "ours: the transform should turn uy onto +Z"
    );
    // Upside-down slats: where rtrace moves by more than 30 % (the sensor by the window:
    // -76 %; the others move by under 10 %, measured at -ad 8192 / 65536), we move the
    // same way by more than 30 %.
    let (rb, rf) = (numbers(&r_base, 3), numbers(&r_flipped, 3));
    let (ob, of) = (numbers(&o_base, 3), numbers(&o_flipped, 3));
    let mut moved = 0;
    for s in 0..rb.len() {
        let (r, o) = (rf[s] / rb[s] - 1.0, of[s] / ob[s] - 1.0);
        eprintln!(
            "sensor {s}: slats upside down: rtrace {:+.1} %, ours {:+.1} %",
            100.0 * r,
            100.0 * o
        );
        if r.abs() > 0.3 {
            moved += 1;
            assert!(
                o.abs() > 0.3 && r.signum() == o.signum(),
                "sensor {s}: rtrace {r} ours {o}"
            );
        }
    }
    assert!(moved >= 1, "upside-down slats changed nothing in rtrace");
    // An up vector that depends on the hit point is refused with the material's place.
    let varying = variant("varying.rad", "6 0 blinds45.xml 0 0 Pz .");
    let out = common::run(
        common::ours("rdc").current_dir(d).args(opts).arg(&varying),
        ROOM_SENSORS.as_bytes(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("varying.rad:") && err.contains("depends on the ray"),
        "{err}"
    );
    // So is one that does not parse, naming the scene line.
    let broken = variant("broken.rad", "6 0 blinds45.xml 0 0 (1 .");
    let out = common::run(
        common::ours("rdc").current_dir(d).args(opts).arg(&broken),
        ROOM_SENSORS.as_bytes(),
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("broken.rad:") && err.contains("does not parse"),
        "{err}"
    );
}

/// Work-plane and vertical sensors of `room.rad`.
const ROOM_SENSORS: &str = "2 1 .8 0 0 1\n2 2.5 .8 0 0 1\n2 4 .8 0 0 1\n1 2.5 .8 0 0 1\n3 2.5 .8 0 0 1\n2 2.5 1.5 0 -1 0\n";

/// The room scene with `xml` as its window, written beside the fixtures (the XML is found
/// beside the scene, as Radiance finds it on RAYPATH's `.`).
fn room_with(dir: &std::path::Path, xml: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(data("room.rad")).unwrap();
    let p = dir.join(format!("room_{xml}.rad"));
    std::fs::write(&p, text.replace("WINDOW_XML", xml)).unwrap();
    std::fs::copy(data(xml), dir.join(xml)).unwrap();
    p
}

fn numbers(bytes: &[u8], per_line: usize) -> Vec<f64> {
    rgb_numbers(bytes, per_line)
        .into_iter()
        .map(photopic)
        .collect()
}

/// The first three values of each non-empty line.
fn rgb_numbers(bytes: &[u8], per_line: usize) -> Vec<[f64; 3]> {
    String::from_utf8(bytes.to_vec())
        .unwrap()
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|w| w.parse().unwrap()).collect();
            assert_eq!(v.len(), per_line, "{l}");
            [v[0], v[1], v[2]]
        })
        .collect()
}

/// Irradiance through each Klems window at six sensors: `rdc -I -h` against three real
/// `rtrace -I` runs (Radiance has no seed: runs 2 and 3 prepend 17 and 41 copies of the
/// first sensor and drop those rows), same `-ab 4 -lw 1e-5 -st .15`.
///
/// Criterion: per sensor, |ours - mean(rtrace)| within 3 combined standard errors (the
/// spread of the rtrace mean, sd / sqrt 3, and ours from `--se-out`) plus 2 % of the value
/// (issue 20's margin). Why our SE is in it: rtrace branches at every BSDF hit (both
/// specular samples and a full ambient hemisphere) while we trace one path per sample, so
/// at the same `-ad` our noise through the peaked blind matrix is 2-3 x Radiance's
/// (measured: 6.7 % relative SE at -ad 8192 for the ceiling-lit sensors, rtrace's run-to-run
/// CV 1-5 % at -ad 4096); ours therefore runs at -ad 262144 (about 1.5 % SE, under a second).
#[test]
fn room_irradiance_through_klems_windows_agrees_with_rtrace() {
    if !common::have_radiance("room_irradiance_through_klems_windows_agrees_with_rtrace") {
        return;
    }
    room_agrees_with_rtrace(&KLEMS);
}

/// The same room and criterion through the rank-3 tensor-tree window (`lobe_tt.xml`):
/// rtrace's tree evaluation and sampling (`bsdf_t.c`) against ours (`ttree`).
#[test]
fn room_irradiance_through_a_tensor_tree_window_agrees_with_rtrace() {
    if !common::have_radiance("room_irradiance_through_a_tensor_tree_window_agrees_with_rtrace") {
        return;
    }
    room_agrees_with_rtrace(&["lobe_tt.xml"]);
}

/// Patterns on a BSDF window (`m_bsdf.c`: the pattern colour multiplies the diffuse parts
/// and the transmission, not the non-diffuse reflection): the same room and criterion with
/// each Klems window modified by a constant `colorfunc` (0.3, 0.6, 0.9) and a `brightfunc`
/// of the hit point (horizontal stripes of 1 and 0.3, 0.25 m each), red, green and blue
/// compared separately.
#[test]
fn room_through_patterned_klems_windows_agrees_with_rtrace() {
    if !common::have_radiance("room_through_patterned_klems_windows_agrees_with_rtrace") {
        return;
    }
    room_agrees_with_rtrace_as(&KLEMS, Some(PATTERN));
}

/// The patterns of the test above (the window material's modifier becomes `stripes`).
const PATTERN: &str = "void colorfunc tint 4 .3 .6 .9 .\n0\n0\n\
tint brightfunc stripes 2 stripe stripes.cal\n0\n0\n";

fn room_agrees_with_rtrace(xmls: &[&str]) {
    room_agrees_with_rtrace_as(xmls, None)
}

/// `pattern`: scene text defining a modifier `stripes` (and `stripes.cal`) that modifies
/// the window material; then the channels are compared one by one, else photopic values.
fn room_agrees_with_rtrace_as(xmls: &[&str], pattern: Option<&str>) {
    let t = common::tmpdir();
    // -st .15 (rtrace's default) on both: matrix parts whose total is at most 0.15 are
    // sampled as diffuse in Radiance (specthresh), so the rule is exercised.
    let opts = ["-ab", "4", "-lw", "1e-5", "-st", ".15"];
    for &xml in xmls {
        let scene = room_with(t.path(), xml);
        if let Some(p) = pattern {
            let text = std::fs::read_to_string(&scene).unwrap();
            let text = text.replace("void BSDF window_mat", "stripes BSDF window_mat");
            std::fs::write(&scene, format!("{p}{text}")).unwrap();
            std::fs::write(
                t.path().join("stripes.cal"),
                "stripe = if(sin(4 * PI * Pz), 1, .3);\n",
            )
            .unwrap();
        }
        // The values compared: photopic, or each channel under a coloured pattern.
        let pick = |v: Vec<[f64; 3]>| -> Vec<f64> {
            match pattern {
                None => v.into_iter().map(photopic).collect(),
                Some(_) => v.into_iter().flatten().collect(),
            }
        };
        let per = if pattern.is_some() { 3 } else { 1 };
        let oct = t.path().join(format!("{xml}.oct"));
        let o = common::run_ok(common::radiance("oconv").arg(&scene), b"");
        std::fs::write(&oct, o).unwrap();
        let n = ROOM_SENSORS.lines().count();
        let first = ROOM_SENSORS.lines().next().unwrap();
        let mut runs: Vec<Vec<f64>> = Vec::new();
        for pad in [0usize, 17, 41] {
            let input = format!("{}{ROOM_SENSORS}", format!("{first}\n").repeat(pad));
            let out = common::run_ok(
                common::radiance("rtrace")
                    .current_dir(t.path())
                    .args(["-h", "-I", "-aa", "0", "-as", "0", "-ad", "4096"])
                    .args(opts)
                    .arg(&oct),
                input.as_bytes(),
            );
            runs.push(pick(rgb_numbers(&out, 3))[per * pad..].to_vec());
        }
        let se_path = t.path().join(format!("{xml}.se"));
        let ours = pick(rgb_numbers(
            &common::run_ok(
                common::ours("rdc")
                    .current_dir(t.path())
                    .args(["-I", "-h", "-s", "5", "-ad", "262144", "--se-out"])
                    .arg(&se_path)
                    .args(opts)
                    .arg(&scene),
                ROOM_SENSORS.as_bytes(),
            ),
            3,
        ));
        let se_text = std::fs::read_to_string(&se_path).unwrap();
        let rel_se: Vec<f64> = se_text
            .split("\n\n")
            .nth(1)
            .unwrap()
            .lines()
            .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
            .collect();
        assert_eq!((ours.len(), rel_se.len()), (n * per, n));
        // Each channel takes its sensor's relative standard error (ours reports one).
        let rel_se: Vec<f64> = rel_se.iter().flat_map(|&x| vec![x; per]).collect();
        let n = n * per;
        let (mut rel, mut cv) = (Vec::new(), Vec::new());
        for s in 0..n {
            let v: Vec<f64> = runs.iter().map(|r| r[s]).collect();
            let mean = v.iter().sum::<f64>() / 3.0;
            let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 2.0).sqrt();
            let sigma = (sd * sd / 3.0 + (rel_se[s] * ours[s]).powi(2)).sqrt();
            let d = ours[s] - mean;
            eprintln!(
                "{xml} sensor {s}: ours {:.5} (se {:.2} %) rtrace {:.5} {:.5} {:.5} (cv {:.2} %): diff {:+.2} % = {:+.1} sigma",
                ours[s],
                100.0 * rel_se[s],
                v[0],
                v[1],
                v[2],
                100.0 * sd / mean,
                100.0 * d / mean,
                d / sigma
            );
            assert!(
                d.abs() <= 3.0 * sigma + 0.02 * mean,
                "{xml} sensor {s}: ours {} vs rtrace mean {mean} (sigma {sigma})",
                ours[s]
            );
            rel.push((d / mean).abs());
            cv.push(sd / mean);
        }
        rel.sort_by(|a, b| a.partial_cmp(b).unwrap());
        cv.sort_by(|a, b| a.partial_cmp(b).unwrap());
        eprintln!(
            "{xml}: |diff| median {:.2} % max {:.2} %; rtrace cv median {:.2} % max {:.2} %",
            100.0 * rel[n / 2],
            100.0 * rel[n - 1],
            100.0 * cv[n / 2],
            100.0 * cv[n - 1]
        );
    }
}

/// The tensor-tree fixture is bsdf2ttree's rendering of a known function (make.sh):
/// reflection 0.2/pi everywhere; transmission 0.05/pi + 0.5 max(0, -i.o)^20. Our lookup
/// must give it back within what a 2^5-cell grid (culled 90 %, no interpolation) can hold.
/// Measured (seed 5, 4000 pairs): reflection exact to 1e-6; transmission more than 72 deg
/// off the lobe worst 6.9 % (grazing pairs, |z| < 0.1, whose cells reach toward the
/// lobe); mean over all transmission pairs 9.4 % (the lobe's steep flanks); the peak
/// 0.489 against 0.516 (the peak cell's average). The bounds sit above those figures
/// with the grid's reasons; a wrong axis, bit order or side rule gives errors of 100 %+.
#[test]
fn tensor_tree_lookup_reproduces_the_function_bsdf2ttree_sampled() {
    use rand::{Rng, SeedableRng};
    use rdaylight::material::ttree::TreeBsdf;
    let x = bsdf::load(&data("lobe_tt.xml")).unwrap();
    let t = TreeBsdf::from_xml(&x, "lobe_tt.xml").unwrap();
    let pi = std::f64::consts::PI;
    let truth = |i: [f64; 3], o: [f64; 3]| {
        if i[2] * o[2] < 0.0 {
            let d = -(i[0] * o[0] + i[1] * o[1] + i[2] * o[2]);
            0.05 / pi + 0.5 * d.max(0.0).powi(20)
        } else {
            0.2 / pi
        }
    };
    let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
    let mut dir = |front: bool| {
        let z: f64 = rng.random::<f64>().max(0.05);
        let phi = 2.0 * std::f64::consts::PI * rng.random::<f64>();
        let r = (1.0 - z * z).sqrt();
        [r * phi.cos(), r * phi.sin(), if front { z } else { -z }]
    };
    let (mut worst_r, mut worst_t_far, mut sum_t, mut n_t) = (0f64, 0f64, 0f64, 0usize);
    for k in 0..4000 {
        let (fi, fo) = (k % 2 == 0, (k / 2) % 2 == 0);
        let (i, o) = (dir(fi), dir(fo));
        // eval is the directional part; the Lambertian minimum (extract_diffuse) adds back.
        let lamb = t.lamb[if fi == fo { 0 } else { 2 }] / pi;
        let (ours, want) = (t.eval(i, o) + lamb, truth(i, o));
        let rel = (ours - want).abs() / want;
        if fi == fo {
            worst_r = worst_r.max(rel);
        } else {
            let d = -(i[0] * o[0] + i[1] * o[1] + i[2] * o[2]);
            // Off the lobe: more than 72 degrees from straight through, where the lobe
            // term is below 0.5 x 0.3^20 (1e-11) and a leaf cell cannot reach it.
            if d < 0.3 && rel > worst_t_far {
                worst_t_far = rel;
            }
            sum_t += rel;
            n_t += 1;
        }
    }
    let mean_t = sum_t / n_t as f64;
    // Straight through at normal incidence: the lobe's peak, 0.05/pi + 0.5.
    let peak = t.eval([0.0, 0.0, 1.0], [0.0, 0.0, -1.0]) + t.lamb[2] / pi;
    eprintln!(
        "tensor tree: peak {peak:.4} (function {:.4})",
        0.05 / pi + 0.5
    );
    eprintln!(
        "tensor tree: reflection worst {:.3} %, transmission off-lobe worst {:.2} %, mean {:.2} %",
        100.0 * worst_r,
        100.0 * worst_t_far,
        100.0 * mean_t
    );
    assert!(worst_r < 5e-4, "reflection {worst_r}");
    assert!(
        worst_t_far < 0.10,
        "transmission off the lobe {worst_t_far}"
    );
    assert!(mean_t < 0.12, "transmission mean {mean_t}");
    assert!((peak / (0.05 / pi + 0.5) - 1.0).abs() < 0.1, "peak {peak}");
}

/// Robustness: prefixes of real fixtures and random bytes give errors with a location,
/// never a panic.
#[test]
fn truncated_fixtures_and_random_bytes_are_clean_errors() {
    use rand::{Rng, SeedableRng};
    for f in ["lobe_tt.xml", "blinds45.xml"] {
        let text = std::fs::read_to_string(data(f)).unwrap();
        let step = text.len() / 150;
        for k in 1..150 {
            let mut i = k * step;
            while !text.is_char_boundary(i) {
                i -= 1;
            }
            let e = bsdf::parse(&text[..i], f).unwrap_err().to_string();
            assert!(e.starts_with(&format!("{f}:")), "{e}");
            assert_eq!(e.lines().count(), 1, "{e}");
        }
    }
    let mut rng = rand_pcg::Pcg64::seed_from_u64(9);
    for _ in 0..200 {
        let n = rng.random_range(0..400);
        let bytes: Vec<u8> = (0..n).map(|_| rng.random()).collect();
        let s = String::from_utf8_lossy(&bytes);
        assert!(bsdf::parse(&s, "r.xml").is_err());
        let doc = format!("<WindowElement><Optical><Layer>{s}</Layer></Optical></WindowElement>");
        let _ = bsdf::parse(&doc, "r.xml");
    }
}

/// `aBSDF` with the shade and a sun (a distant `light`): shadow rays pass the shade's
/// straight-through peak (its 9.45 % openness) onto the floor, and the window's own
/// direct evaluation leaves that peak out (m_bsdf.c's over-counting rule). Floor sensors in
/// and out of the sun patch and a vertical one, `rdc -I -h` vs two rtrace runs at
/// `-ab 2`; the same criterion as the room test (3 combined standard errors + 2 %).
/// Measured once by hand: ours 0.076/0.080, 0.055/0.054, 0.010/0.009, 0.091/0.091 vs
/// rtrace 0.078/0.077, 0.055/0.055, 0.009/0.009, 0.092/0.093.
#[test]
fn absdf_shade_passes_the_sun_like_rtrace() {
    if !common::have_radiance("absdf_shade_passes_the_sun_like_rtrace") {
        return;
    }
    let t = common::tmpdir();
    let text = std::fs::read_to_string(data("room.rad")).unwrap().replace(
        "void BSDF window_mat 6 0 WINDOW_XML 0 0 1 . 0 0",
        "void aBSDF window_mat 5 shade10.xml 0 0 1 . 0 0",
    );
    let text = format!(
        "{text}void light solar 0 0 3 1e4 1e4 1e4\nsolar source sun 0 0 4 0 -1 0.6 0.533\n"
    );
    assert!(text.contains("aBSDF"));
    let scene = t.path().join("sun.rad");
    std::fs::write(&scene, text).unwrap();
    std::fs::copy(data("shade10.xml"), t.path().join("shade10.xml")).unwrap();
    let oct = t.path().join("sun.oct");
    std::fs::write(
        &oct,
        common::run_ok(common::radiance("oconv").arg(&scene), b""),
    )
    .unwrap();
    let sensors = "2 2 .01 0 0 1\n2 3 .01 0 0 1\n2 4.5 .01 0 0 1\n2 2.5 1.5 0 -1 0\n";
    let opts = ["-ab", "2", "-lw", "1e-5", "-st", ".15"];
    let mut runs = Vec::new();
    for pad in [0usize, 7] {
        let first = sensors.lines().next().unwrap();
        let input = format!("{}{sensors}", format!("{first}\n").repeat(pad));
        let out = common::run_ok(
            common::radiance("rtrace")
                .current_dir(t.path())
                .args(["-h", "-I", "-aa", "0", "-as", "0", "-ad", "4096"])
                .args(opts)
                .arg(&oct),
            input.as_bytes(),
        );
        runs.push(numbers(&out, 3)[pad..].to_vec());
    }
    let se_path = t.path().join("sun.se");
    let ours = numbers(
        &common::run_ok(
            common::ours("rdc")
                .current_dir(t.path())
                .args(["-I", "-h", "-s", "3", "-ad", "65536", "--se-out"])
                .arg(&se_path)
                .args(opts)
                .arg(&scene),
            sensors.as_bytes(),
        ),
        3,
    );
    let se_text = std::fs::read_to_string(&se_path).unwrap();
    let rel_se: Vec<f64> = se_text
        .split("\n\n")
        .nth(1)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .collect();
    for s in 0..4 {
        let (a, b) = (runs[0][s], runs[1][s]);
        let mean = 0.5 * (a + b);
        let sd = (a - b).abs() / 2f64.sqrt();
        let sigma = (sd * sd / 2.0 + (rel_se[s] * ours[s]).powi(2)).sqrt();
        let d = ours[s] - mean;
        eprintln!(
            "aBSDF sun sensor {s}: ours {:.5} (se {:.2} %) rtrace {a:.5} {b:.5}: diff {:+.2} %",
            ours[s],
            100.0 * rel_se[s],
            100.0 * d / mean
        );
        assert!(
            d.abs() <= 3.0 * sigma + 0.02 * mean,
            "sensor {s}: ours {} vs rtrace {mean}",
            ours[s]
        );
    }
}
