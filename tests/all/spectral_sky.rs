//! `rspecsky -cs N`: spectral sky matrices. Checks the header layout (NCOMP, Radiance's
//! WAVELENGTH_SPLITS), the patch/time-step shape against gendaymtx, that the photopic
//! weighting of every element equals rspecsky's own RGB matrix (W/m2 and lux inputs), and
//! that `rmtx` multiplies 18-band coefficients by the spectral sky exactly as real
//! `rmtxop` does (what dctimestep refuses).

use crate::common;
use rdaylight::formats::matrix::{Matrix, ReadOptions};
use rdaylight::radiometry::{Channels, RGB_PHOTOPIC};
use rdaylight::sky::spectral::photopic_shares;

fn load(path: &std::path::Path) -> Matrix {
    Matrix::load(path.to_str().unwrap(), &ReadOptions::default())
        .unwrap()
        .0
}

fn run_to(cmd: &mut std::process::Command, path: &std::path::Path) {
    let out = common::run_ok(cmd, b"");
    std::fs::write(path, out).unwrap();
}

/// The 4 London days as a .wea in illuminance units (`weather_data_file_units 3`, values
/// x 110 lm/W): gendaymtx's lux input path, which gensdaymtx refuses for W/m2.
fn lux_wea(dir: &std::path::Path) -> std::path::PathBuf {
    let src =
        std::fs::read_to_string(common::repo().join("radiance-fixtures/weather/london_4days.wea"))
            .unwrap();
    let text: String = src
        .lines()
        .map(|l| {
            if l.starts_with("weather_data_file_units") {
                "weather_data_file_units 3".to_string()
            } else if l.split_whitespace().count() == 5 && !l.starts_with(char::is_alphabetic) {
                // W/m2 -> lx with a nominal 110 lm/W (any positive values do).
                let w: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
                format!(
                    "{} {} {} {} {}",
                    w[0],
                    w[1],
                    w[2],
                    w[3] * 110.0,
                    w[4] * 110.0
                )
            } else {
                l.to_string()
            }
        })
        .map(|l| l + "\n")
        .collect();
    let p = dir.join("lux.wea");
    std::fs::write(&p, text).unwrap();
    p
}

fn check_photopic(spec: &Matrix, rgb: &Matrix) {
    assert_eq!((spec.nrows, spec.ncols), (rgb.nrows, rgb.ncols));
    let shares = photopic_shares(&spec.channels);
    let mut worst: f64 = 0.0;
    for r in 0..spec.nrows {
        for c in 0..spec.ncols {
            let y: f64 = spec.get(r, c).iter().zip(&shares).map(|(a, b)| a * b).sum();
            let want: f64 = rgb
                .get(r, c)
                .iter()
                .zip(RGB_PHOTOPIC)
                .map(|(a, b)| a * b)
                .sum();
            if want.abs() > 1e-4 {
                worst = worst.max((y / want - 1.0).abs());
            } else {
                assert!(y.abs() < 2e-4, "row {r} col {c}: {y} vs {want}");
            }
        }
    }
    eprintln!("photopic: worst relative difference {worst:.2e}");
    assert!(worst < 1e-9, "{worst}");
}

#[test]
fn spectral_matrix_is_photopically_the_rgb_matrix() {
    let t = common::tmpdir();
    let wea = common::repo().join("radiance-fixtures/weather/london_4days.wea");
    let lux = lux_wea(t.path());
    for (w, tag) in [(&wea, "wm2"), (&lux, "lux")] {
        let (s, r) = (
            t.path().join(format!("{tag}_s")),
            t.path().join(format!("{tag}_r")),
        );
        run_to(
            common::ours("rspecsky")
                .args(["-cs", "18", "-m", "1", "-od"])
                .arg(w),
            &s,
        );
        run_to(common::ours("rspecsky").args(["-m", "1", "-od"]).arg(w), &r);
        let (spec, rgb) = (load(&s), load(&r));
        assert_eq!(spec.channels, Channels::spectral(18, 380.0, 780.0).unwrap());
        assert_eq!(spec.nrows, 146);
        check_photopic(&spec, &rgb);
    }
    // The header says what Radiance writes.
    let text = std::fs::read(t.path().join("wm2_s")).unwrap();
    let head = String::from_utf8_lossy(&text[..400]);
    assert!(head.contains("NCOMP=18\n"), "{head}");
    assert!(
        head.contains("WAVELENGTH_SPLITS= 780 588 480 380\n"),
        "{head}"
    );
}

#[test]
fn same_shape_as_gendaymtx_and_rmtx_multiplies_like_rmtxop() {
    if !common::have_radiance("spectral rmtx") {
        return;
    }
    let t = common::tmpdir();
    let wea = common::repo().join("radiance-fixtures/weather/london_4days.wea");
    let sky = t.path().join("sky.smx");
    run_to(
        common::ours("rspecsky")
            .args(["-cs", "18", "-m", "1", "-of"])
            .arg(&wea),
        &sky,
    );
    let g = t.path().join("g.smx");
    run_to(
        common::radiance("gendaymtx")
            .args(["-m", "1", "-of"])
            .arg(&wea),
        &g,
    );
    let (ours, theirs) = (load(&sky), load(&g));
    assert_eq!((ours.nrows, ours.ncols), (theirs.nrows, theirs.ncols));
    // 18-band coefficients: the fixture's rcontrib -cs 18 run (7 sensors x 146 patches).
    let dc = common::repo().join("radiance-fixtures/spectral/dc_run1.mtx");
    let (a, b) = (t.path().join("a.mtx"), t.path().join("b.mtx"));
    run_to(common::ours("rmtx").arg(&dc).arg(&sky).arg("-fd"), &a);
    run_to(common::radiance("rmtxop").arg("-fd").arg(&dc).arg(&sky), &b);
    let (x, y) = (load(&a), load(&b));
    assert_eq!(x.channels.ncomp, 18);
    assert_eq!((x.nrows, x.ncols), (7, theirs.ncols));
    assert_eq!(x.data.len(), y.data.len());
    let top = y.data.iter().cloned().fold(0.0, f64::max);
    assert!(top > 0.0);
    for (p, q) in x.data.iter().zip(&y.data) {
        assert!((p - q).abs() <= 1e-5 * q.abs() + 1e-9 * top, "{p} vs {q}");
    }
}

/// Against real gensdaymtx (Radiance 6's spectral sky matrix: Bruneton's clear sky scaled
/// to the EPW's direct and diffuse values, not Perez). Ignored: gensdaymtx precomputes its
/// atmosphere for minutes per distinct aerosol depth. Prints per daytime step the
/// photopic sum over the sky patches (Radiance's `179 sum v_i A_i`) and the blue/red ratio
/// (bands 380-480 nm over 680-780 nm); asserts the median photopic ratio within 10 %.
/// Measured on london_2days.epw (RADIANCE 6.0a): photopic within 1.5 % on the first
/// (overcast-to-bright) day's midday steps, -24 % to +11 % on the second day; our skies are
/// 3-15 % bluer (blue/red 1.41-1.45 vs 1.20-1.40).
#[test]
#[ignore]
fn compare_with_gensdaymtx() {
    if !common::have_radiance("gensdaymtx") {
        return;
    }
    let t = common::tmpdir();
    let epw = common::repo().join("tests/data/weather/london_2days.epw");
    let g = t.path().join("g.smx");
    let out = common::run_ok(
        common::radiance("gensdaymtx")
            .current_dir(t.path())
            .args(["-m", "1", "-n", "2", "-of"])
            .arg(&epw),
        b"",
    );
    std::fs::write(&g, out).unwrap();
    let o = t.path().join("o.smx");
    run_to(
        common::ours("rspecsky")
            .args(["-cs", "20", "-m", "1", "-of"])
            .arg(&epw),
        &o,
    );
    let (ours, theirs) = (load(&o), load(&g));
    assert_eq!(ours.channels, theirs.channels);
    let a = photopic_shares(&ours.channels);
    let sums = |m: &Matrix, c: usize| -> (f64, f64) {
        let (mut y, mut blue, mut red) = (0.0, 0.0, 0.0);
        for p in 1..m.nrows {
            let v = m.get(p, c);
            y += 179.0 * v.iter().zip(&a).map(|(x, w)| x * w).sum::<f64>();
            blue += v[15..20].iter().sum::<f64>();
            red += v[0..5].iter().sum::<f64>();
        }
        (y, blue / red.max(1e-12))
    };
    let mut ratios = Vec::new();
    eprintln!("step  ours_Y  gensdaymtx_Y  ratio  ours_blue/red  gensdaymtx_blue/red");
    for c in 0..ours.ncols {
        let ((yo, bo), (yg, bg)) = (sums(&ours, c), sums(&theirs, c));
        if yo > 1e4 {
            eprintln!("{c} {yo:.0} {yg:.0} {:.3} {bo:.3} {bg:.3}", yg / yo);
            ratios.push(yg / yo);
        }
    }
    ratios.sort_by(f64::total_cmp);
    let med = ratios[ratios.len() / 2];
    assert!(
        (med - 1.0).abs() < 0.1,
        "median gensdaymtx/ours photopic {med}"
    );
}

/// Real `rmtxop -c Y` (Radiance's own observer tables) of the spectral matrix equals its
/// photopic weighting of the RGB matrix to float precision: rspecsky scales its spectra
/// with the same tables (`spec_dot`). Measured 1.2e-7 to 1.8e-7 worst relative (4 London days, MF 1).
#[test]
fn rmtxop_photopic_of_spectral_equals_rgb() {
    if !common::have_radiance("rmtxop -c Y") {
        return;
    }
    let t = common::tmpdir();
    let wea = common::repo().join("radiance-fixtures/weather/london_4days.wea");
    let (s, r) = (t.path().join("s"), t.path().join("r"));
    run_to(
        common::ours("rspecsky")
            .args(["-cs", "18", "-m", "1", "-od"])
            .arg(&wea),
        &s,
    );
    run_to(
        common::ours("rspecsky").args(["-m", "1", "-od"]).arg(&wea),
        &r,
    );
    let y = |p: &std::path::Path| {
        let out = common::run_ok(
            common::radiance("rmtxop").args(["-fd", "-c", "Y"]).arg(p),
            b"",
        );
        let q = p.with_extension("y");
        std::fs::write(&q, out).unwrap();
        load(&q)
    };
    let (ys, yr) = (y(&s), y(&r));
    assert_eq!(ys.data.len(), yr.data.len());
    let top = yr.data.iter().cloned().fold(0.0, f64::max);
    assert!(top > 1.0);
    let mut worst: f64 = 0.0;
    for (a, b) in ys.data.iter().zip(&yr.data) {
        assert!((a - b).abs() <= 1e-6 * b.abs() + 1e-9 * top, "{a} vs {b}");
        if b.abs() > 1e-3 {
            worst = worst.max((a / b - 1.0).abs());
        }
    }
    eprintln!("rmtxop -c Y: spectral vs RGB worst relative {worst:.2e}");
}
