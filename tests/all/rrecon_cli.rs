//! The `rrecon` binary: the README pipeline (room -> simulate -> reconstruct -> eval) through
//! pipes, the JSON summary and review pictures, and exact error lines for bad input.

use std::io::Write;
use std::process::{Command, Output, Stdio};

fn rrecon(args: &[&str], stdin: &[u8]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_rrecon"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut sin = child.stdin.take().unwrap();
    let data = stdin.to_vec();
    let w = std::thread::spawn(move || {
        let _ = sin.write_all(&data);
    });
    let out = child.wait_with_output().unwrap();
    w.join().unwrap();
    out
}

fn ok(args: &[&str], stdin: &[u8]) -> Vec<u8> {
    let o = rrecon(args, stdin);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o.stdout
}

fn err(args: &[&str], stdin: &[u8]) -> String {
    let o = rrecon(args, stdin);
    assert_eq!(o.status.code(), Some(1), "{args:?} should fail");
    assert!(o.stdout.is_empty(), "nothing on stdout after an error");
    String::from_utf8(o.stderr).unwrap()
}

#[test]
fn room_simulate_reconstruct_eval_through_pipes() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).display().to_string();
    std::fs::write(d("room.rad"), ok(&["room", "rect"], b"")).unwrap();
    let scan = ok(&["simulate", &d("room.rad"), "--resolution", "0.5"], b"");
    assert!(scan.starts_with(b"ply\nformat binary_little_endian 1.0\n"));
    let rad = ok(
        &[
            "--auto",
            "--json",
            &d("s.json"),
            "--review",
            &d("review"),
            "--target-points",
            "40000",
            "-",
        ],
        &scan,
    );
    let text = String::from_utf8(rad).unwrap();
    std::fs::write(d("recon.rad"), &text).unwrap();
    let scene = rdaylight::scene::parse_str(
        &text,
        "recon.rad",
        std::path::Path::new(""),
        &Default::default(),
    )
    .unwrap();
    let glazing = scene
        .surfaces()
        .filter(|(i, _)| {
            scene
                .material_of(*i)
                .is_some_and(|m| scene.objects[m].id == "glazing")
        })
        .count();
    assert_eq!(glazing, 3);
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d("s.json")).unwrap()).unwrap();
    assert_eq!(j["watertight"], true);
    // True WFR: 5.84 m2 of glazing over a 20 m2 floor.
    let wfr = j["wfr"].as_f64().unwrap();
    assert!((wfr - 0.292).abs() < 0.03, "{wfr}");
    assert!((j["floor_area"].as_f64().unwrap() - 20.0).abs() < 0.2);
    // Semi-automatic: one named candidate, and a materials file that overrides `wall`.
    let wall = j["windows"][0]["wall"].as_str().unwrap().to_string();
    std::fs::write(d("m.rad"), "void plastic wall 0 0 5 0.7 0.7 0.7 0 0\n").unwrap();
    let one = ok(
        &[
            "--windows",
            &format!("{wall}:1"),
            "--materials",
            &d("m.rad"),
            "--target-points",
            "40000",
            "-",
        ],
        &scan,
    );
    let one = String::from_utf8(one).unwrap();
    assert_eq!(
        (
            one.matches("\nglazing polygon ").count(),
            text.matches("\nglazing polygon ").count()
        ),
        (1, 3)
    );
    assert!(
        one.contains("void plastic wall\n0\n0\n5 0.7 0.7 0.7 0 0"),
        "{one}"
    );
    assert!(one.contains(&format!("{wall}_window1")));
    let e = err(
        &["--windows", "wall9:1", "--target-points", "40000", "-"],
        &scan,
    );
    assert!(e.starts_with("rrecon: --windows names 'wall9', which is not a wall of this reconstruction; walls: wall0, wall1, wall2, wall3"), "{e}");
    let svgs = std::fs::read_dir(d("review")).unwrap().count();
    assert_eq!(svgs, 4, "one review picture per wall");
    let e: serde_json::Value = serde_json::from_slice(&ok(
        &[
            "eval",
            &d("room.rad"),
            &d("recon.rad"),
            "--samples",
            "20000",
        ],
        b"",
    ))
    .unwrap();
    assert!(e["chamfer"].as_f64().unwrap() < 0.01, "{e}");
    assert_eq!(
        (
            e["truth_watertight"].as_bool(),
            e["recon_watertight"].as_bool()
        ),
        (Some(true), Some(true))
    );
    // The room against itself: zero distances, zero window error.
    let e: serde_json::Value = serde_json::from_slice(&ok(
        &["eval", &d("room.rad"), &d("room.rad"), "--samples", "5000"],
        b"",
    ))
    .unwrap();
    assert!(
        e["hausdorff"].as_f64().unwrap() < 1e-9
            && e["window_area_error"].as_f64().unwrap().abs() < 1e-12,
        "{e}"
    );
}

/// Issue 19: flush glazing with a few stray returns and a board whose shadow looks like a
/// window. The PLY carries its stations; the same points as XYZ do not, and rrecon says what
/// it assumed instead, or takes them from --stations.
#[test]
fn flush_glazing_windows_with_and_without_stations() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).display().to_string();
    std::fs::write(d("room.rad"), ok(&["room", "flush"], b"")).unwrap();
    let scan = ok(
        &[
            "simulate",
            &d("room.rad"),
            "--resolution",
            "0.7",
            "--stray",
            "0.002",
        ],
        b"",
    );
    let glazing = |rad: &[u8]| {
        String::from_utf8_lossy(rad)
            .matches("\nglazing polygon ")
            .count()
    };
    let o = rrecon(&["--auto", "--json", &d("s.json"), "-"], &scan);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(glazing(&o.stdout), 2);
    assert!(
        o.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d("s.json")).unwrap()).unwrap();
    assert_eq!(j["stations_assumed"], false);
    assert_eq!(j["stations"].as_array().unwrap().len(), 3);
    let shadow = j["candidates"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|w| w["candidates"].as_array().unwrap().iter())
        .find(|c| c["view"] == "occluded" && c["area"].as_f64().unwrap() > 1.0)
        .expect("the board's shadow is listed");
    assert_eq!(shadow["auto"], false);
    assert!(
        shadow["reason"]
            .as_str()
            .unwrap()
            .contains("occlusion shadow"),
        "{shadow}"
    );
    // The same points without stations.
    let cloud = rdaylight::recon::ply::read(&scan, "scan.ply").unwrap();
    let mut xyz = String::new();
    for p in &cloud.points {
        xyz.push_str(&format!("{} {} {}\n", p[0], p[1], p[2]));
    }
    std::fs::write(d("scan.xyz"), xyz).unwrap();
    let o = rrecon(&["--auto", &d("scan.xyz")], b"");
    assert!(o.status.success());
    assert_eq!(glazing(&o.stdout), 2);
    let note = String::from_utf8(o.stderr).unwrap();
    assert!(
        note.starts_with("rrecon: note: ")
            && note.contains("gives no scanner stations")
            && note.contains("(give --stations)"),
        "{note}"
    );
    let o = rrecon(
        &[
            "--auto",
            "--stations",
            "2.3,2.0,1.5;4.7,2.6,1.45;1.4,3.2,1.55",
            &d("scan.xyz"),
        ],
        b"",
    );
    assert!(o.status.success());
    assert_eq!(glazing(&o.stdout), 2);
    assert!(
        o.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let e = err(&["--auto", "--stations", "1,2", &d("scan.xyz")], b"");
    assert_eq!(e, "rrecon: --stations '1,2': expected x,y,z\n");
}

#[test]
fn bad_inputs_give_one_line_with_location_and_fix() {
    let dir = tempfile::tempdir().unwrap();
    let d = |n: &str| dir.path().join(n).display().to_string();
    // A millimetre cloud read as metres.
    std::fs::write(d("mm.xyz"), "0 0 0\n5000 4000 2700\n").unwrap();
    let e = err(&["-o", &d("out.rad"), &d("mm.xyz")], b"");
    assert!(
        e.starts_with(&format!(
            "rrecon: {}: bounding box (0.0000 0.0000 0.0000) .. (5000.0000 4000.0000 2700.0000)",
            d("mm.xyz")
        )),
        "{e}"
    );
    assert!(
        e.trim_end()
            .ends_with("it looks like mm: convert with --units mm"),
        "{e}"
    );
    assert!(
        !std::path::Path::new(&d("out.rad")).exists(),
        "nothing half-written"
    );
    std::fs::write(d("bad.xyz"), "1 2 3\n1 2 x\n").unwrap();
    assert_eq!(
        err(&[&d("bad.xyz")], b""),
        format!(
            "rrecon: {}:2:5: 'x' is not a number; expected x y z [...] values\n",
            d("bad.xyz")
        )
    );
    let e = err(&["scan.laz"], b"");
    assert!(
        e.starts_with(
            "rrecon: scan.laz: unsupported point cloud format .laz; convert it to PLY first"
        ),
        "{e}"
    );
    assert_eq!(
        err(&["-"], b""),
        "rrecon: <stdin>: the point cloud is empty; expected at least one point\n"
    );
    let e = err(&["room", "kitchen"], b"");
    assert_eq!(
        e,
        "rrecon: unknown room 'kitchen'; expected one of rect, lshape, slanted, arched, cluttered, flush, flushl\n"
    );
}
