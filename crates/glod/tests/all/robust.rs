//! Robustness (STYLE.md habit 7): random and degenerate scenes never panic, every grouping
//! gives a partition of the surfaces, and every level's scene parses back.

use std::path::Path;

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rdaylight_formats::scene::{self, LoadOptions};
use rdaylight_glod::{Frame, Grouping, Options, analyse, filter};

fn coord(rng: &mut Pcg64) -> f64 {
    match rng.random_range(0..10) {
        0 => 0.0,
        1 => 1e9,
        2 => -1e-9,
        _ => (rng.random_range(-3.0..9.0f64) * 100.0).round() / 100.0,
    }
}

fn random_scene(rng: &mut Pcg64) -> String {
    let mut s = String::from("void plastic m 0 0 5 .5 .5 .5 0 0\nvoid glass g 0 0 3 .9 .9 .9\n");
    for i in 0..rng.random_range(0..25) {
        let m = if rng.random_range(0..8) == 0 {
            "g"
        } else {
            "m"
        };
        let id = format!("o{}.p{i}", rng.random_range(0..5));
        let mut p = |n: usize| {
            (0..n)
                .map(|_| coord(rng).to_string())
                .collect::<Vec<_>>()
                .join(" ")
        };
        let line = match i % 5 {
            0 => {
                let v = 3 + (i % 3);
                // Sometimes all vertices equal: a degenerate polygon.
                format!("{m} polygon {id} 0 0 {} {}", 3 * v, p(3 * v))
            }
            1 => format!("{m} sphere {id} 0 0 4 {}", p(4)),
            2 => format!("{m} cylinder {id} 0 0 7 {} {} 0.1", p(3), p(3)),
            3 => format!("{m} ring {id} 0 0 8 {} 0 0 0 0 1", p(3)),
            _ => format!("{m} cone {id} 0 0 8 {} 0 0.2", p(6)),
        };
        s += &line;
        s += "\n";
    }
    s
}

#[test]
fn random_and_degenerate_scenes_never_panic_and_filter_cleanly() {
    let mut rng = Pcg64::seed_from_u64(7);
    // 6 scenes x 4 groupings, a random frame each: a few seconds (an object with a sphere
    // costs ~50 ms: 2006 points through ~1000 box evaluations).
    for _ in 0..6 {
        let text = random_scene(&mut rng);
        let Ok(sc) = scene::parse_str(&text, "r.rad", Path::new(""), &LoadOptions::default())
        else {
            continue;
        };
        for grouping in [
            Grouping::Prefix(".".into()),
            Grouping::Modifier,
            Grouping::Connectivity(1e-3),
            Grouping::Source,
        ] {
            {
                let frame = if rng.random_range(0..2) == 0 {
                    Frame::Axes
                } else {
                    Frame::Walls
                };
                let opts = Options {
                    grouping: grouping.clone(),
                    frame,
                    ..Options::default()
                };
                let a = analyse(&sc, &opts).unwrap();
                // A partition: every surface exactly once, in the shell or in one object.
                let mut all: Vec<usize> = a.shell.clone();
                a.objects.iter().for_each(|o| all.extend(&o.members));
                all.sort_unstable();
                let surfaces: Vec<usize> = sc.surfaces().map(|(i, _)| i).collect();
                assert_eq!(all, surfaces, "{text}");
                for o in &a.objects {
                    assert!(o.area.is_finite() && o.area >= 0.0, "{}: {}", o.id, o.area);
                }
                for level in 0..=4 {
                    let out = filter::filter(&sc, &a, level).unwrap().to_string();
                    scene::parse_str(&out, "f.rad", Path::new(""), &LoadOptions::default())
                        .unwrap();
                }
            }
        }
    }
}

#[test]
fn an_empty_scene_has_no_shell_and_no_objects() {
    let sc = scene::parse_str("", "e.rad", Path::new(""), &LoadOptions::default()).unwrap();
    let a = analyse(&sc, &Options::default()).unwrap();
    assert!(a.shell.is_empty() && a.objects.is_empty());
    assert!(filter::filter(&sc, &a, 0).unwrap().objects.is_empty());
}
