//! rrecon end to end on simulated scans of known rooms: shell, windows, watertightness,
//! Chamfer and Hausdorff distances against the ground truth (seed Table 4.4 bounds).

use rdaylight::recon::eval::{Comparison, compare};
use rdaylight::recon::model::fix_t_junctions;
use rdaylight::recon::openings::Selection;
use rdaylight::recon::rooms::RoomSpec;
use rdaylight::recon::simulate::{ScanOptions, scan};
use rdaylight::recon::{ReconParams, reconstruct};

/// Scan `room` coarsely (fast tests), reconstruct with `--auto`, compare.
fn run(room: &str, resolution: f64, target: usize) -> (Comparison, bool, usize, usize) {
    let spec = RoomSpec::named(room).unwrap();
    let cloud = scan(
        &spec.scene().unwrap(),
        &ScanOptions {
            stations: spec.stations.clone(),
            resolution,
            noise: 0.003,
            ..Default::default()
        },
    )
    .unwrap();
    let params = ReconParams {
        target_points: target,
        ..Default::default()
    };
    let r = reconstruct(cloud, &params, &Selection::Auto).unwrap();
    let mut truth = spec.model().polygons();
    fix_t_junctions(&mut truth, 1e-6);
    let found = r.model.polygons();
    let c = compare(&truth, &found, 20_000);
    eprintln!(
        "{room}: faces {} planes {} cells {} windows {}/{} chamfer {:.4} m hausdorff {:.3} m area err {:.3} pos err {:.3} watertight {:?} timings {:?}",
        r.model.faces.len(),
        r.shell.planes.len(),
        r.shell.cells,
        c.windows_found,
        c.windows_true,
        c.chamfer,
        c.hausdorff,
        c.window_area_error,
        c.window_position_error,
        r.watertight,
        r.timings
    );
    for (f, cs) in r.model.faces.iter().zip(&r.candidates) {
        for cd in cs.iter().filter(|c| c.area > 0.05) {
            eprintln!(
                "  {} #{} area {:.3} rect {:.2} {:?} clear {:.1}/{:.1} through {} auto {}: {}",
                f.name,
                cd.id,
                cd.area,
                cd.rectangularity,
                cd.view,
                cd.clear,
                cd.facing,
                cd.through,
                cd.auto,
                cd.reason
            );
        }
    }
    (
        c,
        r.watertight.is_closed(),
        r.model.faces.len(),
        r.model.openings.len(),
    )
}

// Seed Table 4.4: sub-centimetre Chamfer distance for regular rooms. Windows: all found, total
// area within 10 % (the seed's models over-predict glazing area too).

#[test]
fn rectangular_room() {
    let (c, closed, faces, windows) = run("rect", 0.4, 60_000);
    assert!(closed);
    assert_eq!((faces, windows), (6, 3));
    assert!(c.chamfer < 0.01 && c.hausdorff < 0.1, "{c:?}");
    assert!(
        c.window_area_error.abs() < 0.1 && c.window_position_error < 0.05,
        "{c:?}"
    );
}

#[test]
fn l_shaped_room() {
    let (c, closed, faces, windows) = run("lshape", 0.4, 60_000);
    assert!(closed);
    assert_eq!((faces, windows), (8, 3));
    assert!(c.chamfer < 0.01 && c.hausdorff < 0.1, "{c:?}");
    assert!(
        c.window_area_error.abs() < 0.1 && c.window_position_error < 0.05,
        "{c:?}"
    );
}

/// Non-orthogonal walls and a sloped ceiling.
#[test]
fn slanted_room() {
    let (c, closed, faces, windows) = run("slanted", 0.4, 60_000);
    assert!(closed);
    assert_eq!((faces, windows), (6, 2));
    assert!(c.chamfer < 0.01 && c.hausdorff < 0.1, "{c:?}");
    assert!(c.window_area_error.abs() < 0.1, "{c:?}");
}

/// Hard rooms: numbers recorded (run with --nocapture), the Chamfer bound looser than the
/// seed's. Window area: the seed's 10 % since outlines sit at the rim samples nearest the
/// opening (measured 1.7 % arched, 0.7 % cluttered; 6.2 % and 3.3 % before).
#[test]
fn arched_window_room() {
    let (c, closed, _, windows) = run("arched", 0.4, 60_000);
    assert!(closed);
    assert_eq!(windows, 2);
    assert!(c.chamfer < 0.02 && c.window_area_error.abs() < 0.1, "{c:?}");
}

/// Furniture occludes walls: the occlusion shadows must not become windows, and the cabinet
/// must not be carved out of the shell.
#[test]
fn cluttered_room() {
    let (c, closed, faces, windows) = run("cluttered", 0.4, 60_000);
    assert!(closed);
    assert_eq!((faces, windows), (6, 3));
    assert!(c.chamfer < 0.02 && c.window_area_error.abs() < 0.1, "{c:?}");
}

// Issue 19: surveys as real rooms often are. Glazing flush with the wall (no reveals to
// scan; the beams go through and return nothing but a few strays), a sloped ceiling over a
// non-rectangular plan, several stations, millimetre noise, and clutter standing clear of the
// floor whose occlusion shadows on the walls are window-sized and window-shaped. `--auto` must
// cut exactly the windows, each within 6 % of its area (measured: -2.4 to +4.2 % over seeds
// 1-4, dense, coarse and native density; docs/recon.md) and with its bounding box within 5 cm
// of the truth's, and leave the shadows.

use rdaylight::geometry::{Vec3, polygon_area};
use rdaylight::recon::openings::View;
use rdaylight::recon::{PointCloud, Reconstruction};

fn flush_scan(room: &str, resolution: f64, stray: f64, seed: u64) -> PointCloud {
    let spec = RoomSpec::named(room).unwrap();
    scan(
        &spec.scene().unwrap(),
        &ScanOptions {
            stations: spec.stations.clone(),
            resolution,
            noise: 0.003,
            stray,
            seed,
            ..Default::default()
        },
    )
    .unwrap()
}

fn bounds(v: &[Vec3]) -> (Vec3, Vec3) {
    v.iter().fold(
        (Vec3::splat(f64::INFINITY), Vec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

/// Every window of `room` cut once, in place and within 6 % of its area; nothing else cut;
/// the largest occlusion shadow listed as one and left. Returns the shadow's area.
fn assert_windows_and_no_shadows(room: &str, r: &Reconstruction) -> f64 {
    let truth = RoomSpec::named(room).unwrap().model();
    assert!(r.watertight.is_closed(), "{room}: {:?}", r.watertight);
    assert_eq!(
        r.model.openings.len(),
        truth.openings.len(),
        "{room}: {:?}",
        r.model.openings.iter().map(|o| &o.name).collect::<Vec<_>>()
    );
    for t in &truth.openings {
        let (tlo, thi) = bounds(&t.outline);
        let found = r.model.openings.iter().find(|o| {
            let (lo, hi) = bounds(&o.outline);
            (lo - tlo).max_abs() < 0.05 && (hi - thi).max_abs() < 0.05
        });
        let Some(o) = found else {
            panic!("{room}: {} ({tlo:?} .. {thi:?}) not found", t.name);
        };
        let (at, af) = (polygon_area(&t.outline), polygon_area(&o.outline));
        eprintln!(
            "{room}: {} area {af:.3} m2, true {at:.3} m2 ({:+.1} %), depth {:?}",
            o.name,
            100.0 * (af - at) / at,
            o.depth
        );
        assert!(
            (af - at).abs() < 0.06 * at,
            "{room} {}: {af} vs {at}",
            t.name
        );
        assert_eq!(o.depth, Some(0.0), "flush glazing has no reveal");
    }
    let shadow = r
        .candidates
        .iter()
        .flatten()
        .filter(|c| c.view == View::Occluded)
        .max_by(|a, b| a.area.total_cmp(&b.area))
        .expect("the board's shadow is a candidate");
    assert!(!shadow.auto && shadow.rectangularity > 0.9, "{shadow:?}");
    assert!(
        r.candidates
            .iter()
            .flatten()
            .all(|c| !c.auto || c.view == View::Open),
        "only open candidates are taken"
    );
    shadow.area
}

/// The pentagon under a sloped ceiling, 3 stations at 0.2 degrees (3 million points), a few
/// stray returns through the glass; the same model for the same seed on one thread as on
/// all, and the same windows when the cloud carries no stations (one is then assumed).
#[test]
fn flush_glazing_pentagon_dense_scan() {
    let cloud = flush_scan("flush", 0.2, 0.001, 1);
    assert!(cloud.len() > 2_500_000, "{}", cloud.len());
    let params = ReconParams::default();
    let r = reconstruct(cloud.clone(), &params, &Selection::Auto).unwrap();
    eprintln!("flush: {} points, {:?}", cloud.len(), r.timings);
    let shadow = assert_windows_and_no_shadows("flush", &r);
    // The board 0.55 m in front of the north wall hides about 1.7 m2 of it, from 0.4 m above
    // the floor: by area, shape and position a window.
    assert!(shadow > 1.2, "{shadow}");
    // Reproducible per seed, whatever the thread count.
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let again = one.install(|| reconstruct(cloud.clone(), &params, &Selection::Auto).unwrap());
    assert_eq!(again.model, r.model);
    assert_eq!(again.candidates, r.candidates);
    let mut bare = cloud;
    bare.stations.clear();
    bare.station_of = None;
    let r = reconstruct(bare, &params, &Selection::Auto).unwrap();
    assert!(
        r.stations_assumed && r.stations.len() == 1,
        "{:?}",
        r.stations
    );
    assert_windows_and_no_shadows("flush", &r);
}

/// The L under a ceiling sloping both ways, 4 stations, and glazing that returns nothing at
/// all (no strays): the line-of-sight test alone finds the windows.
#[test]
fn flush_glazing_l_without_stray_returns() {
    let cloud = flush_scan("flushl", 0.2, 0.0, 2);
    let r = reconstruct(cloud, &ReconParams::default(), &Selection::Auto).unwrap();
    let shadow = assert_windows_and_no_shadows("flushl", &r);
    assert!(shadow > 1.5, "{shadow}");
}

/// At the input's own density: no down-sampling (half a million points, 1 cm spacing).
#[test]
fn flush_glazing_at_native_density() {
    let cloud = flush_scan("flush", 0.5, 0.002, 3);
    let params = ReconParams {
        target_points: cloud.len(),
        ..Default::default()
    };
    let r = reconstruct(cloud, &params, &Selection::Auto).unwrap();
    assert!(r.spacing < 0.015, "not down-sampled: {}", r.spacing);
    assert_windows_and_no_shadows("flush", &r);
}
