//! `rdc --shard K/N` and `rmtx --cat` of the shards: the merge has the bytes of the
//! unsharded run (header included, with `SOURCE_DATE_EPOCH` fixing the dates), for ascii
//! and float output, streamed (`-y`) or not, sensors or per-pixel coefficients; merges of
//! shards that do not belong together are refused, and manifests catch different inputs.

use crate::common;

use common::{ours, repo, run, run_ok, tmpdir};
use std::path::Path;

const EPOCH: &str = "1700000000";

fn room(f: &str) -> String {
    repo()
        .join("examples/room")
        .join(f)
        .to_string_lossy()
        .into_owned()
}

/// 7 sensors of the example room: uneven splits for N = 2, 3, 5 and empty shards beyond 7.
fn sensors() -> Vec<u8> {
    let all = std::fs::read_to_string(room("sensors.pts")).unwrap();
    all.lines()
        .step_by(23)
        .take(7)
        .map(|l| format!("{l}\n"))
        .collect::<String>()
        .into_bytes()
}

fn rdc(args: &[&str], stdin: &[u8]) -> Vec<u8> {
    let mut c = ours("rdc");
    c.env("SOURCE_DATE_EPOCH", EPOCH)
        .args(["-ab", "1", "-ad", "16", "-n", "1"])
        .args(args)
        .args([room("room.rad"), room("skydome.rad")]);
    run_ok(&mut c, stdin)
}

/// Run the N shards into `dir`, returning their paths (and manifests' paths).
fn shards(dir: &Path, n: usize, args: &[&str], stdin: &[u8]) -> (Vec<String>, Vec<String>) {
    let (mut mtx, mut man) = (Vec::new(), Vec::new());
    for k in 0..n {
        let m = dir
            .join(format!("m{k}.json"))
            .to_string_lossy()
            .into_owned();
        let shard = format!("{k}/{n}");
        let mut a = args.to_vec();
        a.extend(["--shard", &shard, "--manifest", &m]);
        let p = dir.join(format!("p{k}.mtx"));
        std::fs::write(&p, rdc(&a, stdin)).unwrap();
        mtx.push(p.to_string_lossy().into_owned());
        man.push(m);
    }
    (mtx, man)
}

fn cat(files: &[String], manifests: &[String]) -> std::process::Output {
    let mut c = ours("rmtx");
    c.arg("--cat").args(files);
    if !manifests.is_empty() {
        c.arg("--manifests").args(manifests);
    }
    run(&mut c, b"")
}

fn merged(files: &[String], manifests: &[String]) -> Vec<u8> {
    let out = cat(files, manifests);
    assert!(
        out.status.success(),
        "rmtx --cat: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

fn refused(files: &[String], manifests: &[String]) -> String {
    let out = cat(files, manifests);
    assert_eq!(out.status.code(), Some(1), "merge should be refused");
    assert!(out.stdout.is_empty(), "nothing written before the checks");
    let e = String::from_utf8(out.stderr).unwrap();
    assert_eq!(e.trim_end().lines().count(), 1, "one-line error: {e}");
    e
}

#[test]
fn merged_shards_equal_the_single_run_ascii_and_float() {
    let pts = sensors();
    let dir = tmpdir();
    for fmt in ["-faa", "-faf"] {
        let args = ["-I", fmt, "-m", "1", "-s", "7"];
        let single = rdc(&args, &pts);
        for n in [1, 2, 3, 5, 9] {
            let d = dir.path().join(format!("{fmt}{n}"));
            std::fs::create_dir(&d).unwrap();
            let (mtx, man) = shards(&d, n, &args, &pts);
            assert!(
                merged(&mtx, &man) == single,
                "{fmt} N={n}: merged shards differ from the single run"
            );
        }
    }
}

#[test]
fn streamed_sensors_and_pixel_rows_shard_too() {
    let pts = sensors();
    let dir = tmpdir();
    // -y: sensors stream; every shard still reads (and counts) all of them.
    let args = ["-I", "-faf", "-m", "1", "-y", "7"];
    let single = rdc(&args, &pts);
    let (mtx, man) = shards(dir.path(), 3, &args, &pts);
    assert!(merged(&mtx, &man) == single, "-y: merge differs");
    let bad = run(
        ours("rdc")
            .args(["-I", "-m", "1", "-ad", "4", "-y", "6", "--shard", "0/3"])
            .args([room("room.rad")]),
        &pts,
    );
    assert_eq!(
        bad.status.code(),
        Some(1),
        "-y 6 with 7 sensors must fail in a shard too"
    );
    // Per-pixel coefficients: shards of whole scanlines (5 lines in 3 shards: 2, 2, 1).
    let d = dir.path().join("pic");
    std::fs::create_dir(&d).unwrap();
    let view = [
        "-faf", "-m", "1", "-vtv", "-vp", "3", "2", "1.2", "-vd", "0", "1", "0", "-vh", "60",
        "-vv", "45", "-x", "4", "-y", "5",
    ];
    let single = rdc(&view, b"");
    let (mtx, man) = shards(&d, 3, &view, b"");
    assert!(merged(&mtx, &man) == single, "pixel rows: merge differs");
}

#[test]
fn shard_option_is_validated() {
    for bad in ["3/3", "0/0", "1", "0/100001", "x/2"] {
        let out = run(
            ours("rdc").args(["-I", "-m", "1", "--shard", bad, &room("room.rad")]),
            b"",
        );
        assert_eq!(out.status.code(), Some(1), "--shard {bad}");
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(e.contains("0 <= K < N <= 100000"), "--shard {bad}: {e}");
    }
    // Pictures (no -m/--suns) cannot be merged, nor RGBE rows.
    let pic = run(
        ours("rdc").args([
            "-vtv",
            "-x",
            "4",
            "-y",
            "4",
            "--shard",
            "0/2",
            &room("room.rad"),
        ]),
        b"",
    );
    assert_eq!(pic.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&pic.stderr).contains("pictures cannot be merged"));
    let rgbe = run(
        ours("rdc").args(["-I", "-m", "1", "-fac", "--shard", "0/2", &room("room.rad")]),
        b"",
    );
    assert_eq!(rgbe.status.code(), Some(1));
    let out = run(
        ours("rdc").args(["-I", "-m", "1", "--manifest", "m.json", &room("room.rad")]),
        b"",
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("needs --shard"));
}

#[test]
fn merge_refuses_shards_that_do_not_belong_together() {
    let pts = sensors();
    let dir = tmpdir();
    let args = ["-I", "-faf", "-m", "1"];
    let (mtx, _) = shards(dir.path(), 3, &args, &pts);
    // Out of order, missing, repeated.
    let e = refused(&[mtx[1].clone(), mtx[0].clone(), mtx[2].clone()], &[]);
    assert!(e.contains("is shard 1/3 but comes in position 0"), "{e}");
    let e = refused(&[mtx[0].clone(), mtx[2].clone()], &[]);
    assert!(e.contains("missing 1"), "{e}");
    // A shard of another shape (MF 2: 578 columns).
    let other = dir.path().join("other");
    std::fs::create_dir(&other).unwrap();
    let (mf2, _) = shards(&other, 3, &["-I", "-faf", "-m", "2"], &pts);
    let e = refused(&[mtx[0].clone(), mf2[1].clone(), mtx[2].clone()], &[]);
    assert!(e.contains("146") && e.contains("578"), "{e}");
    // Same shape, another seed: another run.
    let seed = dir.path().join("seed");
    std::fs::create_dir(&seed).unwrap();
    let (s9, _) = shards(&seed, 3, &["-I", "-faf", "-m", "1", "-s", "9"], &pts);
    let e = refused(&[mtx[0].clone(), s9[1].clone(), mtx[2].clone()], &[]);
    assert!(e.contains("different runs"), "{e}");
    // A shard mixed with an ordinary matrix.
    let plain = dir.path().join("plain.mtx");
    std::fs::write(&plain, rdc(&args, &pts)).unwrap();
    let e = refused(&[mtx[0].clone(), plain.to_string_lossy().into_owned()], &[]);
    assert!(e.contains("no SHARD= line"), "{e}");
    // A truncated shard.
    let cut = dir.path().join("cut.mtx");
    let bytes = std::fs::read(&mtx[1]).unwrap();
    std::fs::write(&cut, &bytes[..bytes.len() - 4]).unwrap();
    let cut = cut.to_string_lossy().into_owned();
    let e = refused(&[mtx[0].clone(), cut, mtx[2].clone()], &[]);
    assert!(e.contains("cut.mtx"), "a truncated shard is named: {e}");
}

/// What a resume relies on: `rmtx --verify` tells complete shards from missing, cut and
/// altered ones (one line each, status 1 naming the bad ones), and the merge with
/// manifests stops naming a missing shard or one whose bytes differ from what its job
/// wrote (same size: only the manifest's output hash can tell).
#[test]
fn verify_and_merge_name_missing_cut_and_altered_shards() {
    let pts = sensors();
    let dir = tmpdir();
    let args = ["-I", "-faf", "-m", "1"];
    let (mtx, man) = shards(dir.path(), 4, &args, &pts);
    let verify = |files: &[String]| {
        run(
            ours("rmtx")
                .arg("--verify")
                .args(files)
                .arg("--manifests")
                .args(&man),
            b"",
        )
    };
    let ok = verify(&mtx);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let lines = String::from_utf8(ok.stdout).unwrap();
    assert_eq!(lines.matches(": complete (shard ").count(), 4, "{lines}");
    // Shard 1 gone, shard 2 cut short, shard 3 with one bit flipped.
    std::fs::remove_file(&mtx[1]).unwrap();
    let bytes = std::fs::read(&mtx[2]).unwrap();
    std::fs::write(&mtx[2], &bytes[..bytes.len() - 8]).unwrap();
    let mut flipped = std::fs::read(&mtx[3]).unwrap();
    let n = flipped.len();
    flipped[n - 3] ^= 0x10;
    std::fs::write(&mtx[3], &flipped).unwrap();
    let bad = verify(&mtx);
    assert_eq!(bad.status.code(), Some(1));
    let lines = String::from_utf8(bad.stdout).unwrap();
    let per: Vec<&str> = lines.lines().collect();
    assert_eq!(per.len(), 4, "{lines}");
    assert!(
        per[0].ends_with("(shard 0/4, rows 0..2 of 7)"),
        "{}",
        per[0]
    );
    assert!(per[1].contains("No such file"), "{}", per[1]);
    assert!(
        per[2].contains("truncated") || per[2].contains("ends"),
        "{}",
        per[2]
    );
    assert!(
        per[3].contains("a corrupt or stale shard; run shard 3/4 again"),
        "{}",
        per[3]
    );
    let e = String::from_utf8(bad.stderr).unwrap();
    assert!(
        e.contains("3 of 4 shards missing, incomplete or corrupt")
            && e.contains(&mtx[1])
            && e.contains(&mtx[3]),
        "{e}"
    );
    let e = refused(&mtx, &man);
    assert!(e.contains(&mtx[1]), "the missing shard is named: {e}");
    let e = refused(&[mtx[0].clone(), mtx[1].clone(), mtx[3].clone()], &[]);
    assert!(e.contains(&mtx[1]), "{e}");
    // Shards 0..2 as written, shard 3 altered: only its manifest's hash tells.
    let again = dir.path().join("again");
    std::fs::create_dir(&again).unwrap();
    let (good, _) = shards(&again, 4, &args, &pts);
    let files = [
        good[0].clone(),
        good[1].clone(),
        good[2].clone(),
        mtx[3].clone(),
    ];
    assert!(cat(&files, &[]).status.success(), "the header cannot tell");
    let e = refused(&files, &man);
    assert!(
        e.contains(&mtx[3]) && e.contains("corrupt"),
        "the altered shard is named: {e}"
    );
}

#[test]
fn manifests_catch_other_inputs_versions_and_missing_shards() {
    let pts = sensors();
    let dir = tmpdir();
    let args = ["-I", "-faa", "-m", "1"];
    let (mtx, man) = shards(dir.path(), 3, &args, &pts);
    // Shard 2 computed from moved sensors: the headers agree, only the manifests tell.
    let other = dir.path().join("other");
    std::fs::create_dir(&other).unwrap();
    let moved = String::from_utf8(pts.clone())
        .unwrap()
        .replacen(' ', "1 ", 1)
        .into_bytes();
    let (mtx2, man2) = shards(&other, 3, &args, &moved);
    let files = [mtx[0].clone(), mtx[1].clone(), mtx2[2].clone()];
    assert!(
        cat(&files, &[]).status.success(),
        "headers alone cannot tell"
    );
    let e = refused(&files, &[man[0].clone(), man[1].clone(), man2[2].clone()]);
    assert!(
        e.contains("different inputs") && e.contains("<stdin>"),
        "{e}"
    );
    // Missing shard indices are named.
    let e = refused(&mtx, &[man[0].clone(), man[2].clone()]);
    assert!(e.contains("missing 1"), "{e}");
    // Another tool version.
    let v = dir.path().join("v.json");
    let text = std::fs::read_to_string(&man[1]).unwrap();
    let bumped = text.replace(env!("CARGO_PKG_VERSION"), "0.0.0-other");
    assert_ne!(text, bumped);
    std::fs::write(&v, bumped).unwrap();
    let v = v.to_string_lossy().into_owned();
    let e = refused(&mtx, &[man[0].clone(), v, man[2].clone()]);
    assert!(e.contains("version"), "{e}");
    // Manifest of the wrong shard for a file.
    let e = refused(&mtx, &[man[0].clone(), man[1].clone(), man[1].clone()]);
    assert!(
        e.contains("given twice 1") && e.contains("missing 2"),
        "{e}"
    );
    // And the matching set merges.
    assert!(merged(&mtx, &man) == rdc(&args, &pts));
}
