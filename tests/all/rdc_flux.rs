//! `rdc --flux` (the rfluxmtx counterpart, issue 20) against real `rfluxmtx`,
//! `dctimestep` and closed forms, on a small side-lit room (4 x 5 x 3 m, an open 2 x 1 m
//! window in the south wall y = 0, an outside ground plane of reflectance 0.2).
//!
//! Agreement criterion (as `rdc_agreement.rs`, the issue's): per item (a sensor's row sum,
//! a patch's total) the relative difference between ours and the mean of three real runs,
//! median and p95 over items, within Radiance's own run-to-run spread (coefficient of
//! variation over the runs, median and p95) + 2 % / + 5 %. Radiance has no seed option:
//! view-matrix run k gets 7k dummy sensors prepended (rows dropped), daylight-matrix run k
//! `-c 200+k` rays per patch, which reshuffles every sample.

use crate::common;
use rdaylight::formats::matrix::{Matrix, ReadOptions};
use rdaylight::stats::{median, percentile};
use std::path::Path;

const ROOM: &str = "\
void plastic wall 0 0 5 0.5 0.5 0.5 0 0
void plastic floor 0 0 5 0.2 0.2 0.2 0 0
void plastic ceiling 0 0 5 0.8 0.8 0.8 0 0
void plastic ground 0 0 5 0.2 0.2 0.2 0 0
floor polygon fl 0 0 12  0 0 0  4 0 0  4 5 0  0 5 0
ceiling polygon ce 0 0 12  0 0 3  0 5 3  4 5 3  4 0 3
wall polygon wn 0 0 12  0 5 0  4 5 0  4 5 3  0 5 3
wall polygon ww 0 0 12  0 0 0  0 5 0  0 5 3  0 0 3
wall polygon we 0 0 12  4 0 0  4 0 3  4 5 3  4 5 0
wall polygon s1 0 0 12  0 0 0  0 0 3  1 0 3  1 0 0
wall polygon s2 0 0 12  3 0 0  3 0 3  4 0 3  4 0 0
wall polygon s3 0 0 12  1 0 0  1 0 1  3 0 1  3 0 0
wall polygon s4 0 0 12  1 0 2  1 0 3  3 0 3  3 0 2
ground polygon gr 0 0 12  -50 -0.01 0  50 -0.01 0  50 -50 0  -50 -50 0
";

/// The window as a Klems receiver (and sender): a glow polygon facing into the room (+Y).
const WINDOW: &str = "\
#@rfluxmtx h=kf u=+Z
void glow windowglow 0 0 4 1 1 1 0
windowglow polygon window 0 0 12  1 0 1  1 0 2  3 0 2  3 0 1
";

/// The 3-phase sky: ground (one bin) then the Tregenza sky (145 bins): 146 columns in
/// gendaymtx's row order.
const SKY: &str = "\
#@rfluxmtx h=u u=+Y
void glow groundglow 0 0 4 1 1 1 0
groundglow source ground 0 0 4 0 0 -1 180
#@rfluxmtx h=r1 u=+Y
void glow skyglow 0 0 4 1 1 1 0
skyglow source skydome 0 0 4 0 0 1 180
";

/// 20 upward work-plane sensors, 4 across x 5 deep.
fn sensors() -> String {
    let mut s = String::new();
    for y in [0.75, 1.75, 2.75, 3.75, 4.5] {
        for x in [0.5, 1.5, 2.5, 3.5] {
            s.push_str(&format!("{x} {y} 0.8 0 0 1\n"));
        }
    }
    s
}

fn fixture() -> tempfile::TempDir {
    let t = common::tmpdir();
    for (name, text) in [("room.rad", ROOM), ("window.rad", WINDOW), ("sky.rad", SKY)] {
        std::fs::write(t.path().join(name), text).unwrap();
    }
    t
}

fn load(path: &Path) -> Matrix {
    Matrix::load(path.to_str().unwrap(), &ReadOptions::default())
        .unwrap()
        .0
}

fn save(dir: &Path, name: &str, bytes: &[u8]) -> Matrix {
    std::fs::write(dir.join(name), bytes).unwrap();
    load(&dir.join(name))
}

/// Photopic value of element (r, c): Radiance's 0.265 R + 0.670 G + 0.065 B.
fn y(m: &Matrix, r: usize, c: usize) -> f64 {
    let v = m.get(r, c);
    0.265 * v[0] + 0.670 * v[1] + 0.065 * v[2]
}

fn row_sums(m: &Matrix, skip: usize) -> Vec<f64> {
    (skip..m.nrows)
        .map(|r| (0..m.ncols).map(|c| y(m, r, c)).sum())
        .collect()
}

fn col_sums(m: &Matrix, skip: usize) -> Vec<f64> {
    (0..m.ncols)
        .map(|c| (skip..m.nrows).map(|r| y(m, r, c)).sum())
        .collect()
}

/// Ours vs the mean of Radiance's `runs` over `items` (indices into the vectors): asserts
/// the criterion of the module docs (spread = per-item sample standard deviation over the
/// runs / their mean) and prints the figures. Also `shading.rs`'s five-phase check.
pub(crate) fn agree(what: &str, ours: &[f64], runs: &[&[f64]], items: &[usize]) {
    assert!(items.len() >= 5, "{what}: only {} items", items.len());
    let k = runs.len() as f64;
    let mut diff = Vec::new();
    let mut cv = Vec::new();
    let mut bias = 0.0;
    for &i in items {
        let m = runs.iter().map(|r| r[i]).sum::<f64>() / k;
        let var = runs.iter().map(|r| (r[i] - m).powi(2)).sum::<f64>() / (k - 1.0);
        bias += (ours[i] - m) / m / items.len() as f64;
        diff.push(((ours[i] - m) / m).abs());
        cv.push(var.sqrt() / m);
    }
    let (d_med, d_p95) = (median(&diff), percentile(&diff, 95.0));
    let (s_med, s_p95) = (median(&cv), percentile(&cv, 95.0));
    eprintln!(
        "{what}, {} items: median {:.2} % (limit {:.2}), p95 {:.2} % (limit {:.2}), mean signed {:+.2} %",
        items.len(),
        100.0 * d_med,
        100.0 * (s_med + 0.02),
        100.0 * d_p95,
        100.0 * (s_p95 + 0.05),
        100.0 * bias
    );
    assert!(
        d_med <= s_med + 0.02,
        "{what}: median {d_med} > {s_med} + 0.02"
    );
    assert!(
        d_p95 <= s_p95 + 0.05,
        "{what}: p95 {d_p95} > {s_p95} + 0.05"
    );
}

/// Indices whose value carries at least `share` of the total (the patches that matter).
fn heavy(v: &[f64], share: f64) -> Vec<usize> {
    let total: f64 = v.iter().sum();
    (0..v.len()).filter(|&i| v[i] >= share * total).collect()
}

const V_OPTS: [&str; 5] = ["-I+", "-ab", "3", "-lw", "1e-5"];

/// (a) The view matrix V (sensors -> window Klems patches) against rfluxmtx's.
#[test]
fn view_matrix_agrees_with_rfluxmtx() {
    if !common::have_radiance("rdc_flux::view_matrix") {
        return;
    }
    let t = fixture();
    let pts = sensors();
    let pad = "2 2 0.8 0 0 1\n".repeat(7);
    let rf = |input: String| {
        common::run_ok(
            common::radiance("rfluxmtx")
                .current_dir(t.path())
                .args(V_OPTS)
                .args(["-ad", "16384", "-faa", "-", "window.rad", "room.rad"]),
            input.as_bytes(),
        )
    };
    // Three runs, k x 7 dummy sensors in front of run k (their rows dropped).
    let runs: Vec<Matrix> = (0..3)
        .map(|k| {
            save(
                t.path(),
                &format!("r{k}.vmx"),
                &rf(format!("{}{pts}", pad.repeat(k))),
            )
        })
        .collect();
    // Four times Radiance's -ad: our sensor paths do not fan out at each bounce as
    // rcontrib's ambient samples do, so they need more samples for its noise.
    let ours = common::run_ok(
        common::ours("rdc")
            .current_dir(t.path())
            .args(["--flux", "-s", "5"])
            .args(V_OPTS)
            .args(["-ad", "65536", "-faf", "-", "window.rad", "room.rad"]),
        pts.as_bytes(),
    );
    let ours = save(t.path(), "ours.vmx", &ours);
    assert_eq!((ours.nrows, ours.ncols), (20, 145));
    assert_eq!((runs[0].ncols, runs[2].nrows), (145, 34));
    let rows: Vec<Vec<f64>> = (0..3).map(|k| row_sums(&runs[k], 7 * k)).collect();
    let rows: Vec<&[f64]> = rows.iter().map(|v| v.as_slice()).collect();
    let all: Vec<usize> = (0..20).collect();
    agree(
        "V row sums (sensor irradiance from the window)",
        &row_sums(&ours, 0),
        &rows,
        &all,
    );
    let cols: Vec<Vec<f64>> = (0..3).map(|k| col_sums(&runs[k], 7 * k)).collect();
    let cols: Vec<&[f64]> = cols.iter().map(|v| v.as_slice()).collect();
    let items = heavy(cols[0], 0.01);
    agree(
        "V patch totals (patches with >= 1 % of the flux)",
        &col_sums(&ours, 0),
        &cols,
        &items,
    );
}

const D_OPTS: [&str; 6] = ["-ab", "1", "-ad", "128", "-lw", "1e-3"];

/// (b) The daylight matrix D (window -> ground + Tregenza sky) against rfluxmtx's.
#[test]
fn daylight_matrix_agrees_with_rfluxmtx() {
    if !common::have_radiance("rdc_flux::daylight_matrix") {
        return;
    }
    let t = fixture();
    let rf = |c: &str| {
        common::run_ok(
            common::radiance("rfluxmtx")
                .current_dir(t.path())
                .args(D_OPTS)
                .args(["-c", c, "-faa", "window.rad", "sky.rad", "room.rad"]),
            b"",
        )
    };
    let runs: Vec<Matrix> = ["200", "201", "202"]
        .iter()
        .map(|c| save(t.path(), &format!("r{c}.dmx"), &rf(c)))
        .collect();
    // Our sender rays fan out -ad 128 directions at the ground as Radiance's do; more rays
    // per patch than Radiance's runs so that our own noise is small beside theirs.
    let ours = common::run_ok(
        common::ours("rdc")
            .current_dir(t.path())
            .args(["--flux", "-s", "3", "-c", "800"])
            .args(D_OPTS)
            .args(["-fad", "window.rad", "sky.rad", "room.rad"]),
        b"",
    );
    let ours = save(t.path(), "ours.dmx", &ours);
    assert_eq!((ours.nrows, ours.ncols), (145, 146));
    assert_eq!((runs[0].nrows, runs[0].ncols), (145, 146));
    let rows: Vec<Vec<f64>> = runs.iter().map(|m| row_sums(m, 0)).collect();
    let rows: Vec<&[f64]> = rows.iter().map(|v| v.as_slice()).collect();
    let all: Vec<usize> = (0..145).collect();
    agree(
        "D row sums (a window patch under a uniform sky)",
        &row_sums(&ours, 0),
        &rows,
        &all,
    );
    let cols: Vec<Vec<f64>> = runs.iter().map(|m| col_sums(m, 0)).collect();
    let cols: Vec<&[f64]> = cols.iter().map(|v| v.as_slice()).collect();
    let items = heavy(cols[0], 0.01);
    agree(
        "D sky-patch totals (patches with >= 1 % of the flux)",
        &col_sums(&ours, 0),
        &cols,
        &items,
    );
}

/// A Reinhart MF 1 sky vector (146 rows, ground first): radiance 1 + 2 sin(altitude), the
/// ground 0.3, grey.
fn sky_vector() -> String {
    let mut s =
        String::from("#?RADIANCE\nNROWS=146\nNCOLS=1\nNCOMP=3\nFORMAT=ascii\n\n0.3 0.3 0.3\n");
    let alpha = 90.0 / 7.5;
    for (r, n) in [30, 30, 24, 24, 18, 12, 6, 1].iter().enumerate() {
        let alt = (alpha * (r as f64 + 0.5)).min(90.0).to_radians();
        let v = 1.0 + 2.0 * alt.sin();
        for _ in 0..*n {
            s.push_str(&format!("{v} {v} {v}\n"));
        }
    }
    s
}

/// The 145 x 145 identity: the clear aperture's T (a ray arriving at the window in patch
/// b leaves it in patch b: V's and D's bins are the same directions, module docs of
/// `rdc::flux`).
fn identity() -> String {
    let mut s = String::from("#?RADIANCE\nNROWS=145\nNCOLS=145\nNCOMP=3\nFORMAT=ascii\n\n");
    for i in 0..145 {
        let row: Vec<&str> = (0..145)
            .map(|j| if i == j { "1 1 1" } else { "0 0 0" })
            .collect();
        s.push_str(&row.join("\t"));
        s.push('\n');
    }
    s
}

/// Photopic column 0 of a dctimestep result.
fn dctimestep(dir: &Path, args: &[&str]) -> Vec<f64> {
    let out = common::run_ok(
        common::radiance("dctimestep").current_dir(dir).args(args),
        b"",
    );
    let m = save(dir, "dct.out", &out);
    (0..m.nrows).map(|r| y(&m, r, 0)).collect()
}

/// (c) The 3-phase chain V T D s through real dctimestep, T = identity (an open window),
/// equals our own 2-phase coefficients times the same sky within the 2-phase run-to-run
/// spread + 2 % / + 5 %. Bounces: V -ab 7 inside, D -ab 1 outside, 2-phase -ab 8 (paths
/// beyond that carry < 0.5^7 of the light); -lw 1e-7 so that roulette adds little noise.
#[test]
fn three_phase_chain_through_dctimestep_matches_two_phase() {
    if !common::have_radiance("rdc_flux::three_phase") {
        return;
    }
    let t = fixture();
    let dir = t.path();
    std::fs::write(dir.join("sky.vec"), sky_vector()).unwrap();
    std::fs::write(dir.join("ident.mtx"), identity()).unwrap();
    let pts = sensors();
    let rdc = |args: &[&str], input: &str, out: &str| {
        let o = common::run_ok(
            common::ours("rdc").current_dir(dir).args(args),
            input.as_bytes(),
        );
        std::fs::write(dir.join(out), o).unwrap();
    };
    let deep = ["-ad", "8192", "-lw", "1e-7", "-faf"];
    rdc(
        &[
            &["--flux", "-I", "-ab", "7", "-s", "1"][..],
            &deep,
            &["-", "window.rad", "room.rad"],
        ]
        .concat(),
        &pts,
        "v.vmx",
    );
    rdc(
        &[
            "--flux",
            "-ab",
            "1",
            "-c",
            "4000",
            "-s",
            "2",
            "-faf",
            "window.rad",
            "sky.rad",
            "room.rad",
        ],
        "",
        "d.dmx",
    );
    rdc(
        &[
            &["-I", "-ab", "8", "-m", "1", "-s", "3"][..],
            &deep,
            &["room.rad"],
        ]
        .concat(),
        &pts,
        "dc1.mtx",
    );
    rdc(
        &[
            &["-I", "-ab", "8", "-m", "1", "-s", "4"][..],
            &deep,
            &["room.rad"],
        ]
        .concat(),
        &pts,
        "dc2.mtx",
    );
    let three = dctimestep(dir, &["v.vmx", "ident.mtx", "d.dmx", "sky.vec"]);
    let two1 = dctimestep(dir, &["dc1.mtx", "sky.vec"]);
    let two2 = dctimestep(dir, &["dc2.mtx", "sky.vec"]);
    assert_eq!(three.len(), 20);
    let all: Vec<usize> = (0..20).collect();
    agree(
        "V T D s (dctimestep) vs 2-phase",
        &three,
        &[&two1, &two2],
        &all,
    );
    // Our own rmtx reads the same matrices: V D s (T = identity) equals dctimestep's.
    let ours = common::run_ok(
        common::ours("rmtx")
            .current_dir(dir)
            .args(["v.vmx", "d.dmx", "sky.vec"]),
        b"",
    );
    let m = save(dir, "rmtx.out", &ours);
    for (r, want) in three.iter().enumerate() {
        let got = y(&m, r, 0);
        assert!(
            (got - want).abs() <= 1e-4 * want.abs() + 1e-9,
            "row {r}: rmtx {got}, dctimestep {want}"
        );
    }
}

/// Window patch `b`'s share of rays going up, exactly: the window faces +Y with u = +Z,
/// so a ray leaving patch b (local azimuth phi, frame x = -X, y = +Z) travels along
/// `-v` with `z = -sin(theta) sin(phi)`: upward for phi in (pi, 2 pi). Azimuth is uniform
/// inside a patch, so the share is the part of the patch's azimuth range in (180, 360).
fn upward_share(b: usize) -> f64 {
    let basis = rdaylight::geometry::KlemsBasis::new(rdaylight::geometry::KlemsKind::Full);
    let (r, j) = basis.ring_of(b);
    let n = basis.ring_len(r) as f64;
    if n == 1.0 {
        return 0.5;
    }
    let w = 360.0 / n;
    let (lo, hi) = ((j as f64 - 0.5) * w, (j as f64 + 0.5) * w);
    // Overlap of [lo, hi] (possibly starting below 0) with (180, 360) and (-180, 0).
    let overlap = |a: f64, b: f64| (hi.min(b) - lo.max(a)).max(0.0);
    (overlap(180.0, 360.0) + overlap(-180.0, 0.0)) / w
}

/// (d) Energy: a bare opening (no room, no ground) sending to a sky-only receiver. Each row
/// of D times a uniform sky of radiance 1 is the share of the patch's rays that go up
/// ([`upward_share`]: 1, 0 or a known fraction), and the window's irradiance from that sky,
/// sum over patches of lambda_b x row_b, is pi / 2 (a vertical surface sees half the sky).
/// No Radiance needed; the sampling is stratified, so -c 10000 resolves the shares to 1/100.
#[test]
fn bare_opening_rows_are_the_patch_share_of_sky() {
    let t = common::tmpdir();
    let dir = t.path();
    std::fs::write(dir.join("window.rad"), WINDOW).unwrap();
    std::fs::write(
        dir.join("skyonly.rad"),
        "#@rfluxmtx h=r1 u=+Y\nvoid glow skyglow 0 0 4 1 1 1 0\nskyglow source skydome 0 0 4 0 0 1 180\n",
    )
    .unwrap();
    let out = common::run_ok(
        common::ours("rdc").current_dir(dir).args([
            "--flux",
            "-ab",
            "0",
            "-c",
            "10000",
            "-fad",
            "window.rad",
            "skyonly.rad",
        ]),
        b"",
    );
    let d = save(dir, "d.dmx", &out);
    assert_eq!((d.nrows, d.ncols), (145, 145));
    let basis = rdaylight::geometry::KlemsBasis::new(rdaylight::geometry::KlemsKind::Full);
    let rows = row_sums(&d, 0);
    let mut e = 0.0;
    for (b, got) in rows.iter().enumerate() {
        let want = upward_share(b);
        assert!((got - want).abs() <= 0.011, "patch {b}: {got} vs {want}");
        e += basis.lambda(b) * got;
    }
    assert!(
        (e - std::f64::consts::FRAC_PI_2).abs() < 0.005,
        "window irradiance {e}"
    );
}

/// Window-to-window: the window as sender, a copy 1 mm outside as receiver (same file
/// text, shifted): every ray lands in its own patch, so T is the identity (the convention
/// that makes V, T and D concatenate).
#[test]
fn window_to_window_is_the_identity() {
    let t = common::tmpdir();
    let dir = t.path();
    std::fs::write(dir.join("window.rad"), WINDOW).unwrap();
    std::fs::write(
        dir.join("outside.rad"),
        "#@rfluxmtx h=kf u=+Z\nvoid glow og 0 0 4 1 1 1 0\nog polygon o 0 0 12  1 -0.001 1  1 -0.001 2  3 -0.001 2  3 -0.001 1\n",
    )
    .unwrap();
    let out = common::run_ok(
        common::ours("rdc").current_dir(dir).args([
            "--flux",
            "-ab",
            "0",
            "-c",
            "400",
            "-fad",
            "window.rad",
            "outside.rad",
        ]),
        b"",
    );
    let m = save(dir, "t.mtx", &out);
    assert_eq!((m.nrows, m.ncols), (145, 145));
    for b in 0..145 {
        // Grazing patches (theta up to 90 deg) lose the rays that pass the 1 mm gap beside
        // the receiver's edge: at most 1 mm x (edge length) / (2 m^2 x cos), under 1 %
        // above 80 degrees' patches' mean cosine.
        let diag = y(&m, b, b);
        let off: f64 = (0..145).filter(|&c| c != b).map(|c| y(&m, b, c)).sum();
        assert!(
            diag > 0.97 && diag <= 1.0 + 1e-9,
            "patch {b}: diagonal {diag}"
        );
        assert!(off < 1e-9, "patch {b}: {off} outside its own bin");
    }
}

/// Same seed, same bytes whatever -n; o= files replace their targets and hold the
/// columns standard output would have had.
#[test]
fn same_seed_same_bytes_and_o_files() {
    let t = fixture();
    let dir = t.path();
    let d = |n: &str| {
        common::run_ok(
            common::ours("rdc").current_dir(dir).args([
                "--flux",
                "-ab",
                "1",
                "-c",
                "50",
                "-n",
                n,
                "-s",
                "9",
                "-faf",
                "window.rad",
                "sky.rad",
                "room.rad",
            ]),
            b"",
        )
    };
    // The header names the command (with its -n); the data after it must be identical.
    let body = |b: Vec<u8>| {
        let at = b.windows(2).position(|w| w == b"\n\n").expect("header end");
        b[at..].to_vec()
    };
    let one = d("1");
    assert!(body(one.clone()) == body(d("2")), "-n 1 and -n 2 differ");
    let split = SKY
        .replace("h=u u=+Y", "h=u u=+Y o=ground.dmx")
        .replace("h=r1 u=+Y", "h=r1 u=+Y o=sky.dmx");
    std::fs::write(dir.join("sky_o.rad"), split).unwrap();
    let out = common::run_ok(
        common::ours("rdc").current_dir(dir).args([
            "--flux",
            "-ab",
            "1",
            "-c",
            "50",
            "-s",
            "9",
            "-faf",
            "window.rad",
            "sky_o.rad",
            "room.rad",
        ]),
        b"",
    );
    assert!(out.is_empty(), "o= files leave standard output empty");
    let all = save(dir, "all.dmx", &one);
    let (g, s) = (load(&dir.join("ground.dmx")), load(&dir.join("sky.dmx")));
    assert_eq!((g.ncols, s.ncols, s.nrows), (1, 145, 145));
    for r in 0..145 {
        assert_eq!(all.get(r, 0), g.get(r, 0));
        for c in 0..145 {
            assert_eq!(all.get(r, c + 1), s.get(r, c));
        }
    }
}

/// Bad combinations and bad directives: one line naming the option or file:line, exit 1,
/// no output file left behind.
#[test]
fn bad_input_is_one_line() {
    let t = fixture();
    let dir = t.path();
    std::fs::write(
        dir.join("nobasis.rad"),
        "void glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("badh.rad"),
        "#@rfluxmtx h=sc6\nvoid glow g 0 0 4 1 1 1 0\ng source s 0 0 4 0 0 1 180\n",
    )
    .unwrap();
    let cases: [(&[&str], &str); 6] = [
        (
            &["--flux", "-I", "window.rad", "sky.rad", "room.rad"],
            "-I with a sender file",
        ),
        (&["--flux", "-c", "0", "window.rad", "sky.rad"], "-c 0"),
        (
            &["--flux", "-c", "99999999", "window.rad", "sky.rad"],
            "-c 99999999: at most",
        ),
        (&["--flux", "window.rad"], "--flux needs a sender"),
        (&["--flux", "window.rad", "nobasis.rad"], "nobasis.rad:2"),
        (&["--flux", "window.rad", "badh.rad"], "badh.rad:1"),
    ];
    for (args, want) in cases {
        let out = common::run(common::ours("rdc").current_dir(dir).args(args), b"");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
    }
    let files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(files.len(), 5, "{files:?}");
}
