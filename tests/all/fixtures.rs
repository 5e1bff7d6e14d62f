//! Quick checks of the committed Radiance reference fixtures (`radiance-fixtures/`, made by
//! `radiance-fixtures/make_fixtures.sh` with real Radiance):
//!
//! - every file listed in `manifest.tsv` exists with the recorded size, its information header
//!   (if any) parses with [`Header::read`], and its header and data agree with the manifest's
//!   NROWS x NCOLS x NCOMP (float data length, or the count of ascii numbers);
//! - the daylight-coefficient references have the documented shapes (165 sensors x 146 or
//!   2306 patches, RGB);
//! - oracles on Radiance's own outputs: under a uniform unit-radiance glow sky an open upward
//!   sensor's coefficient row sums to pi (within the run-to-run spread measured from the three
//!   runs) and each coefficient equals its patch's projected solid angle; the furnace boxes
//!   give pi, 0 and pi * 0.5^ab as documented in `radiance-fixtures/README.md`.
//!
//! Needs no Radiance installation: it reads files only.

use crate::common;

use rdaylight::formats::header::Header;
use std::f64::consts::PI;
use std::path::PathBuf;

/// One row of `manifest.tsv`.
#[derive(Debug)]
struct Entry {
    file: String,
    kind: String,
    bytes: usize,
    nrows: Option<usize>,
    ncols: Option<usize>,
    ncomp: Option<usize>,
    format: String,
}

fn dir() -> PathBuf {
    common::repo().join("radiance-fixtures")
}

fn opt(s: &str) -> Option<usize> {
    (!s.is_empty()).then(|| s.parse().expect("manifest number"))
}

fn manifest() -> Vec<Entry> {
    let text = std::fs::read_to_string(dir().join("manifest.tsv")).expect("manifest.tsv");
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.starts_with('#') || line.is_empty() {
            continue;
        }
        let f: Vec<&str> = line.splitn(11, '\t').collect();
        assert_eq!(
            f.len(),
            11,
            "manifest.tsv:{}: expected 11 tab-separated fields",
            i + 1
        );
        out.push(Entry {
            file: f[0].to_string(),
            kind: f[1].to_string(),
            bytes: f[2].parse().expect("bytes"),
            nrows: opt(f[3]),
            ncols: opt(f[4]),
            ncomp: opt(f[5]),
            format: f[6].to_string(),
        });
    }
    out
}

/// Header and the data bytes after it.
fn split(bytes: &[u8], name: &str) -> (Header, usize) {
    let mut rest: &[u8] = bytes;
    let h = Header::read(&mut rest, name).unwrap_or_else(|e| panic!("{name}: header: {e}"));
    (h, bytes.len() - rest.len())
}

/// A float/ascii Radiance matrix: (nrows, ncols, ncomp, values row-major).
fn read_matrix(file: &str) -> (usize, usize, usize, Vec<f64>) {
    let bytes = std::fs::read(dir().join(file)).expect(file);
    let (h, off) = split(&bytes, file);
    let ncols = h.get_usize("NCOLS", file).unwrap().expect("NCOLS");
    let ncomp = h.get_usize("NCOMP", file).unwrap().unwrap_or(3);
    let data = &bytes[off..];
    let vals: Vec<f64> = match h.format() {
        Some("float") => {
            assert_eq!(
                h.get("BigEndian"),
                Some("0"),
                "{file}: expected little-endian floats"
            );
            data.chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f64)
                .collect()
        }
        Some("ascii") => std::str::from_utf8(data)
            .expect("utf8")
            .split_whitespace()
            .map(|t| t.parse().expect("number"))
            .collect(),
        other => panic!("{file}: unexpected FORMAT {other:?}"),
    };
    let nrows = vals.len() / (ncols * ncomp);
    assert_eq!(nrows * ncols * ncomp, vals.len(), "{file}: ragged data");
    (nrows, ncols, ncomp, vals)
}

/// Headerless rtrace output: rows of numbers.
fn read_rows(file: &str) -> Vec<Vec<f64>> {
    std::fs::read_to_string(dir().join(file))
        .expect(file)
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            l.split_whitespace()
                .map(|t| t.parse().expect("number"))
                .collect()
        })
        .collect()
}

#[test]
fn every_manifest_file_exists_parses_and_has_the_stated_shape() {
    let entries = manifest();
    assert!(
        entries.len() > 50,
        "manifest lists only {} files",
        entries.len()
    );
    let mut matrices = 0;
    for e in &entries {
        let path = dir().join(&e.file);
        let bytes = std::fs::read(&path).unwrap_or_else(|err| panic!("{}: {err}", e.file));
        assert!(!bytes.is_empty(), "{} is empty", e.file);
        assert_eq!(
            bytes.len(),
            e.bytes,
            "{}: size differs from the manifest",
            e.file
        );
        if !bytes.starts_with(b"#?") {
            // Headerless text (scenes, sensors, rtrace -h values, evalglare): must be UTF-8,
            // and rtrace value files hold 3 finite numbers per line.
            let text = std::str::from_utf8(&bytes).expect("text file");
            if e.file.starts_with("points/") || e.file.ends_with("_rtrace.txt") {
                for l in text.lines() {
                    let v: Vec<f64> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
                    assert!(
                        v.len() == 3 && v.iter().all(|x| x.is_finite()),
                        "{}: {l}",
                        e.file
                    );
                }
            }
            continue;
        }
        let (h, off) = split(&bytes, &e.file);
        assert_eq!(h.magic.as_deref(), Some("RADIANCE"), "{}", e.file);
        if e.file.ends_with(".hdr") {
            assert!(
                h.format().unwrap_or("").contains("rgbe"),
                "{}: picture format",
                e.file
            );
            assert!(h.get("VIEW").is_some(), "{}: picture without VIEW=", e.file);
            continue;
        }
        let (Some(nrows), Some(ncols)) = (e.nrows, e.ncols) else {
            panic!("{}: matrix without NROWS/NCOLS in the manifest", e.file)
        };
        matrices += 1;
        let ncomp = e.ncomp.unwrap_or(3);
        assert_eq!(
            h.get_usize("NCOLS", &e.file).unwrap(),
            Some(ncols),
            "{}",
            e.file
        );
        if let Some(n) = h.get_usize("NROWS", &e.file).unwrap() {
            assert_eq!(n, nrows, "{}", e.file);
        }
        assert_eq!(
            h.get_usize("NCOMP", &e.file).unwrap(),
            e.ncomp,
            "{}",
            e.file
        );
        assert_eq!(h.format(), Some(e.format.as_str()), "{}", e.file);
        let data = &bytes[off..];
        match e.format.as_str() {
            "float" => assert_eq!(data.len(), nrows * ncols * ncomp * 4, "{}", e.file),
            "ascii" => {
                let n = std::str::from_utf8(data)
                    .unwrap()
                    .split_whitespace()
                    .count();
                assert_eq!(n, nrows * ncols * ncomp, "{}", e.file);
            }
            f => panic!("{}: unexpected format {f}", e.file),
        }
        assert!(
            matches!(e.kind.as_str(), "mc" | "exact" | "derived"),
            "{}",
            e.file
        );
    }
    assert!(matrices >= 20, "only {matrices} matrices checked");
}

#[test]
fn daylight_coefficient_references_are_165_sensors_by_patches() {
    for (file, ncols) in [
        ("dc/office_m1.mtx", 146),
        ("dc/office_m1_run1.mtx", 146),
        ("dc/office_m1_run2.mtx", 146),
        ("dc/office_m1_run3.mtx", 146),
        ("dc/furnished_m1.mtx", 146),
        ("dc/specular_m1.mtx", 146),
        ("dc/office_m1_rfluxmtx.mtx", 146),
        ("dc/office_m4.mtx", 2306),
    ] {
        let (nrows, nc, ncomp, vals) = read_matrix(file);
        assert_eq!((nrows, nc, ncomp), (165, ncols, 3), "{file}");
        assert!(
            vals.iter().all(|v| v.is_finite() && *v >= 0.0),
            "{file}: bad value"
        );
        // Every sensor sees some sky; the ground bin (0) is lit by the exterior ground.
        for r in 0..nrows {
            let s: f64 = (0..nc).map(|p| vals[(r * nc + p) * 3]).sum();
            assert!(s > 1e-3 && s < PI, "{file}: row {r} sums to {s}");
        }
    }
}

/// Projected solid angle (integral of cos(zenith) d omega) of each Tregenza patch for an
/// upward sensor: a band between altitudes a1 and a2 holds pi (sin^2 a2 - sin^2 a1), shared
/// by its n patches; the zenith cap from 84 degrees up. Layout: Radiance `reinhart.cal` MF 1.
fn tregenza_projected_solid_angles() -> Vec<f64> {
    let counts = [30, 30, 24, 24, 18, 12, 6];
    let mut out = vec![0.0]; // ground bin
    for (i, n) in counts.iter().enumerate() {
        let (a1, a2) = (
            (12.0 * i as f64).to_radians(),
            (12.0 * (i + 1) as f64).to_radians(),
        );
        let band = PI * (a2.sin().powi(2) - a1.sin().powi(2));
        out.extend(std::iter::repeat_n(band / *n as f64, *n));
    }
    out.push(PI * (1.0 - 84f64.to_radians().sin().powi(2)));
    out
}

#[test]
fn open_sensor_under_uniform_glow_sums_to_pi_within_the_measured_spread() {
    let runs: Vec<_> = (1..=3)
        .map(|r| read_matrix(&format!("oracles/open_sensor_dc_run{r}.mtx")))
        .collect();
    for (nrows, ncols, ncomp, _) in &runs {
        assert_eq!((*nrows, *ncols, *ncomp), (4, 146, 3));
    }
    let at = |run: usize, row: usize, p: usize, c: usize| runs[run].3[(row * 146 + p) * 3 + c];
    // Row sums per run and channel; the tolerance is the measured run-to-run spread of the
    // sums (3 standard errors) plus float32 rounding of 146 terms.
    for row in 0..4 {
        for c in 0..3 {
            let sums: Vec<f64> = (0..3)
                .map(|r| (0..146).map(|p| at(r, row, p, c)).sum())
                .collect();
            let mean = sums.iter().sum::<f64>() / 3.0;
            let sd = (sums.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / 2.0).sqrt();
            let tol = 3.0 * sd / 3f64.sqrt() + 1e-5 * PI;
            assert!(
                (mean - PI).abs() <= tol,
                "row {row} channel {c}: {sums:?} vs pi, tol {tol}"
            );
        }
    }
    // Upward sensor (row 0): ground bin empty, each sky bin = its projected solid angle.
    // A coefficient is a count of equal-weight hemisphere samples, so its noise is a few
    // samples whatever the patch size: the tolerance is 4.5 standard errors of the 3-run
    // mean, the run-to-run variance pooled over each band of patches (zenith with its band).
    let exact = tregenza_projected_solid_angles();
    assert_eq!(exact.len(), 146);
    assert!((exact.iter().sum::<f64>() - PI).abs() < 1e-12);
    let mean_of = |row: usize, p: usize| (0..3).map(|r| at(r, row, p, 0)).sum::<f64>() / 3.0;
    let var_of = |row: usize, p: usize| {
        let m = mean_of(row, p);
        (0..3).map(|r| (at(r, row, p, 0) - m).powi(2)).sum::<f64>() / 2.0
    };
    assert_eq!(mean_of(0, 0), 0.0, "upward sensor sees the ground bin");
    let bands = [
        (1, 31),
        (31, 61),
        (61, 85),
        (85, 109),
        (109, 127),
        (127, 139),
        (139, 146),
    ];
    for (lo, hi) in bands {
        let var = (lo..hi).map(|p| var_of(0, p)).sum::<f64>() / (hi - lo) as f64;
        let tol = 4.5 * (var / 3.0).sqrt() + 1e-6;
        assert!(
            tol < 0.2 * exact[lo],
            "patches {lo}..{hi}: noise too large for an oracle"
        );
        for (p, want) in exact.iter().enumerate().take(hi).skip(lo) {
            let m = mean_of(0, p);
            assert!(
                (m - want).abs() <= tol,
                "patch {p}: {m} vs projected solid angle {want} (tol {tol})"
            );
        }
    }
    // Vertical (south-facing) sensor: half of its cosine-weighted hemisphere is below the
    // horizon, so the ground bin holds pi/2; the downward sensor sees only ground (pi).
    let g1 = mean_of(1, 0);
    let tol = 4.5 * (var_of(1, 0) / 3.0).sqrt() + 2.0 * PI / 1e4;
    assert!((g1 - PI / 2.0).abs() < tol, "vertical ground bin {g1}");
    let g3 = mean_of(3, 0);
    assert!((g3 - PI).abs() < 1e-5 * PI, "downward ground bin {g3}");
}

#[test]
fn furnace_oracles_hold_in_the_radiance_outputs() {
    let near = |file: &str, want: f64| {
        for (i, row) in read_rows(file).iter().enumerate() {
            for v in row {
                assert!(
                    (v - want).abs() <= 1e-4 * want.max(1.0),
                    "{file}:{}: {v} vs {want}",
                    i + 1
                );
            }
        }
    };
    // Glow walls facing in: rtrace and rcontrib both see radiance 1 everywhere.
    near("oracles/furnace_glow_rtrace.txt", PI);
    // Glow walls facing out: glow emits only from its front, so rtrace reads 0 ...
    near("oracles/furnace_glow_out_rtrace.txt", 0.0);
    // ... while rcontrib counts every ray that hits the modifier, front or back.
    for f in [
        "oracles/furnace_glow_rcontrib.txt",
        "oracles/furnace_glow_out_rcontrib.txt",
    ] {
        let (nrows, ncols, _, vals) = read_matrix(f);
        assert_eq!((nrows, ncols), (4, 1), "{f}");
        assert!(vals.iter().all(|v| (v - PI).abs() < 1e-5), "{f}: {vals:?}");
    }
    // Grey (0.5) closed box lit only by the ambient value 1: E = pi * 0.5^ab.
    for ab in 1..=3 {
        near(
            &format!("oracles/furnace_grey_ab{ab}.txt"),
            PI * 0.5f64.powi(ab),
        );
    }
    // Open upward sensor with rtrace: pi.
    let rows = read_rows("oracles/open_sensor_rtrace.txt");
    assert_eq!(rows.len(), 4);
    assert!(
        rows.iter().flatten().all(|v| (v - PI).abs() < 1e-4 * PI),
        "{rows:?}"
    );
}
