//! `rmtx`'s products in either loop order: when holding the right-most operand (the sky)
//! would cost more than holding the left rows and the result, the sky's rows are streamed
//! into the result instead (`formats::matrix::Outer`). Both orders give the same bytes,
//! and the product's peak memory stays bounded for the main job's shapes: the sun-only
//! matrix of `make` (5186 suns x 8760 hours) and a dense MF 4 sky (2306 x 8760, where
//! dctimestep peaks at 254 MB and rmtx holding the sky 287 MB; `benches/memory.sh`).
//!
//! Peak memory is the measured program's own maximum resident set (see `run_measured`),
//! deterministic for a given input, unlike time: no timed test here.

use crate::common;

use common::{ours, repo, run_ok, tmpdir};
use rdaylight::formats::matrix::{Matrix, ReadOptions};
use std::io::Write;
use std::path::Path;

fn path(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

/// The data after a Radiance header (the first empty line).
fn data(bytes: &[u8]) -> &[u8] {
    let end = bytes
        .windows(2)
        .position(|w| w == b"\n\n")
        .expect("a header");
    &bytes[end + 2..]
}

/// A float matrix file with a header, `value(row, col, comp)` per number; the headerless
/// data goes to `raw` when given.
fn write_float(
    p: &Path,
    raw: Option<&Path>,
    (nrows, ncols): (usize, usize),
    value: impl Fn(usize, usize, usize) -> f32,
) {
    let mut f = std::io::BufWriter::new(std::fs::File::create(p).unwrap());
    write!(
        f,
        "#?RADIANCE\nNROWS={nrows}\nNCOLS={ncols}\nNCOMP=3\nBigEndian=0\nFORMAT=float\n\n"
    )
    .unwrap();
    let mut bytes = Vec::with_capacity(ncols * 12);
    let mut all = Vec::new();
    for r in 0..nrows {
        bytes.clear();
        for c in 0..ncols {
            for k in 0..3 {
                bytes.extend_from_slice(&value(r, c, k).to_le_bytes());
            }
        }
        f.write_all(&bytes).unwrap();
        if raw.is_some() {
            all.extend_from_slice(&bytes);
        }
    }
    f.flush().unwrap();
    if let Some(raw) = raw {
        std::fs::write(raw, all).unwrap();
    }
}

/// Real coefficients (the first 8 sensors of rcontrib's `office_m1.mtx`, 146 patches)
/// times 48 hours of London: 8 x 146 x 4 + 8 x 48 x 8 bytes in the outer order against
/// 146 x 48 x 24 for the held sky, so the product from files takes the outer order. The
/// same coefficients from headerless standard input (no NROWS: the rows cannot be counted
/// before they are read) take the held order, the code path rmtx always had. Same bytes
/// for float, ascii and double output, with -c, -s and --hours.
#[test]
fn outer_order_gives_the_held_orders_bytes() {
    let t = tmpdir();
    let opts = ReadOptions::default();
    let dc = Matrix::load(
        &path(&repo().join("radiance-fixtures/dc/office_m1.mtx")),
        &opts,
    )
    .unwrap()
    .0;
    let (left, raw) = (t.path().join("dc8.mtx"), t.path().join("dc8.raw"));
    write_float(&left, Some(&raw), (8, dc.ncols), |r, c, k| {
        dc.get(r, c)[k] as f32
    });
    let epw = repo().join("tests/data/weather/london_2days.epw");
    let sky = t.path().join("sky.smx");
    let bytes = run_ok(ours("rspecsky").args(["-m", "1", "-of", &path(&epw)]), b"");
    std::fs::write(&sky, bytes).unwrap();
    let raw_in = std::fs::read(&raw).unwrap();
    let ncols = dc.ncols.to_string();
    for args in [
        vec!["-ff"],
        vec!["-fa", "-c", "47.4", "119.9", "11.6"],
        vec!["-fd", "-s", "0.5"],
        vec!["-ff", "--hours", "7:31"],
    ] {
        let outer = run_ok(
            ours("rmtx").args(&args).args([&path(&left), &path(&sky)]),
            b"",
        );
        let held = run_ok(
            ours("rmtx")
                .args(&args)
                .args(["-if", "--ncols", &ncols, "-", &path(&sky)]),
            &raw_in,
        );
        assert!(data(&outer).iter().any(|&b| b != 0), "{args:?}: all zero");
        assert!(
            data(&outer) == data(&held),
            "{args:?}: the two orders differ"
        );
    }
}

/// Run `program args` (stdin closed) and return its output and its own peak resident set
/// in MB. Not `wait4` on a child of this process: the child is spawned with the parent's
/// address space (vfork) and Linux carries the old address space's high-water mark into
/// the child's `ru_maxrss` at exec, so the test binary's own resident set (other tests'
/// data, often over 150 MB) would be counted. A small Python process forks the program
/// instead, then reports `wait4`'s figure for it alone (its old address space is
/// Python's, about 10 MB) into a file.
fn run_measured(program: &Path, args: &[String]) -> (std::process::Output, f64) {
    use std::process::Stdio;
    const WRAP: &str = "import os, sys\n\
pid = os.fork()\n\
if pid == 0:\n    os.execv(sys.argv[2], sys.argv[2:])\n\
_, status, usage = os.wait4(pid, 0)\n\
open(sys.argv[1], 'w').write(str(usage.ru_maxrss))\n\
sys.exit(os.waitstatus_to_exitcode(status) & 255)\n";
    let t = tmpdir();
    let report = t.path().join("maxrss");
    let out = std::process::Command::new("python3")
        .arg("-c")
        .arg(WRAP)
        .arg(&report)
        .arg(program)
        .args(args)
        .stdin(Stdio::null())
        .output()
        .expect("python3 runs");
    let maxrss: f64 = std::fs::read_to_string(&report)
        .expect("the wrapper's report")
        .trim()
        .parse()
        .expect("a number");
    // ru_maxrss is KiB on Linux, bytes on macOS.
    let kib = if cfg!(target_os = "macos") {
        maxrss / 1024.0
    } else {
        maxrss
    };
    (out, kib / 1024.0)
}

/// The main job's two large products, on synthetic matrices of their shapes (generated
/// here: 545 MB and 242 MB of float): 165 sensors times the sun-only matrix (one sun per
/// daytime hour among 5186 patches, as `rspecsky -m 6 -5 0.533 -d`), and times a dense
/// MF 4 sky (2306 patches, zero at night). Holding the MF 4 sky took 287 MB; both must
/// stay under the 150 MB for the whole `make` job, each product measured alone.
#[test]
fn the_main_jobs_products_stay_under_150_mb() {
    let t = tmpdir();
    let (nsens, hours) = (165usize, 8760usize);
    let daytime = |h: usize| (7..19).contains(&(h % 24));
    let run_product = |left: &Path, right: &Path| -> (Vec<u8>, f64) {
        let args: Vec<String> = ["-ff", "-c", "47.4", "119.9", "11.6"]
            .iter()
            .map(|s| s.to_string())
            .chain([path(left), path(right)])
            .collect();
        let (out, peak) = run_measured(Path::new(env!("CARGO_BIN_EXE_rmtx")), &args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        (out.stdout, peak)
    };
    // Sun coefficients: every sensor sees a band of suns (a window's view).
    let (suns, sun) = (5186usize, t.path().join("sun.mtx"));
    write_float(&sun, None, (nsens, suns), |r, c, k| {
        if (c + r) % 7 < 2 {
            1e-6 * (1 + (c * 3 + k) % 11) as f32
        } else {
            0.0
        }
    });
    let sky_sun = t.path().join("sky_sun.smx");
    write_float(&sky_sun, None, (suns, hours), |p, h, _| {
        if daytime(h) && p == (h * 37) % suns {
            5e5
        } else {
            0.0
        }
    });
    let (direct, peak_sun) = run_product(&sun, &sky_sun);
    std::fs::remove_file(&sky_sun).unwrap();
    // MF 4: sparse coefficients (as rdc's at low -ad: most patches unseen by a sensor).
    let (patches, dc) = (2306usize, t.path().join("dc4.mtx"));
    write_float(&dc, None, (nsens, patches), |r, c, k| {
        if (c * 13 + r) % 19 == 0 {
            1e-4 * (1 + (r + k) % 5) as f32
        } else {
            0.0
        }
    });
    let sky4 = t.path().join("sky4.smx");
    write_float(&sky4, None, (patches, hours), |p, h, k| {
        if daytime(h) {
            (1 + (p + h + k) % 97) as f32
        } else {
            0.0
        }
    });
    let (ill, peak4) = run_product(&dc, &sky4);
    let peak = peak_sun.max(peak4);
    eprintln!("measured peak resident set of the products: {peak:.1} MB (bound 150 MB)");
    // Both products were computed: 165 x 8760 lux values each, daytime ones non-zero.
    let opts = ReadOptions::default();
    for (what, bytes) in [("direct sun", &direct), ("MF 4", &ill)] {
        let m = Matrix::from_reader(&bytes[..], what, &opts).unwrap();
        assert_eq!((m.nrows, m.ncols, m.ncomp()), (nsens, hours, 1), "{what}");
        assert!(m.data.iter().any(|&v| v > 0.0), "{what}: all zero");
    }
    assert!(peak < 150.0, "peak resident set {peak:.1} MB >= 150 MB");
}
