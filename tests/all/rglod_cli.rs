//! The `rglod` binary on the bundled furnished room (examples/furnished): the object table,
//! filtered scenes that are exact subsets and parse back, and one-line errors with status 1.

use std::path::Path;
use std::process::{Command, Output};

use rdaylight::scene::{self, LoadOptions};

const ROOM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/furnished/room.rad");

fn rglod(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rglod"))
        .args(args)
        .output()
        .unwrap()
}

fn ok(args: &[&str]) -> String {
    let o = rglod(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

fn err(args: &[&str]) -> String {
    let o = rglod(args);
    assert_eq!(o.status.code(), Some(1), "{args:?} should fail");
    assert!(o.stdout.is_empty(), "nothing on stdout after an error");
    let e = String::from_utf8(o.stderr).unwrap();
    assert_eq!(e.lines().count(), 1, "one line: {e}");
    e
}

#[test]
fn objects_table_of_the_furnished_room() {
    let t = ok(&["objects", ROOM]);
    let rows: Vec<Vec<&str>> = t.lines().skip(2).map(|l| l.split('\t').collect()).collect();
    assert_eq!(rows.len(), 34, "34 objects");
    let level = |id: &str| {
        rows.iter()
            .find(|r| r[0] == id)
            .unwrap_or_else(|| panic!("{id}"))[12]
    };
    // Seed thresholds: boxed desks and shelves >= 3.0 (GLoD1), polygon desks 2.56 (GLoD2),
    // chairs 2.03 (GLoD3), books and lamps below 0.5 (GLoD4).
    assert_eq!(level("desk_5"), "1");
    assert_eq!(level("shelf_1"), "1");
    assert_eq!(level("cabinet_1"), "1");
    assert_eq!(level("desk_1"), "2");
    assert_eq!(level("chair_7"), "3");
    assert_eq!(level("book_3"), "4");
    let desk1 = rows.iter().find(|r| r[0] == "desk_1").unwrap();
    assert_eq!(
        desk1[11], "2.560000",
        "a single polygon gets its flat box's 2ab"
    );
    let cab = rows.iter().find(|r| r[0] == "cabinet_1").unwrap();
    let area: f64 = cab[11].parse().unwrap();
    assert!(
        (area - 2.0 * (0.5 + 1.2 + 0.6)).abs() < 1e-4,
        "turned cabinet: {area}"
    );
    let json = ok(&["objects", "--json", ROOM]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["objects"].as_array().unwrap().len(), 34);
}

#[test]
fn filtered_levels_are_exact_subsets_that_parse_back() {
    let input = scene::load(&[ROOM], &LoadOptions::default()).unwrap();
    let texts: Vec<String> = input.objects.iter().map(|o| o.to_string()).collect();
    let mut counts = Vec::new();
    for level in ["0", "1", "2", "3", "4"] {
        let text = ok(&["filter", "-l", level, ROOM]);
        let back =
            scene::parse_str(&text, "out.rad", Path::new(""), &LoadOptions::default()).unwrap();
        let mut from = 0;
        for o in &back.objects {
            let t = o.to_string();
            from += 1 + texts[from..]
                .iter()
                .position(|x| *x == t)
                .expect("input object");
        }
        counts.push(back.surfaces().count());
    }
    assert_eq!(counts[4], input.surfaces().count(), "GLoD4 is everything");
    assert!(counts.windows(2).all(|w| w[0] < w[1]), "{counts:?}");
    // GLoD0 is the example room's shell: floor, ceiling, 3 walls, 4 south-wall pieces, the
    // window and the exterior ground (11 surfaces).
    assert_eq!(counts[0], 11);
}

#[test]
fn errors_are_one_line_with_the_place_and_the_fix() {
    let e = err(&["filter", "-l", "7", ROOM]);
    assert!(
        e.contains("-l 7") && e.contains("0 (shell only) to 4"),
        "{e}"
    );
    let e = err(&["objects", "--thresholds", "0.5,2.4,3", ROOM]);
    assert!(e.contains("GLoD1 >= GLoD2 >= GLoD3"), "{e}");
    let dir = std::env::temp_dir().join(format!("rglod-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.rad");
    std::fs::write(
        &bad,
        "void plastic m 0 0 5 .5 .5 .5 0 0\nm polygon p 0 0 11 0 0 0 1 0 0 1 1\n",
    )
    .unwrap();
    let e = err(&["objects", bad.to_str().unwrap()]);
    assert!(e.contains("bad.rad:2"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `rglod study` on the example room's shell with one floating slab (a GLoD1 object, OBB
/// area 7.05 m2) over one of two sensors: GLoD1-4 keep the slab and trace the same paths
/// (same seed), so their TAI equals GLoD4's exactly; GLoD0 drops it, and the sensor under it
/// gains light (positive PE).
#[test]
fn study_levels_against_glod4() {
    let dir = tempfile::tempdir().unwrap();
    let shell = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/room/room.rad"
    ))
    .unwrap();
    let slab = "wall_mat polygon desk_1.bottom 0 0 12 2 3 0.6 2 4.5 0.6 4 4.5 0.6 4 3 0.6\n\
         wall_mat polygon desk_1.top 0 0 12 2 3 0.75 4 3 0.75 4 4.5 0.75 2 4.5 0.75\n\
         wall_mat polygon desk_1.south 0 0 12 2 3 0.6 4 3 0.6 4 3 0.75 2 3 0.75\n\
         wall_mat polygon desk_1.north 0 0 12 2 4.5 0.6 2 4.5 0.75 4 4.5 0.75 4 4.5 0.6\n\
         wall_mat polygon desk_1.west 0 0 12 2 3 0.6 2 3 0.75 2 4.5 0.75 2 4.5 0.6\n\
         wall_mat polygon desk_1.east 0 0 12 4 3 0.6 4 4.5 0.6 4 4.5 0.75 4 3 0.75\n";
    let room = dir.path().join("room.rad");
    std::fs::write(&room, format!("{shell}\n{slab}")).unwrap();
    let pts = dir.path().join("s.pts");
    std::fs::write(&pts, "3 3.75 0.3 0 0 1\n1 6 0.8 0 0 1\n").unwrap();
    let epw = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/weather/GBR_London.Gatwick.037760_IWEC.epw"
    );
    let t = ok(&[
        "study",
        "-w",
        epw,
        "--pts",
        pts.to_str().unwrap(),
        "-ab",
        "2",
        "-ad",
        "256",
        "-lw",
        "1e-3",
        room.to_str().unwrap(),
    ]);
    let rows: Vec<Vec<&str>> = t.lines().skip(1).map(|l| l.split('\t').collect()).collect();
    assert_eq!(rows.len(), 5, "{t}");
    let tai = |i: usize| rows[i][3].parse::<f64>().unwrap();
    let pe = |i: usize| rows[i][4].parse::<f64>().unwrap();
    for i in 1..5 {
        assert_eq!(tai(i), tai(4), "GLoD{i} keeps the slab: {t}");
        assert_eq!(pe(i), 0.0, "{t}");
    }
    assert_eq!(rows[0][1], "0", "GLoD0 keeps no object: {t}");
    assert_eq!(rows[1][1], "1", "{t}");
    assert!(pe(0) > 5.0, "dropping the slab must brighten the room: {t}");
}

/// `rglod plan`: one filled footprint per object of the furnished room, classed by level as
/// the object table assigns them, inside one SVG document.
#[test]
fn plan_view_has_every_object_by_level() {
    let svg = ok(&["plan", ROOM]);
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    let table = ok(&["objects", ROOM]);
    for level in 1..=4 {
        let want = table
            .lines()
            .skip(2)
            .filter(|l| l.ends_with(&format!("\t{level}")))
            .count();
        let got = svg.matches(&format!("class=\"glod{level}\"")).count();
        assert_eq!(got, want, "GLoD{level}");
    }
    assert!(svg.matches("class=\"glod").count() >= 30);
}
