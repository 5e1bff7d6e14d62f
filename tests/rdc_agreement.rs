//! rdc against real Radiance on the committed fixtures (radiance-fixtures/README.md): the
//! project's agreement criterion for daylight coefficients. Per-sensor annual totals (DC x
//! the full-year average London sky, photopic) of ours vs the mean of three real rcontrib runs
//! (`-ab 5 -ad 10000 -lw 1e-5`) must agree within Radiance's own run-to-run spread (from the
//! manifest: median and p95 per-sensor coefficient of variation) plus 2 % (median) and plus
//! 5 % (p95). Our own noise at the same `-ad` is in that budget; the mean signed difference
//! (bias) must stay within 1 %.

mod common;
use rdaylight::formats::matrix::{Matrix, ReadOptions};

/// Photopic weights of `rmtxop -c Y` (what the fixtures' spreads were computed with).
const Y: [f64; 3] = [47.45394, 119.94894, 11.59712];

fn load(path: &std::path::Path) -> Matrix {
    Matrix::load(path.to_str().unwrap(), &ReadOptions::default())
        .unwrap()
        .0
}

/// Annual photopic total per row of `dc` under the average sky column.
fn totals(dc: &Matrix, sky: &Matrix) -> Vec<f64> {
    (0..dc.nrows)
        .map(|r| {
            (0..dc.ncols)
                .map(|p| {
                    let (d, s) = (dc.get(r, p), sky.get(p, 0));
                    (0..3).map(|c| Y[c] * d[c] * s[c]).sum::<f64>()
                })
                .sum()
        })
        .collect()
}

/// (median, p95) of the per-sensor coefficient of variation recorded in the manifest.
fn manifest_spread(file: &str) -> (f64, f64) {
    let text =
        std::fs::read_to_string(common::repo().join("radiance-fixtures/manifest.tsv")).unwrap();
    let cols: Vec<&str> = text
        .lines()
        .find(|l| l.starts_with(&format!("{file}\t")))
        .unwrap_or_else(|| panic!("{file} not in manifest"))
        .split('\t')
        .collect();
    (cols[8].parse().unwrap(), cols[9].parse().unwrap())
}

#[test]
fn office_daylight_coefficients_agree_with_rcontrib() {
    let fx = common::repo().join("radiance-fixtures");
    // Every 4th sensor: 42 rows keep the test short in the (opt-level 1) test profile.
    let pts = std::fs::read_to_string(fx.join("sensors/office.pts")).unwrap();
    let chosen: Vec<(usize, &str)> = pts
        .lines()
        .enumerate()
        .filter(|(i, _)| i % 4 == 0)
        .collect();
    let input: String = chosen.iter().map(|(_, l)| format!("{l}\n")).collect();
    let out = common::run_ok(
        common::ours("rdc").current_dir(&fx).args([
            "-I",
            "-ab",
            "5",
            "-ad",
            "10000",
            "-lw",
            "1e-5",
            "-m",
            "1",
            "-faf",
            "-s",
            "7",
            "scenes/office.rad",
            "scenes/sky_glow360.rad",
        ]),
        input.as_bytes(),
    );
    let t = common::tmpdir();
    std::fs::write(t.path().join("dc.mtx"), out).unwrap();
    let ours = load(&t.path().join("dc.mtx"));
    let theirs = load(&fx.join("dc/office_m1.mtx"));
    let sky = load(&fx.join("sky/london_year_m1_A.smx"));
    assert_eq!((ours.nrows, ours.ncols), (chosen.len(), 146));
    let (a, b) = (totals(&ours, &sky), totals(&theirs, &sky));
    let mut rel: Vec<f64> = chosen
        .iter()
        .zip(&a)
        .map(|((i, _), x)| (x - b[*i]) / b[*i])
        .collect();
    let bias = rel.iter().sum::<f64>() / rel.len() as f64;
    rel.iter_mut().for_each(|r| *r = r.abs());
    rel.sort_by(|x, y| x.partial_cmp(y).unwrap());
    let median = rel[rel.len() / 2];
    let p95 = rel[((rel.len() as f64 * 0.95).ceil() as usize).min(rel.len()) - 1];
    let (s_med, s_p95) = manifest_spread("dc/office_m1.mtx");
    eprintln!(
        "rdc vs rcontrib, office, {} sensors: median {:.2} % (limit {:.2}), p95 {:.2} % (limit {:.2}), bias {:+.2} %",
        rel.len(),
        100.0 * median,
        100.0 * (s_med + 0.02),
        100.0 * p95,
        100.0 * (s_p95 + 0.05),
        100.0 * bias
    );
    assert!(median <= s_med + 0.02, "median {median}");
    assert!(p95 <= s_p95 + 0.05, "p95 {p95}");
    assert!(bias.abs() <= 0.01, "bias {bias}");
}
