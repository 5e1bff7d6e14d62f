//! Objects, the shell and filtering on scenes whose answer is known: the bundled example
//! room's shell with a few pieces of furniture.

use std::path::Path;

use rdaylight_formats::scene::{self, LoadOptions, Primitive, Scene};
use rdaylight_glod::{Frame, Grouping, Options, analyse, filter};

fn parse(text: &str) -> Scene {
    scene::parse_str(text, "test.rad", Path::new(""), &LoadOptions::default()).unwrap()
}

fn room_shell() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/room/room.rad"
    ))
    .unwrap()
}

/// A rectangle (4 vertices) at height z.
fn rect(m: &str, id: &str, x0: f64, y0: f64, x1: f64, y1: f64, z: f64) -> String {
    format!("{m} polygon {id} 0 0 12 {x0} {y0} {z} {x1} {y0} {z} {x1} {y1} {z} {x0} {y1} {z}\n")
}

/// An axis-aligned box as 6 polygons named `prefix.f0`..`f5`.
fn boxed(m: &str, prefix: &str, lo: [f64; 3], hi: [f64; 3]) -> String {
    let v = |i: usize| {
        [
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]
    };
    let faces = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let mut s = String::new();
    for (k, f) in faces.iter().enumerate() {
        s += &format!("{m} polygon {prefix}.f{k} 0 0 12");
        for &i in f {
            let p = v(i);
            s += &format!(" {} {} {}", p[0], p[1], p[2]);
        }
        s += "\n";
    }
    s
}

fn furnished() -> String {
    let mut s = room_shell();
    s += "void plastic wood 0 0 5 .4 .3 .2 0 0\nvoid plastic unused 0 0 5 .1 .1 .1 0 0\n";
    s += "void metal steel 0 0 5 .6 .6 .6 .9 0\n";
    // GLoD1: 1.5 x 1 m top, 2ab = 3.0 exactly at the threshold.
    s += &rect("wood", "desk_1.top", 1.0, 2.0, 2.5, 3.0, 0.72);
    // GLoD2: 1.2 x 1 m, 2.4 m2 exactly.
    s += &rect("wood", "desk_2", 3.0, 5.0, 4.2, 6.0, 0.72);
    // GLoD3: a chair of parts, seat 0.45 x 0.45 and a back: box 0.45 x 0.45 x 0.9.
    s += &rect("wood", "chair_1.seat", 1.5, 3.2, 1.95, 3.65, 0.45);
    s += "wood polygon chair_1.back 0 0 12 1.5 3.65 0.45 1.95 3.65 0.45 1.95 3.65 0.9 1.5 3.65 0.9\n";
    s += "steel cylinder chair_1.leg 0 0 7 1.5 3.2 0 1.5 3.2 0.45 0.02\n";
    // GLoD4: a 0.2 m ball, box area 6 * 0.04 = 0.24.
    s += "wood sphere plant_1.pot 0 0 4 5 7 0.1 0.1\n";
    // A box against the east wall: its back lies on the wall plane but it is furniture.
    s += &boxed("wood", "cabinet_1", [5.6, 4.0, 0.0], [6.0, 5.0, 1.0]);
    s
}

#[test]
fn the_example_rooms_shell_is_permanent_and_the_ground_exterior() {
    let s = parse(&room_shell());
    let a = analyse(&s, &Options::default()).unwrap();
    assert!(a.objects.is_empty(), "{:?}", a.objects);
    assert_eq!(a.shell.len(), s.surfaces().count());
}

#[test]
fn objects_levels_and_boxes_in_a_furnished_room() {
    let s = parse(&furnished());
    let a = analyse(&s, &Options::default()).unwrap();
    let find = |id: &str| {
        a.objects
            .iter()
            .find(|o| o.id == id)
            .unwrap_or_else(|| panic!("{id}"))
    };
    let ids: Vec<&str> = a.objects.iter().map(|o| o.id.as_str()).collect();
    assert_eq!(ids, ["desk_1", "desk_2", "chair_1", "plant_1", "cabinet_1"]);
    assert_eq!((find("desk_1").area, find("desk_1").level), (3.0, 1));
    assert_eq!(find("desk_2").level, 2);
    assert!((find("desk_2").area - 2.4).abs() < 1e-12);
    assert_eq!(find("chair_1").members.len(), 3);
    assert_eq!(find("chair_1").level, 3);
    assert_eq!(find("plant_1").level, 4);
    assert!((find("plant_1").area - 0.24).abs() < 0.24 * 0.005);
    let cab = find("cabinet_1");
    assert_eq!(
        cab.members.len(),
        6,
        "the back panel on the wall stays with its cabinet"
    );
    assert!(
        (cab.area - 2.0 * (0.4 + 0.4 + 1.0)).abs() < 1e-9,
        "{}",
        cab.area
    );
    // The window (glass) and every wall are shell; nothing else is.
    let shell_ids: Vec<&str> = a.shell.iter().map(|&i| s.objects[i].id.as_str()).collect();
    assert!(shell_ids.contains(&"window") && shell_ids.contains(&"ground"));
    assert_eq!(a.shell.len(), 11);
}

#[test]
fn filtered_scenes_are_exact_subsets_that_parse_back() {
    let input = parse(&furnished());
    let a = analyse(&input, &Options::default()).unwrap();
    let texts: Vec<String> = input.objects.iter().map(|o| o.to_string()).collect();
    let mut sizes = Vec::new();
    for level in 0..=4u8 {
        let out = filter::filter(&input, &a, level).unwrap();
        let text = out.to_string();
        let back = parse(&text);
        assert_eq!(back.objects.len(), out.objects.len());
        // Every output object is an input object, text-equal, in input order.
        let mut from = 0;
        for o in &back.objects {
            let t = o.to_string();
            let at = texts[from..]
                .iter()
                .position(|x| *x == t)
                .unwrap_or_else(|| panic!("{t}"));
            from += at + 1;
        }
        // Exactly the shell plus the objects of this level and below.
        let want: usize = a.shell.len()
            + a.objects
                .iter()
                .filter(|o| o.level <= level)
                .map(|o| o.members.len())
                .sum::<usize>();
        assert_eq!(back.surfaces().count(), want, "level {level}");
        assert!(!text.contains("unused"), "unused materials are dropped");
        assert_eq!(
            text.contains("steel"),
            level >= 3,
            "steel only with the chair"
        );
        sizes.push(back.objects.len());
    }
    assert!(sizes.windows(2).all(|w| w[0] <= w[1]), "{sizes:?}");
    assert!(filter::filter(&input, &a, 5).is_err());
}

#[test]
fn grouping_by_modifier_and_by_connectivity() {
    let mut text = room_shell();
    text += "void plastic red 0 0 5 .5 0 0 0 0\nvoid plastic blue 0 0 5 0 0 .5 0 0\n";
    // Two boxes touching corner to corner, one red and one blue, plus a free blue panel.
    text += &boxed("red", "a", [1.0, 1.0, 0.0], [2.0, 2.0, 1.0]);
    text += &boxed("blue", "b", [2.0, 2.0, 1.0], [2.5, 2.5, 1.5]);
    text += &rect("blue", "c", 4.0, 6.0, 4.5, 6.5, 1.0);
    let s = parse(&text);
    let by_mod = analyse(
        &s,
        &Options {
            grouping: Grouping::Modifier,
            ..Options::default()
        },
    )
    .unwrap();
    let mut ids: Vec<(String, usize)> = by_mod
        .objects
        .iter()
        .map(|o| (o.id.clone(), o.members.len()))
        .collect();
    ids.sort();
    // The red box's bottom lies on the floor plane: with modifier grouping on-plane polygons
    // join the shell first (objects.rs, rule 4), so red keeps 5 faces.
    assert_eq!(ids, [("blue".to_string(), 7), ("red".to_string(), 5)]);
    // Room surfaces share the material 'wall_mat' but stay in the shell.
    assert_eq!(by_mod.shell.len(), s.surfaces().count() - 12);
    let by_conn = analyse(
        &s,
        &Options {
            grouping: Grouping::Connectivity(1e-6),
            ..Options::default()
        },
    )
    .unwrap();
    let mut sizes: Vec<usize> = by_conn.objects.iter().map(|o| o.members.len()).collect();
    sizes.sort();
    assert_eq!(
        sizes,
        [1, 11],
        "the boxes touch at a corner; the floor face is shell"
    );
}

#[test]
fn permanent_patterns_and_a_rotated_room() {
    let s = parse(&furnished());
    let a = analyse(
        &s,
        &Options {
            permanent: vec!["desk_*".into(), "plant".into()],
            ..Options::default()
        },
    )
    .unwrap();
    let ids: Vec<&str> = a.objects.iter().map(|o| o.id.as_str()).collect();
    assert_eq!(ids, ["chair_1", "cabinet_1"]);
    // The wall frame finds the same shell in an axis-aligned room ...
    let p = analyse(
        &s,
        &Options {
            frame: Frame::Walls,
            ..Options::default()
        },
    )
    .unwrap();
    assert_eq!(p.objects.len(), 5);
    // ... and in the same room turned 27 degrees in plan, where the axes frame cannot.
    let (c, sn) = (27f64.to_radians().cos(), 27f64.to_radians().sin());
    let mut turned = s.clone();
    for o in &mut turned.objects {
        let rot = |p: &mut [f64; 3]| *p = [c * p[0] - sn * p[1], sn * p[0] + c * p[1], p[2]];
        match &mut o.kind {
            Primitive::Polygon { vertices } => vertices.iter_mut().for_each(rot),
            Primitive::Sphere { center, .. } => rot(center),
            Primitive::Cylinder { p0, p1, .. } => {
                rot(p0);
                rot(p1)
            }
            _ => {}
        }
    }
    let t = analyse(
        &turned,
        &Options {
            frame: Frame::Walls,
            ..Options::default()
        },
    )
    .unwrap();
    let ids: Vec<&str> = t.objects.iter().map(|o| o.id.as_str()).collect();
    assert_eq!(ids, ["desk_1", "desk_2", "chair_1", "plant_1", "cabinet_1"]);
    for (o, q) in t.objects.iter().zip(&a_all(&s)) {
        assert!((o.area - q).abs() < 1e-3 * q, "{}: {} vs {q}", o.id, o.area);
    }
}

#[test]
fn glob_matches() {
    use rdaylight_glod::objects::glob;
    assert!(glob("wall", "wall_3"));
    assert!(!glob("wall", "my_wall"));
    assert!(glob("*wall*", "my_wall_2"));
    assert!(glob("chair_?.leg", "chair_1.leg"));
    assert!(!glob("chair_?.leg", "chair_12.leg"));
    assert!(glob("*", ""));
}

fn a_all(s: &Scene) -> Vec<f64> {
    analyse(s, &Options::default())
        .unwrap()
        .objects
        .iter()
        .map(|o| o.area)
        .collect()
}

#[test]
fn grouping_by_source_file_or_inline_command() {
    let mut text = room_shell();
    text += "void plastic wood 0 0 5 .4 .3 .2 0 0\n";
    text += &rect("wood", "loose_a", 1.0, 1.0, 2.0, 2.0, 0.7);
    text += "!echo wood polygon p1 0 0 9 1 5 1 2 5 1 2 6 1\n";
    text += "!echo wood polygon p2 0 0 9 3 5 1 4 5 1 4 6 1\n";
    let opts = LoadOptions {
        allow_exec: true,
        command_env: Vec::new(),
    };
    let s = scene::parse_str(&text, "test.rad", Path::new(""), &opts).unwrap();
    let a = analyse(
        &s,
        &Options {
            grouping: Grouping::Source,
            ..Options::default()
        },
    )
    .unwrap();
    let ids: Vec<&str> = a.objects.iter().map(|o| o.id.as_str()).collect();
    assert_eq!(ids.len(), 3, "{ids:?}");
    assert_eq!(ids[0], "test.rad", "the file's own loose primitive");
    assert!(
        ids[1].contains("!echo") && ids[2].contains("!echo"),
        "{ids:?}"
    );
}
