//! The spectral chain's loose ends (issue 8): symbolic `rmtx -c` on spectral matrices
//! against real `rmtxop`, spectral coefficients times spectral skies through to
//! illuminance, EXR pictures from `rdc`, and `rdc --uplift`.

mod common;

/// Parse the numbers of an ascii matrix (header skipped).
fn numbers(text: &[u8]) -> Vec<f64> {
    let text = String::from_utf8_lossy(text);
    let body = text.split_once("\n\n").map_or(&*text, |(_, b)| b);
    body.split_whitespace()
        .map(|w| w.parse().expect("a number"))
        .collect()
}

/// A 3x4 matrix with 18 smooth positive spectra, as rcontrib -cs 18 writes it.
fn spectral_matrix(n: usize) -> String {
    let mut s = format!(
        "#?RADIANCE\nNROWS=3\nNCOLS=4\nNCOMP={n}\nWAVELENGTH_SPLITS= 780 588 480 380\n\
         FORMAT=ascii\n\n"
    );
    for r in 0..3 {
        for c in 0..4 {
            for b in 0..n {
                let x = b as f64 / n as f64;
                let v = 0.2
                    + (r * 4 + c) as f64 * 0.05
                    + 0.4 * (3.0 * x + r as f64 + c as f64).sin().abs();
                s.push_str(&format!("{v:.6} "));
            }
            s.push('\t');
        }
        s.push('\n');
    }
    s
}

#[test]
fn symbolic_transforms_of_spectra_agree_with_rmtxop() {
    if !common::have_radiance("symbolic_transforms_of_spectra_agree_with_rmtxop") {
        return;
    }
    let t = common::tmpdir();
    for n in [9, 18] {
        let path = t.path().join(format!("m{n}.mtx"));
        std::fs::write(&path, spectral_matrix(n)).unwrap();
        for (sym, tol) in [
            ("Y", 1e-6),
            ("M", 1e-6),
            // Our V'(lambda) table is within one unit of Radiance's (spectrum::Curve).
            ("S", 1e-5),
            ("y", 1e-6),
            ("m", 1e-6),
            ("A", 1e-6),
            // R G B X Z: rmtxop's band edges land one nm low at some whole-number edges
            // (ops::ChannelTransform::symbolic_for): measured 1.3e-4 (9 bands, blue) here.
            ("RGB", 3e-4),
            ("XYZ", 3e-4),
        ] {
            let theirs = numbers(&common::run_ok(
                common::radiance("rmtxop")
                    .args(["-fa", "-c", sym])
                    .arg(&path),
                b"",
            ));
            let ours = numbers(&common::run_ok(
                common::ours("rmtx").args(["-fa", "-c", sym]).arg(&path),
                b"",
            ));
            assert_eq!(ours.len(), theirs.len(), "-c {sym} ({n} bands)");
            assert_eq!(ours.len(), 12 * sym.len());
            let mut worst: f64 = 0.0;
            for (a, b) in ours.iter().zip(&theirs) {
                worst = worst.max((a - b).abs() / b.abs().max(1e-3));
            }
            eprintln!("-c {sym}, {n} bands: worst relative difference {worst:.2e}");
            assert!(worst < tol, "-c {sym} ({n} bands): {worst:.2e}");
        }
    }
}
