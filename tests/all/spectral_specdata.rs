//! Function-file patterns (`specdata`, `specfunc`, `brightfunc`, `colorfunc` with `.cal`
//! files, evaluated by [`rdaylight::cal`]) traced by rdc and by real `rtrace -cs N -co`.
//!
//! Patterns are evaluated per escaping ray on skies and per hit on surfaces.
//! The scenes are direct views and direct sunlight (`-ab 0`), so both tracers are
//! deterministic: agreement is to the printed digits (2e-3 relative allowed, for float
//! rounding, in RGB runs too since the spectrum -> RGB step uses Radiance's cumulative
//! observer tables (`scolor2rgb`; with the 5 nm CIE table the sky's coarse 6-sample spectra
//! were up to 3.5 % off on blue)), except
//! - `specfunc`: Radiance jitters each wavelength sample with `frandom()` (up to 2 % per
//!   ray here), we sample at the step centres; the mean of 400 rtrace rays is compared
//!   within 1 % (its standard error is about 0.1 %).
//!
//! Data: `tests/data/specdata/` (`sky_alt.dat` 2-D with an irregular wavelength axis,
//! `refl.dat` 2-D regular, `sky.cal`). The sky's coordinate runs past the data range on
//! both sides, so Radiance's extrapolation and taper are compared too.

use crate::common;

use std::path::Path;

fn rows(text: &str) -> Vec<Vec<f64>> {
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect()
}

/// A temporary folder with the test data and `scene` written as `scene.rad`.
fn setup(scene: &str) -> tempfile::TempDir {
    let t = common::tmpdir();
    let data = common::repo().join("tests/data/specdata");
    for f in ["sky_alt.dat", "refl.dat", "sky.cal"] {
        std::fs::copy(data.join(f), t.path().join(f)).unwrap();
    }
    std::fs::write(t.path().join("scene.rad"), scene).unwrap();
    t
}

fn rtrace(dir: &Path, args: &[&str], rays: &str) -> Vec<Vec<f64>> {
    let oct = common::run_ok(
        common::radiance("oconv").current_dir(dir).arg("scene.rad"),
        b"",
    );
    std::fs::write(dir.join("scene.oct"), oct).unwrap();
    let mut a = vec!["-h", "-ab", "0"];
    a.extend_from_slice(args);
    a.extend_from_slice(&["-co+", "scene.oct"]);
    rows(
        &String::from_utf8(common::run_ok(
            common::radiance("rtrace").current_dir(dir).args(&a),
            rays.as_bytes(),
        ))
        .unwrap(),
    )
}

fn rdc(dir: &Path, args: &[&str], rays: &str) -> Vec<Vec<f64>> {
    let mut a = vec!["-h", "-ab", "0"];
    a.extend_from_slice(args);
    a.push("scene.rad");
    rows(
        &String::from_utf8(common::run_ok(
            common::ours("rdc").current_dir(dir).args(&a),
            rays.as_bytes(),
        ))
        .unwrap(),
    )
}

/// Per value: |ours - theirs| <= tol |theirs| + 1e-6; returns the worst relative error.
fn compare(what: &str, ours: &[Vec<f64>], theirs: &[Vec<f64>], tol: f64) -> f64 {
    assert_eq!(ours.len(), theirs.len(), "{what}: rows");
    let mut worst: f64 = 0.0;
    for (i, (o, t)) in ours.iter().zip(theirs).enumerate() {
        assert_eq!(o.len(), t.len(), "{what} row {i}: channels");
        for (b, (x, y)) in o.iter().zip(t).enumerate() {
            worst = worst.max((x - y).abs() / y.abs().max(1e-9));
            assert!(
                (x - y).abs() <= tol * y.abs() + 1e-6,
                "{what} row {i} channel {b}: ours {x} vs rtrace {y}"
            );
        }
    }
    eprintln!("{what}: worst relative difference {:.2e}", worst);
    worst
}

const VIEW_RAYS: &str = "0 0 0 0 0 1\n0 0 0 0.3 0.2 0.9\n0 0 0 -0.7 0.1 0.4\n\
                         0 0 0 0.2 -0.9 0.3\n0 0 0 0.9 0.4 0.1\n0 0 0 -0.5 -0.5 0.7\n\
                         0 0 0 0.6 0.6 0.5\n0 0 0 0.01 0.99 0.05\n0 0 0 0.3 0.1 -0.8\n";

#[test]
fn specdata_sky_agrees_with_rtrace_per_band() {
    if !common::have_radiance("specdata_sky_agrees_with_rtrace_per_band") {
        return;
    }
    let t = setup(
        "void specdata skyspec\n4 sf sky_alt.dat sky.cal alt\n0\n1 0.7\n\
         skyspec glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n\
         void glow groundglow 0 0 4 .2 .2 .2 0\ngroundglow source ground 0 0 4 0 0 -1 180\n",
    );
    for cs in [&["-cs", "8"][..], &["-cs", "20"], &[]] {
        let theirs = rtrace(t.path(), cs, VIEW_RAYS);
        let ours = rdc(t.path(), cs, VIEW_RAYS);
        compare(&format!("specdata sky {cs:?}"), &ours, &theirs, 2e-3);
    }
}

#[test]
fn brightfunc_colorfunc_and_surface_specdata_agree_with_rtrace() {
    if !common::have_radiance("brightfunc_colorfunc_and_surface_specdata_agree_with_rtrace") {
        return;
    }
    // A .cal brightfunc sky (array, if), a colorfunc ground with file '.', and a floor
    // whose specdata coordinate is a real argument (constant: folded once) lit by a sun.
    let t = setup(
        "void brightfunc skyb\n2 skyb sky.cal\n0\n0\n\
         skyb glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n\
         void colorfunc cf\n4 .8 .5*(1+A1) 1.2 .\n0\n1 .4\n\
         cf glow groundglow 0 0 4 1 1 1 0\ngroundglow source ground 0 0 4 0 0 -1 180\n\
         void specdata floorspec\n4 noop refl.dat . A1\n0\n1 1.3\n\
         floorspec plastic floormat 0 0 5 .6 .6 .6 0 0\n\
         floormat polygon floor 0 0 12 -5 -5 -1 5 -5 -1 5 5 -1 -5 5 -1\n\
         void light sunmat 0 0 3 1e4 1e4 1e4\nsunmat source sun 0 0 4 .3 .2 .9 .533\n",
    );
    // Sky views (up) and floor views (down, lit by the sun).
    let rays = "0 0 0 0 0 1\n0 0 0 0.3 0.2 0.9\n0 0 0 -0.7 0.1 0.4\n0 0 0 0.9 0.4 0.1\n\
                0 0 0 0.1 0.05 -1\n0 0 0 -0.3 0.2 -0.8\n";
    for (cs, tol) in [
        (&["-cs", "8"][..], 2e-3),
        (&["-cs", "20"], 2e-3),
        (&[], 2e-3),
    ] {
        let theirs = rtrace(t.path(), cs, rays);
        let ours = rdc(t.path(), cs, rays);
        compare(
            &format!("brightfunc/colorfunc/floor {cs:?}"),
            &ours,
            &theirs,
            tol,
        );
    }
}

#[test]
fn ray_dependent_surface_patterns_agree_with_rtrace() {
    if !common::have_radiance("ray_dependent_surface_patterns_agree_with_rtrace") {
        return;
    }
    // A floor whose specdata coordinate follows the hit point (Px) and a trans pane whose
    // brightfunc reads Rdot and Nz (the unflipped normal: patterns run before the
    // material flips it), both evaluated per hit; sun-lit, -ab 0.
    let t = setup(
        "void specdata floorspec\n4 noop refl.dat . Px/4+1\n0\n0\n\
         floorspec plastic floormat 0 0 5 .6 .6 .6 0 0\n\
         floormat polygon floor 0 0 12 -5 -5 -1 5 -5 -1 5 5 -1 -5 5 -1\n\
         void brightfunc rd\n2 .5+.5*Rdot*Rdot+.1*Nz .\n0\n0\n\
         rd trans tmat 0 0 7 .7 .6 .5 0 0 .4 0\n\
         tmat polygon pane 0 0 12 2 -5 -.5 2 5 -.5 5 5 -.5 5 -5 -.5\n\
         void light sunmat 0 0 3 1e4 1e4 1e4\nsunmat source sun 0 0 4 .3 .2 .9 .533\n",
    );
    let rays = "0 0 0 0.1 0.05 -1\n0 0 0 -0.6 0.2 -0.5\n0 0 0 -0.1 -0.3 -0.5\n\
                0 0 0 0.3 0.6 -0.5\n0 0 0 0.5 0 -0.15\n3 0 0 0.2 0.1 -1\n3 0 0 -0.2 0.3 -1\n";
    for (cs, tol) in [
        (&["-cs", "8"][..], 2e-3),
        (&["-cs", "20"], 2e-3),
        (&[], 2e-3),
    ] {
        let theirs = rtrace(t.path(), cs, rays);
        let ours = rdc(t.path(), cs, rays);
        compare(&format!("per-hit patterns {cs:?}"), &ours, &theirs, tol);
    }
}

#[test]
fn transformed_patterns_agree_with_rtrace() {
    if !common::have_radiance("transformed_patterns_agree_with_rtrace") {
        return;
    }
    // Transforms on patterns: the sky's specdata tilted (-rx), a ground brightfunc that
    // also reads S and Tx (-rz -s -t), a floor specdata moved, scaled and mirrored.
    let t = setup(
        "void specdata skyspec\n6 sf sky_alt.dat sky.cal alt -rx 30\n0\n1 0.7\n\
         skyspec glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n\
         void brightfunc gb\n10 .5+Dx*Dx+.1*Dy+S*.01+Tx*.02 . -rz 90 -s 2 -t 1 2 0\n0\n0\n\
         gb glow groundglow 0 0 4 .2 .2 .2 0\ngroundglow source ground 0 0 4 0 0 -1 180\n\
         void specdata floorspec\n11 noop refl.dat . Px/4+1 -s 2 -t 1 0 0 -my\n0\n0\n\
         floorspec plastic floormat 0 0 5 .6 .6 .6 0 0\n\
         floormat polygon floor 0 0 12 -5 -5 -1 5 -5 -1 5 5 -1 -5 5 -1\n\
         void light sunmat 0 0 3 1e4 1e4 1e4\nsunmat source sun 0 0 4 .3 .2 .9 .533\n",
    );
    let rays = "0 0 0 0 0 1\n0 0 0 -0.7 0.1 0.4\n0 0 0 0.2 -0.9 0.3\n\
                0 0 0 0.1 0.05 -1\n0 0 0 -0.6 0.2 -0.5\n0 0 0 0.3 0.6 -0.5\n\
                0 0 -2 0.3 0.6 -0.5\n0 0 -2 -0.5 0.1 -0.2\n";
    for cs in [&["-cs", "8"][..], &["-cs", "20"]] {
        let theirs = rtrace(t.path(), cs, rays);
        let ours = rdc(t.path(), cs, rays);
        compare(
            &format!("transformed patterns {cs:?}"),
            &ours,
            &theirs,
            2e-3,
        );
    }
}

#[test]
fn radiance_sky_cal_files_with_transforms_agree_with_rtrace() {
    if !common::have_radiance("radiance_sky_cal_files_with_transforms_agree_with_rtrace") {
        return;
    }
    // Radiance's own skybright.cal (gensky) and perezlum.cal (gendaylit), rotated: with a
    // transform they are not evaluated natively but read from RAYPATH and run through the
    // .cal evaluator, a test of the evaluator on real Radiance files.
    let (_, lib) = common::radiance_dirs().unwrap();
    let make = |prog: &str, args: &[&str], from: &str, to: &str| -> String {
        let out = common::run_ok(common::radiance(prog).args(args), b"");
        let text = String::from_utf8(out).unwrap();
        assert!(text.contains(from), "{prog} output: {text}");
        text.replace(from, to)
    };
    let skies = [
        make(
            "gensky",
            &["3", "21", "11", "+s", "-a", "40", "-o", "105", "-m", "105"],
            "2 skybr skybright.cal",
            "4 skybr skybright.cal -rz 40",
        ),
        make(
            "gendaylit",
            &[
                "6", "21", "9.5", "-a", "40", "-o", "105", "-m", "105", "-W", "600", "120",
            ],
            "2 skybright perezlum.cal",
            "4 skybright perezlum.cal -rz -25",
        ),
    ];
    let rays = "0 0 0 0 0 1\n0 0 0 0.3 0.2 0.9\n0 0 0 -0.7 0.1 0.4\n\
                0 0 0 0.2 -0.9 0.3\n0 0 0 0.9 0.4 0.1\n0 0 0 -0.4 -0.6 0.2\n";
    for sky in skies {
        let t = setup(&format!(
            "{sky}\nskyfunc glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 180\n"
        ));
        let theirs = rtrace(t.path(), &[], rays);
        let ours = rows(
            &String::from_utf8(common::run_ok(
                common::ours("rdc")
                    .current_dir(t.path())
                    .env("RAYPATH", format!(".:{}", lib.display()))
                    .args(["-h", "-ab", "0", "scene.rad"]),
                rays.as_bytes(),
            ))
            .unwrap(),
        );
        compare("rotated Radiance sky", &ours, &theirs, 2e-3);
    }
}

#[test]
fn specfunc_ground_agrees_with_the_mean_of_rtrace() {
    if !common::have_radiance("specfunc_ground_agrees_with_the_mean_of_rtrace") {
        return;
    }
    let t = setup(
        "void specfunc gspec\n2 sp sky.cal\n0\n2 380 780\n\
         gspec glow groundglow 0 0 4 .2 .2 .2 0\ngroundglow source ground 0 0 4 0 0 -1 180\n",
    );
    let rays = "0 0 0 0.2 0.1 -0.9\n".repeat(400);
    for cs in [&["-cs", "8"][..], &[]] {
        let theirs = rtrace(t.path(), cs, &rays);
        let ours = rdc(t.path(), cs, "0 0 0 0.2 0.1 -0.9\n");
        let n = theirs[0].len();
        let mean: Vec<f64> = (0..n)
            .map(|b| theirs.iter().map(|r| r[b]).sum::<f64>() / theirs.len() as f64)
            .collect();
        compare(&format!("specfunc ground {cs:?}"), &ours, &[mean], 1e-2);
    }
}

#[test]
fn bad_patterns_are_reported_with_location() {
    // An undefined spectral function names itself; a transform option that is not
    // modelled (-i arrays) is refused rather than silently ignored.
    let t = setup(
        "void specdata bad\n4 nosuch refl.dat . A1\n0\n1 1\n\
         bad plastic m 0 0 5 .5 .5 .5 0 0\nm polygon p 0 0 12 0 0 0 1 0 0 1 1 0 0 1 0\n",
    );
    let out = common::run(
        common::ours("rdc")
            .current_dir(t.path())
            .args(["-h", "-ab", "0", "-cs", "8", "scene.rad"]),
        b"0 0 1 0 0 -1\n",
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("scene.rad:1:1: specdata 'bad': undefined function 'nosuch'"),
        "{err}"
    );
    let t = setup(
        "void brightfunc turned\n5 Dx . -i 2 -rz\n0\n0\n\
         turned plastic m 0 0 5 .5 .5 .5 0 0\nm polygon p 0 0 12 0 0 0 1 0 0 1 1 0 0 1 0\n",
    );
    let out = common::run(
        common::ours("rdc")
            .current_dir(t.path())
            .args(["-h", "-ab", "0", "-cs", "8", "scene.rad"]),
        b"0 0 1 0 0 -1\n",
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("scene.rad:1:1: unsupported transform option '-i' on brightfunc 'turned'"),
        "{err}"
    );
    // A syntax error in the .cal file: file:line:column and what was expected.
    let t = setup(
        "void brightfunc b\n2 x broken.cal\n0\n0\nb glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n",
    );
    std::fs::write(t.path().join("broken.cal"), "x = 1;\ny = (2 + ;\n").unwrap();
    let out = common::run(
        common::ours("rdc")
            .current_dir(t.path())
            .args(["-h", "-ab", "0", "scene.rad"]),
        b"0 0 0 0 0 1\n",
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("broken.cal:2:10: expected a number, a name, '$N', '-' or '(', found ';'"),
        "{err}"
    );
}
