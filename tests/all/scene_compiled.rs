//! Compiled scenes (`rdc --compile`, issue 18). Round trips: tracing a compiled scene gives
//! the very bytes of tracing its sources (polygons and every analytic shape, a spectral
//! pattern, the sun and a `skybright.cal` sky, a BSDF window, an `.obj` mesh and, with real
//! Radiance's `oconv`, an instanced octree). Staleness: a run refuses a compiled scene
//! whose sources changed since (one line naming the file), and accepts one only touched.
//! Damage: every prefix and every flipped byte of a compiled scene is an error, never a
//! panic; through `rdc` one line, status 1 and nothing on standard output.
//! `--scene-cache`: a run reuses the kept compiled scene (not rewritten) while its sources
//! are unchanged, and compiles again (other bytes) when one of them changed.

use std::path::Path;
use std::process::Output;

use crate::common::{self, have_radiance, ours, radiance, run, run_ok, tmpdir};
use rdaylight::trace::compiled;

const SENSORS: &str = "1 1 .8 0 0 1\n2 2.5 .8 0 0 1\n3 4 1.5 0 -1 0\n2 1 2.9 0 0 -1\n";

/// Shapes of every kind, a spectral pattern on one material, under a sun and a gensky sky.
const SHAPES: &str = "void spectrum warm 0 0 5 400 700 .4 .6 .8\n\
    warm plastic wall 0 0 5 .6 .6 .6 0 0\n\
    void metal steel 0 0 5 .7 .7 .7 .9 .05\n\
    void glass pane 0 0 3 .86 .86 .86\n\
    wall polygon floor 0 0 12 0 0 0 4 0 0 4 5 0 0 5 0\n\
    wall polygon ceiling 0 0 12 0 0 3 0 5 3 4 5 3 4 0 3\n\
    wall polygon west 0 0 12 0 0 0 0 5 0 0 5 3 0 0 3\n\
    wall polygon east 0 0 12 4 0 0 4 0 3 4 5 3 4 5 0\n\
    wall polygon north 0 0 12 0 5 0 4 5 0 4 5 3 0 5 3\n\
    pane polygon south 0 0 12 0 0 0 0 0 3 4 0 3 4 0 0\n\
    steel sphere ball 0 0 4 2 2 1 .3\n\
    steel bubble hollow 0 0 4 3 3 2 .2\n\
    wall cone lamp 0 0 8 1 4 2 1 4 2.5 .3 .1\n\
    wall cup bowl 0 0 8 3 1 .5 3 1 .8 .2 .25\n\
    wall cylinder post 0 0 7 3.5 4.5 0 3.5 4.5 2 .05\n\
    wall tube pipe 0 0 7 .5 .5 2.5 3.5 .5 2.5 .03\n\
    wall ring disc 0 0 8 2 2.5 .01 0 0 1 .1 .4\n\
    void light sun_mat 0 0 3 6e6 6e6 6e6\n\
    sun_mat source sun 0 0 4 .3 -.8 .5 .533\n\
    void brightfunc skyfunc 2 skybr skybright.cal 0 7 1 3.1 .27 .3 -.8 .5 .3\n\
    skyfunc glow sky_glow 0 0 4 .9 .9 1.1 0\n\
    sky_glow source sky 0 0 4 0 0 1 180\n\
    void glow ground_glow 0 0 4 1.4 .9 .6 0\n\
    ground_glow source ground 0 0 4 0 0 -1 180\n";

fn rdc(dir: &Path, args: &[&str], stdin: &[u8]) -> Output {
    run(ours("rdc").current_dir(dir).args(args), stdin)
}

fn rdc_ok(dir: &Path, args: &[&str]) -> Vec<u8> {
    run_ok(ours("rdc").current_dir(dir).args(args), SENSORS.as_bytes())
}

/// One error line, status 1, nothing on standard output; the line.
fn one_line_error(out: &Output) -> String {
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(out.stdout.is_empty(), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    err
}

/// `rdc OPTS scene...` and `rdc OPTS scene.rdb` after `rdc --compile scene.rdb scene...`
/// give the same bytes (and they are not empty).
fn same_bytes(dir: &Path, opts: &[&str], scene: &[&str]) {
    let direct = rdc_ok(dir, &[opts, scene].concat());
    let mut compile = vec!["--compile", "scene.rdb"];
    compile.extend(scene);
    run_ok(ours("rdc").current_dir(dir).args(&compile), b"");
    let from_file = rdc_ok(dir, &[opts, &["scene.rdb"]].concat());
    assert!(!direct.is_empty());
    assert_eq!(
        String::from_utf8_lossy(&from_file),
        String::from_utf8_lossy(&direct),
        "{scene:?} {opts:?}"
    );
}

#[test]
fn compiled_scenes_trace_the_bytes_of_their_sources() {
    let t = tmpdir();
    let d = t.path();
    // Shapes of every kind, a spectral pattern, sun and sky: values, and coefficients.
    std::fs::write(d.join("shapes.rad"), SHAPES).unwrap();
    same_bytes(d, &["-h", "-I", "-ab", "2", "-ad", "64"], &["shapes.rad"]);
    same_bytes(
        d,
        &["-h", "-I", "-ab", "2", "-ad", "64", "-m", "1"],
        &["shapes.rad"],
    );
    same_bytes(d, &["-h", "-ab", "1", "-ad", "16"], &["shapes.rad"]);
    // The example room, its sky coefficients as the main job computes them.
    let room = common::repo().join("examples/room/room.rad");
    std::fs::copy(room, d.join("room.rad")).unwrap();
    same_bytes(
        d,
        &["-h", "-I", "-ab", "3", "-ad", "128", "-m", "1"],
        &["room.rad"],
    );
    // A BSDF window (its XML is read again by each run).
    let bsdf = common::repo().join("tests/data/bsdf");
    let text = std::fs::read_to_string(bsdf.join("room.rad")).unwrap();
    std::fs::write(
        d.join("bsdf.rad"),
        text.replace("WINDOW_XML", "blinds45.xml"),
    )
    .unwrap();
    std::fs::copy(bsdf.join("blinds45.xml"), d.join("blinds45.xml")).unwrap();
    same_bytes(d, &["-h", "-I", "-ab", "2", "-ad", "128"], &["bsdf.rad"]);
    // An .obj mesh with its own materials, placed twice (one shared BVH).
    let mesh = common::repo().join("tests/data/mesh");
    for f in ["table.obj", "table.mat"] {
        std::fs::copy(mesh.join(f), d.join(f)).unwrap();
    }
    std::fs::write(
        d.join("tables.rad"),
        "void mesh t1 5 table.obj -t 1 1 0 0 0\nvoid mesh t2 7 table.obj -rz 30 -t 2.5 3 0 0 0\n",
    )
    .unwrap();
    same_bytes(
        d,
        &["-h", "-I", "-ab", "2", "-ad", "64"],
        &["shapes.rad", "table.mat", "tables.rad"],
    );
}

#[test]
fn instanced_octrees_compile_and_their_changes_are_seen() {
    if !have_radiance("instanced_octrees_compile_and_their_changes_are_seen") {
        return;
    }
    let t = tmpdir();
    let d = t.path();
    std::fs::write(d.join("shapes.rad"), SHAPES).unwrap();
    let boxes = |size: &str| {
        let made = run_ok(
            radiance("genbox")
                .current_dir(d)
                .args(["steel", "crate", size, size, size]),
            b"",
        );
        let mut text = b"void metal steel 0 0 5 .7 .7 .7 .9 .05\n".to_vec();
        text.extend(made);
        std::fs::write(d.join("crate.rad"), text).unwrap();
        let oct = run_ok(
            radiance("oconv").current_dir(d).args(["-f", "crate.rad"]),
            b"",
        );
        std::fs::write(d.join("crate.oct"), oct).unwrap();
    };
    boxes(".3");
    std::fs::write(
        d.join("crates.rad"),
        "void instance c1 5 crate.oct -t 1 3 0 0 0\nvoid instance c2 7 crate.oct -rz 20 -t 2.5 1.5 0 0 0\n",
    )
    .unwrap();
    let opts = ["-h", "-I", "-ab", "2", "-ad", "64"];
    same_bytes(d, &opts, &["shapes.rad", "crates.rad"]);
    // The octree changes: the compiled scene is refused, naming it.
    boxes(".4");
    let err = one_line_error(&rdc(
        d,
        &[&opts[..], &["scene.rdb"]].concat(),
        SENSORS.as_bytes(),
    ));
    assert!(
        err.contains("crate.oct") && err.contains("out of date"),
        "{err}"
    );
}

#[test]
fn a_changed_source_is_refused_naming_it() {
    let t = tmpdir();
    let d = t.path();
    std::fs::write(d.join("shapes.rad"), SHAPES).unwrap();
    let mesh = common::repo().join("tests/data/mesh");
    for f in ["table.obj", "table.mat"] {
        std::fs::copy(mesh.join(f), d.join(f)).unwrap();
    }
    std::fs::write(
        d.join("tables.rad"),
        "void mesh t1 5 table.obj -t 1 1 0 0 0\n",
    )
    .unwrap();
    let scene = ["shapes.rad", "table.mat", "tables.rad"];
    let opts = ["-h", "-I", "-ab", "1", "-ad", "16"];
    run_ok(
        ours("rdc")
            .current_dir(d)
            .args(["--compile", "scene.rdb"])
            .args(scene),
        b"",
    );
    let first = rdc_ok(d, &[&opts[..], &["scene.rdb"]].concat());
    let again = || rdc(d, &[&opts[..], &["scene.rdb"]].concat(), SENSORS.as_bytes());
    // Rewritten with the same bytes (a newer time): still the same scene.
    std::fs::write(d.join("shapes.rad"), SHAPES).unwrap();
    let out = again();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(out.stdout, first);
    // Each kind of source changed: a scene file, a file a mesh reads, a file gone.
    let cases: [(&str, &dyn Fn()); 3] = [
        ("shapes.rad", &|| {
            std::fs::write(d.join("shapes.rad"), format!("{SHAPES}# moved\n")).unwrap()
        }),
        ("table.obj", &|| {
            let obj = std::fs::read_to_string(mesh.join("table.obj")).unwrap();
            std::fs::write(d.join("table.obj"), obj.replacen("v ", "v  ", 1)).unwrap()
        }),
        ("table.mat", &|| {
            std::fs::remove_file(d.join("table.mat")).unwrap()
        }),
    ];
    for (file, change) in cases {
        change();
        let err = one_line_error(&again());
        assert!(
            err.contains(file) && err.contains("scene.rdb is out of date"),
            "{file}: {err}"
        );
        // Put it back: accepted again.
        match file {
            "shapes.rad" => std::fs::write(d.join(file), SHAPES).unwrap(),
            _ => {
                std::fs::copy(mesh.join(file), d.join(file)).unwrap();
            }
        }
        assert_eq!(again().stdout, first, "{file} restored");
    }
}

#[test]
fn damaged_compiled_scenes_are_errors_not_panics() {
    let t = tmpdir();
    let d = t.path();
    std::fs::write(d.join("shapes.rad"), SHAPES).unwrap();
    run_ok(
        ours("rdc")
            .current_dir(d)
            .args(["--compile", "scene.rdb", "shapes.rad"]),
        b"",
    );
    let path = d.join("scene.rdb");
    let bytes = std::fs::read(&path).unwrap();
    assert!(compiled::decode(&bytes, &path).is_ok());
    // Every prefix, and every byte flipped (anywhere: the checksum covers the header too).
    for n in 0..bytes.len() {
        assert!(
            compiled::decode(&bytes[..n], &path).is_err(),
            "prefix {n} accepted"
        );
    }
    for k in 0..bytes.len() {
        let mut b = bytes.clone();
        b[k] ^= 0x10;
        assert!(
            compiled::decode(&b, &path).is_err(),
            "byte {k} flipped accepted"
        );
    }
    // Another format version: refused as such.
    let at = bytes.windows(8).position(|w| w == b"RDSCENE\0").unwrap() + 8;
    let mut v2 = bytes.clone();
    v2[at] = 2;
    let e = compiled::decode(&v2, &path).unwrap_err().to_string();
    assert!(e.contains("format 2") && e.contains("rdc --compile"), "{e}");
    // Through rdc: one line, status 1, nothing written.
    let opts = ["-h", "-I", "-ab", "1", "-ad", "16"];
    std::fs::write(d.join("cut.rdb"), &bytes[..bytes.len() * 2 / 3]).unwrap();
    let mut flipped = bytes.clone();
    flipped[bytes.len() / 2] ^= 1;
    std::fs::write(d.join("flip.rdb"), &flipped).unwrap();
    std::fs::write(d.join("v2.rdb"), &v2).unwrap();
    for (f, what) in [
        ("cut.rdb", "truncated"),
        ("flip.rdb", "checksum"),
        ("v2.rdb", "format 2"),
    ] {
        let err = one_line_error(&rdc(d, &[&opts[..], &[f]].concat(), SENSORS.as_bytes()));
        assert!(err.contains(f) && err.contains(what), "{err}");
    }
    // A compiled scene is a run's only scene; --flux and --compile take .rad files.
    let err = one_line_error(&rdc(
        d,
        &[&opts[..], &["scene.rdb", "shapes.rad"]].concat(),
        SENSORS.as_bytes(),
    ));
    assert!(err.contains("only scene input"), "{err}");
    let err = one_line_error(&rdc(d, &["--compile", "again.rdb", "scene.rdb"], b""));
    assert!(err.contains("compiled already"), "{err}");
    assert!(!d.join("again.rdb").exists());
    let err = one_line_error(&rdc(
        d,
        &["--flux", "-I", "-", "shapes.rad", "scene.rdb"],
        SENSORS.as_bytes(),
    ));
    assert!(err.contains("scene.rdb is a compiled scene"), "{err}");
    // Standard input cannot be checked later: refused, nothing written.
    let err = one_line_error(&rdc(d, &["--compile", "in.rdb", "-"], SHAPES.as_bytes()));
    assert!(err.contains("standard input"), "{err}");
    assert!(!d.join("in.rdb").exists());
}

#[test]
fn scene_cache_reuses_only_unchanged_scenes() {
    use std::os::unix::fs::MetadataExt;
    let t = tmpdir();
    let d = t.path();
    std::fs::write(d.join("shapes.rad"), SHAPES).unwrap();
    let opts = ["-h", "-I", "-ab", "1", "-ad", "16"];
    let cached = || {
        rdc_ok(
            d,
            &[&["--scene-cache", "cache"], &opts[..], &["shapes.rad"]].concat(),
        )
    };
    let entries = || -> Vec<std::path::PathBuf> {
        let mut v: Vec<_> = std::fs::read_dir(d.join("cache"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        v.sort();
        v
    };
    let direct = rdc_ok(d, &[&opts[..], &["shapes.rad"]].concat());
    assert_eq!(cached(), direct);
    let kept = entries();
    assert_eq!(kept.len(), 1, "{kept:?}");
    let ino = std::fs::metadata(&kept[0]).unwrap().ino();
    // Unchanged sources: the kept file is read, not written again.
    assert_eq!(cached(), direct);
    assert_eq!(entries(), kept);
    assert_eq!(std::fs::metadata(&kept[0]).unwrap().ino(), ino);
    // A changed scene: other numbers, those of the changed scene, and a second entry.
    std::fs::write(
        d.join("shapes.rad"),
        SHAPES.replace("6e6 6e6 6e6", "3e6 3e6 3e6"),
    )
    .unwrap();
    let changed = cached();
    assert_ne!(changed, direct);
    assert_eq!(changed, rdc_ok(d, &[&opts[..], &["shapes.rad"]].concat()));
    assert_eq!(entries().len(), 2);
}
