//! `rglare annual --views FILE --shard K/N` and `rglare annual --cat` of the shards: the
//! merge has the bytes of the unsharded many-view run for N = 1, 2, 3, 5 and 7 (empty
//! shards beyond 5 views), to standard output or a file; each view's section equals the
//! single-view run of that view; merges of shards that are missing, out of order, cut
//! short, altered or of another run are refused before anything is written, and
//! manifests catch shards of other inputs. Cheap settings (12 x 12 view rays, -ab 1,
//! the 14 hours of `radiance-fixtures/glare/annual/hours.wea`): the test is about bytes,
//! not glare.

use crate::common;

use common::{ours, repo, run, tmpdir};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Five views in every spelling a line may take, with a comment and a blank line.
const VIEWS: &str = "\
-vp 3 1.5 1.2 -vd 0 -1 0
# the desk by the window
-vp 2 2 1.2 -vd 1 0 0

VIEW= -vp 4 3 1.2 -vd 0 1 0
rvu -vp 1 1 1.2 -vd -1 0 0
-vp 3 4 1.2 -vd 0 -1 0
";

fn fixture(p: &str) -> String {
    repo()
        .join("radiance-fixtures")
        .join(p)
        .to_string_lossy()
        .into_owned()
}

/// `rglare annual` with the shared options and view; `extra` first.
fn annual(dir: &Path, extra: &[&str]) -> Command {
    let mut c = ours("rglare");
    c.current_dir(dir).arg("annual").args(extra).args([
        "-w",
        &fixture("glare/annual/hours.wea"),
        "--rays",
        "12",
        "-ab",
        "1",
        "-ad",
        "8",
        "--eye-ad",
        "64",
        "-vta",
        "-vu",
        "0",
        "0",
        "1",
        "-vh",
        "180",
        "-vv",
        "180",
        &fixture("scenes/furnished.rad"),
    ]);
    c
}

fn ok(c: &mut Command) -> Vec<u8> {
    let out = run(c, b"");
    assert!(
        out.status.success(),
        "{c:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// One-line error, status 1, nothing on standard output.
fn refused(c: &mut Command) -> String {
    let out = run(c, b"");
    assert_eq!(out.status.code(), Some(1), "{c:?} should be refused");
    assert!(out.stdout.is_empty(), "nothing written before the checks");
    let e = String::from_utf8(out.stderr).unwrap();
    assert_eq!(e.trim_end().lines().count(), 1, "one-line error: {e}");
    e
}

/// The N shards of the views in `dir` (views.txt there), with manifests.
fn shards(dir: &Path, n: usize) -> (Vec<String>, Vec<String>) {
    let (mut files, mut mans) = (Vec::new(), Vec::new());
    for k in 0..n {
        let f = dir
            .join(format!("g.{k}.txt"))
            .to_string_lossy()
            .into_owned();
        let m = dir
            .join(format!("g.{k}.json"))
            .to_string_lossy()
            .into_owned();
        let shard = format!("{k}/{n}");
        ok(&mut annual(
            dir,
            &[
                "--views",
                "views.txt",
                "--shard",
                &shard,
                "--manifest",
                &m,
                "-o",
                &f,
            ],
        ));
        files.push(f);
        mans.push(m);
    }
    (files, mans)
}

fn cat(files: &[String], manifests: &[String]) -> Command {
    let mut c = ours("rglare");
    c.args(["annual", "--cat"]).args(files);
    if !manifests.is_empty() {
        c.arg("--manifests").args(manifests);
    }
    c
}

fn views_dir(root: &Path, name: &str, views: &str) -> PathBuf {
    let d = root.join(name);
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(d.join("views.txt"), views).unwrap();
    d
}

#[test]
fn merged_view_shards_equal_the_single_run() {
    let tmp = tmpdir();
    let d = views_dir(tmp.path(), "v", VIEWS);
    let single = ok(&mut annual(&d, &["--views", "views.txt"]));
    let text = String::from_utf8(single.clone()).unwrap();
    assert_eq!(text.matches("\n# view ").count() + 1, 5, "five sections");
    for n in [1, 2, 3, 5, 7] {
        let sub = d.join(format!("n{n}"));
        std::fs::create_dir(&sub).unwrap();
        std::fs::copy(d.join("views.txt"), sub.join("views.txt")).unwrap();
        let (files, mans) = shards(&sub, n);
        assert!(
            ok(&mut cat(&files, &mans)) == single,
            "N={n}: merged shards differ from the single run"
        );
    }
    // To a file (written atomically) as well.
    let (files, _) = shards(&d, 3);
    let out = d.join("merged.txt");
    ok(cat(&files, &[]).arg("-o").arg(&out));
    assert!(std::fs::read(&out).unwrap() == single, "-o: merge differs");
    // A view's section is what a run of that view alone prints: the views are independent.
    let alone = ok(&mut annual(
        &d,
        &["-vp", "2", "2", "1.2", "-vd", "1", "0", "0"],
    ));
    let section = text
        .split_inclusive('\n')
        .skip_while(|l| !l.starts_with("# view 1 of 5 (0-based; views.txt line 3)"))
        .skip(1)
        .take_while(|l| !l.starts_with("# view 2 of 5"))
        .collect::<String>();
    assert!(
        section.as_bytes() == alone,
        "view 1's section differs from its own run"
    );
}

#[test]
fn merge_refuses_missing_misordered_cut_altered_and_foreign_shards() {
    let tmp = tmpdir();
    let d = views_dir(tmp.path(), "a", VIEWS);
    let (f, m) = shards(&d, 3);
    let e = refused(&mut cat(&[f[0].clone(), f[2].clone()], &[]));
    assert!(e.contains("missing 1"), "{e}");
    let e = refused(&mut cat(&[f[1].clone(), f[0].clone(), f[2].clone()], &[]));
    assert!(e.contains("comes in position 0"), "{e}");
    // A job killed while writing (no END= line), and a body changed after the fact.
    let text = std::fs::read_to_string(&f[1]).unwrap();
    let cut = d.join("cut.txt").to_string_lossy().into_owned();
    std::fs::write(&cut, &text[..text.len() / 2]).unwrap();
    let e = refused(&mut cat(&[f[0].clone(), cut, f[2].clone()], &[]));
    assert!(
        e.contains("cut.txt") && e.contains("incomplete shard"),
        "{e}"
    );
    let bad = d.join("bad.txt").to_string_lossy().into_owned();
    let last_step = text.rfind("\n12 ").unwrap() + 1;
    let mut altered = text.clone().into_bytes();
    altered[last_step + 8] = if altered[last_step + 8] == b'1' {
        b'2'
    } else {
        b'1'
    };
    std::fs::write(&bad, altered).unwrap();
    let e = refused(&mut cat(&[f[0].clone(), bad, f[2].clone()], &[]));
    assert!(e.contains("bad.txt") && e.contains("corrupt shard"), "{e}");
    // Not a shard; a shard of another run (seed 5).
    let plain = d.join("plain.txt").to_string_lossy().into_owned();
    std::fs::write(&plain, ok(&mut annual(&d, &["--views", "views.txt"]))).unwrap();
    let e = refused(&mut cat(&[plain], &[]));
    assert!(e.contains("not a shard"), "{e}");
    let other = d.join("other.txt").to_string_lossy().into_owned();
    ok(&mut annual(
        &d,
        &[
            "--views",
            "views.txt",
            "--shard",
            "1/3",
            "-o",
            &other,
            "-s",
            "5",
        ],
    ));
    let e = refused(&mut cat(&[f[0].clone(), other, f[2].clone()], &[]));
    assert!(e.contains("different runs"), "{e}");
    // Another views.txt under the same name: the commands agree, only manifests tell.
    let moved = VIEWS.replace("-vp 4 3 1.2", "-vp 4 3.5 1.2");
    let d2 = views_dir(tmp.path(), "b", &moved);
    let (f2, m2) = shards(&d2, 3);
    let files = [f[0].clone(), f2[1].clone(), f[2].clone()];
    ok(&mut cat(&files, &[]));
    let e = refused(&mut cat(
        &files,
        &[m[0].clone(), m2[1].clone(), m[2].clone()],
    ));
    assert!(
        e.contains("different inputs") && e.contains("views.txt"),
        "{e}"
    );
    let e = refused(&mut cat(&f, &[m[0].clone(), m[2].clone(), m[1].clone()]));
    assert!(
        e.contains("g.2.json is shard 2/3 but comes in position 1"),
        "{e}"
    );
}

#[test]
fn views_and_shard_options_are_checked() {
    let tmp = tmpdir();
    let d = views_dir(
        tmp.path(),
        "a",
        "-vp 3 1.5 1.2 -vd 0 -1 0\n-vp 3 1.5 -vd 0 1 0\n",
    );
    let e = refused(&mut annual(&d, &["--views", "views.txt"]));
    assert!(e.starts_with("rglare: views.txt:2:"), "{e}");
    let d = views_dir(tmp.path(), "b", "# nothing\n\n");
    let e = refused(&mut annual(&d, &["--views", "views.txt"]));
    assert!(e.contains("no views"), "{e}");
    let e = refused(&mut annual(&d, &["--manifest", "m.json"]));
    assert!(e.contains("needs --shard"), "{e}");
    let e = refused(&mut annual(&d, &["--views", "views.txt", "--shard", "3/3"]));
    assert!(e.contains("0 <= K < N"), "{e}");
}
