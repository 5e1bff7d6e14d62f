//! `rmtx --hours A:B|K/N` time chunks of a matrix product and `rmtx --cat-columns` of the
//! chunks: the merge has the bytes of the whole product (header included) for float,
//! ascii and double output, to a pipe or a file; merges of chunks that do not tile the
//! hours or do not belong together are refused before anything is written, and manifests
//! catch chunks of other inputs. The coefficients are real rcontrib output
//! (`radiance-fixtures/dc/office_m1.mtx`, 165 x 146 x RGB float), the sky 48 hours of
//! London (`tests/data/weather/london_2days.epw`).

use crate::common;

use common::{ours, repo, run, run_ok, tmpdir};
use rdaylight::formats::matrix::{Matrix, ReadOptions};
use std::path::{Path, PathBuf};

fn dc() -> String {
    path(&repo().join("radiance-fixtures/dc/office_m1.mtx"))
}

fn path(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

/// The 48-hour sky matrix (146 x 48 x 3 float) in `dir`.
fn sky(dir: &Path) -> String {
    let epw = repo().join("tests/data/weather/london_2days.epw");
    let out = run_ok(ours("rspecsky").args(["-m", "1", "-of", &path(&epw)]), b"");
    let p = dir.join("sky.smx");
    std::fs::write(&p, out).unwrap();
    path(&p)
}

fn rmtx(args: &[&str]) -> Vec<u8> {
    run_ok(ours("rmtx").args(args), b"")
}

/// `rmtx args` with standard output a file (seekable: FORMAT= is padded as for the whole
/// product written to a file).
fn rmtx_to_file(args: &[&str], out: &Path) {
    let f = std::fs::File::create(out).unwrap();
    let status = ours("rmtx").args(args).stdout(f).status().unwrap();
    assert!(status.success(), "rmtx {args:?}");
}

/// Chunks `spans` of `rmtx args`, written into `dir`; their paths and manifests.
fn chunks(dir: &Path, args: &[&str], spans: &[&str]) -> (Vec<String>, Vec<String>) {
    let (mut files, mut mans) = (Vec::new(), Vec::new());
    for (i, s) in spans.iter().enumerate() {
        let f = dir.join(format!("c{i}.mtx"));
        let m = path(&dir.join(format!("c{i}.json")));
        let mut a = vec!["--hours", s, "--manifest", &m];
        a.extend(args);
        std::fs::write(&f, rmtx(&a)).unwrap();
        files.push(path(&f));
        mans.push(m);
    }
    (files, mans)
}

fn cat(files: &[String], manifests: &[String]) -> std::process::Output {
    let mut c = ours("rmtx");
    c.arg("--cat-columns").args(files);
    if !manifests.is_empty() {
        c.arg("--manifests").args(manifests);
    }
    run(&mut c, b"")
}

fn merged(files: &[String], manifests: &[String]) -> Vec<u8> {
    let out = cat(files, manifests);
    assert!(
        out.status.success(),
        "rmtx --cat-columns: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// A refused merge: status 1, one line naming the problem, nothing on standard output.
fn refused(files: &[String], manifests: &[String]) -> String {
    let out = cat(files, manifests);
    assert_eq!(out.status.code(), Some(1), "merge should be refused");
    assert!(out.stdout.is_empty(), "nothing written before the checks");
    let e = String::from_utf8(out.stderr).unwrap();
    assert_eq!(e.trim_end().lines().count(), 1, "one-line error: {e}");
    e
}

fn dir_in(root: &Path, name: &str) -> PathBuf {
    let d = root.join(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn chunks_merge_into_the_whole_product() {
    let tmp = tmpdir();
    let sky = sky(tmp.path());
    let dc = dc();
    // Lux in float (the annual pipeline), RGB in ascii, RGB in double; uneven explicit
    // spans and K/N blocks (48 hours in 5 blocks: 10, 10, 10, 9, 9; in 48: one hour each).
    let products: [&[&str]; 3] = [
        &["-ff", "-c", "47.4", "119.9", "11.6"],
        &["-fa"],
        &["-fd", "-s", "0.5"],
    ];
    let splits: [Vec<String>; 4] = [
        vec!["0:48".into()],
        vec!["0:17".into(), "17:30".into(), "30:48".into()],
        (0..5).map(|k| format!("{k}/5")).collect(),
        (0..48).map(|k| format!("{k}/48")).collect(),
    ];
    for (p, opts) in products.iter().enumerate() {
        let mut args = opts.to_vec();
        args.extend([dc.as_str(), sky.as_str()]);
        let whole = rmtx(&args);
        for (s, spans) in splits.iter().enumerate() {
            if p > 0 && s == 3 {
                continue; // one-hour chunks once is enough
            }
            let d = dir_in(tmp.path(), &format!("p{p}s{s}"));
            let spans: Vec<&str> = spans.iter().map(String::as_str).collect();
            let (files, mans) = chunks(&d, &args, &spans);
            assert!(
                merged(&files, &mans) == whole,
                "{opts:?} in {} chunks: merge differs from the whole product",
                spans.len()
            );
        }
    }
    // Written to files, binary data starts aligned (FORMAT= padded): the same bytes again.
    let d = dir_in(tmp.path(), "files");
    let args = ["-ff", dc.as_str(), sky.as_str()];
    rmtx_to_file(&args, &d.join("whole.mtx"));
    let mut files = Vec::new();
    for (k, s) in ["0:20", "20:48"].iter().enumerate() {
        let f = d.join(format!("c{k}.mtx"));
        rmtx_to_file(&[&["--hours", s][..], &args].concat(), &f);
        files.push(path(&f));
    }
    let mut cmd = vec!["--cat-columns"];
    cmd.extend(files.iter().map(String::as_str));
    rmtx_to_file(&cmd, &d.join("merged.mtx"));
    let whole = std::fs::read(d.join("whole.mtx")).unwrap();
    assert!(
        std::fs::read(d.join("merged.mtx")).unwrap() == whole,
        "file output: merge differs"
    );
    let data = whole.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
    assert_eq!(
        data % 4,
        0,
        "a file's float data starts at a multiple of 4 bytes"
    );
}

#[test]
fn hours_of_one_matrix_are_its_columns() {
    let tmp = tmpdir();
    let sky = sky(tmp.path());
    let chunk = rmtx(&["-fd", "--hours", "5:9", &sky]);
    let got = Matrix::from_reader(&chunk[..], "chunk", &ReadOptions::default()).unwrap();
    let (all, _) = Matrix::load(&sky, &ReadOptions::default()).unwrap();
    assert_eq!((got.nrows, got.ncols), (146, 4));
    for r in 0..146 {
        for c in 0..4 {
            assert_eq!(got.get(r, c), all.get(r, c + 5), "row {r} hour {}", c + 5);
        }
    }
    let header = String::from_utf8_lossy(&chunk[..400]).into_owned();
    assert!(header.contains("\nHOURS= 5:9 48\n"), "{header}");
    // The header's command is the whole product's: --hours is not in it.
    assert!(!header.contains("--hours"), "{header}");
}

#[test]
fn plain_matrices_join_side_by_side() {
    let tmp = tmpdir();
    let sky = sky(tmp.path());
    let out = rmtx(&["--cat-columns", &sky, &sky]);
    let m = Matrix::from_reader(&out[..], "out", &ReadOptions::default()).unwrap();
    let (s, _) = Matrix::load(&sky, &ReadOptions::default()).unwrap();
    assert_eq!((m.nrows, m.ncols), (146, 96));
    for r in 0..146 {
        assert_eq!(&m.row(r)[..144], s.row(r));
        assert_eq!(&m.row(r)[144..], s.row(r));
    }
    let e = run(ours("rmtx").args(["--cat-columns", &sky, &dc()]), b"");
    assert_eq!(e.status.code(), Some(1));
    let e = String::from_utf8_lossy(&e.stderr);
    assert!(e.contains("NROWS and NCOMP must agree"), "{e}");
}

#[test]
fn merge_refuses_chunks_that_do_not_tile_or_belong() {
    let tmp = tmpdir();
    let sky = sky(tmp.path());
    let dc = dc();
    let d = dir_in(tmp.path(), "a");
    let args = ["-ff", dc.as_str(), sky.as_str()];
    let (c, m) = chunks(&d, &args, &["0:17", "17:30", "30:48"]);
    let e = refused(&[c[0].clone(), c[2].clone()], &[]);
    assert!(e.contains("hours 17:30 of 48 missing after"), "{e}");
    let e = refused(&[c[0].clone(), c[1].clone()], &[]);
    assert!(e.contains("hours 30:48 of 48 missing after"), "{e}");
    let e = refused(&[c[0].clone(), c[2].clone(), c[1].clone()], &[]);
    assert!(
        e.contains("comes after") && e.contains("in order of hours"),
        "{e}"
    );
    let e = refused(
        &[c[0].clone(), c[1].clone(), c[1].clone(), c[2].clone()],
        &[],
    );
    assert!(e.contains("overlaps"), "{e}");
    // A chunk of another product (ascii) or a plain matrix among chunks.
    let o = dir_in(tmp.path(), "o");
    let (oa, _) = chunks(&o, &["-fa", dc.as_str(), sky.as_str()], &["17:30"]);
    let e = refused(&[c[0].clone(), oa[0].clone(), c[2].clone()], &[]);
    assert!(e.contains("different products"), "{e}");
    let e = refused(&[c[0].clone(), sky.clone()], &[]);
    assert!(e.contains("no HOURS= line"), "{e}");
    // Truncated chunks, binary and ascii.
    let cut = path(&d.join("cut.mtx"));
    let bytes = std::fs::read(&c[1]).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() - 4]).unwrap();
    let e = refused(&[c[0].clone(), cut.clone(), c[2].clone()], &[]);
    assert!(e.contains("cut.mtx") && e.contains("truncated"), "{e}");
    let (ac, _) = chunks(&o, &["-fa", dc.as_str(), sky.as_str()], &["0:17", "17:48"]);
    let text = std::fs::read(&ac[1]).unwrap();
    std::fs::write(&cut, &text[..text.len() - 100]).unwrap();
    let e = refused(&[ac[0].clone(), cut], &[]);
    assert!(e.contains("an incomplete chunk?"), "{e}");
    // No conversion while merging.
    let out = run(
        ours("rmtx").args(["-c", "Y", "--cat-columns"]).args(&c),
        b"",
    );
    assert_eq!(out.status.code(), Some(1));
    // Manifests: one per chunk, in order; chunks of another coefficient file are caught
    // even though their headers (same command line) agree.
    let e = refused(&c, &[m[0].clone(), m[1].clone()]);
    assert!(e.contains("2 manifests for 3 chunks"), "{e}");
    let e = refused(&c, &[m[0].clone(), m[2].clone(), m[1].clone()]);
    assert!(e.contains("not that chunk"), "{e}");
    let other_dc = d.join("other");
    std::fs::create_dir(&other_dc).unwrap();
    let moved = other_dc.join("office_m1.mtx");
    let mut bytes = std::fs::read(&dc).unwrap();
    let n = bytes.len();
    bytes[n - 1] ^= 1;
    std::fs::write(&moved, &bytes).unwrap();
    // Same command line (relative names), another dc.mtx: only the manifests tell.
    let rel = |dir: &Path, spans: &[&str]| -> (Vec<String>, Vec<String>) {
        std::fs::copy(&sky, dir.join("sky.smx")).unwrap();
        if !dir.join("office_m1.mtx").exists() {
            std::fs::copy(&dc, dir.join("office_m1.mtx")).unwrap();
        }
        let (mut f, mut ms) = (Vec::new(), Vec::new());
        for (i, s) in spans.iter().enumerate() {
            let man = format!("r{i}.json");
            let out = run_ok(
                ours("rmtx")
                    .current_dir(dir)
                    .args(["-ff", "--hours", s, "--manifest", &man])
                    .args(["office_m1.mtx", "sky.smx"]),
                b"",
            );
            let p = dir.join(format!("r{i}.mtx"));
            std::fs::write(&p, out).unwrap();
            f.push(path(&p));
            ms.push(path(&dir.join(man)));
        }
        (f, ms)
    };
    let (f1, m1) = rel(&dir_in(tmp.path(), "rel"), &["0:24", "24:48"]);
    let (f2, m2) = rel(&other_dc, &["0:24", "24:48"]);
    let files = [f1[0].clone(), f2[1].clone()];
    assert!(
        cat(&files, &[]).status.success(),
        "headers alone cannot tell"
    );
    let e = refused(&files, &[m1[0].clone(), m2[1].clone()]);
    assert!(
        e.contains("different inputs") && e.contains("office_m1.mtx"),
        "{e}"
    );
}

#[test]
fn hours_option_is_validated() {
    let tmp = tmpdir();
    let sky = sky(tmp.path());
    let dc = dc();
    let fails = |args: &[&str], want: &str| {
        let out = run(ours("rmtx").args(args), b"");
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}: nothing written");
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(e.contains(want), "{args:?}: {e}");
    };
    fails(
        &["--hours", "40:49", &dc, &sky],
        "sky.smx has 48 columns (hours 0:48)",
    );
    for bad in ["5:5", "9:5", "x:4", "7", "5/5"] {
        fails(&["--hours", bad, &dc, &sky], "--hours");
    }
    fails(&["--hours", "0:9", "-t", &dc, &sky], "transpose the merged");
    fails(&["--manifest", "m.json", &dc, &sky], "needs --hours");
    fails(&["--hours", "0:9", "--cat", &dc, &dc], "not both");
    fails(&["--cat", "--cat-columns", &dc, &dc], "give one of them");
}
