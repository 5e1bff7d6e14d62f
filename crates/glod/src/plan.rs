//! # A plan view of the objects coloured by level (SVG)
//!
//! Looking down the z axis (Radiance's up): the permanent shell's surfaces in grey outline,
//! and each object as the convex hull of its surface points projected on the floor plane,
//! filled with its level's colour (the footprint a consultant sketches; a chair is its
//! seat-and-legs outline, not its bounding box). Drawn in the order of the levels, largest
//! objects first, so small objects on desks stay visible. A legend names the levels and
//! thresholds. SVG because it is a vector the user can open anywhere and edit.

use std::fmt::Write;

use crate::level::Thresholds;
use crate::obb::hull2;
use crate::objects::Analysis;
use crate::points::sample;
use rdaylight_formats::scene::Scene;

/// Fill colours of GLoD1..4 (ColorBrewer "Set1"-like, distinguishable in print and for the
/// common colour-vision deficiencies: blue, orange, green, purple).
pub const LEVEL_COLOURS: [&str; 4] = ["#377eb8", "#ff7f00", "#4daf4a", "#984ea3"];

/// Pixels per metre of the drawing.
const SCALE: f64 = 60.0;
const MARGIN: f64 = 20.0;
const LEGEND_H: f64 = 70.0;

fn footprint(scene: &Scene, members: &[usize]) -> Vec<[f64; 2]> {
    let pts: Vec<[f64; 2]> = members
        .iter()
        .filter_map(|&i| scene.objects.get(i))
        .filter_map(|o| sample(&o.kind))
        .flat_map(|s| s.points.into_iter().map(|p| [p[0], p[1]]))
        .collect();
    hull2(pts)
}

/// The plan view of `analysis` (of `scene`) as an SVG document; `thresholds` for the legend.
pub fn svg(scene: &Scene, analysis: &Analysis, thresholds: &Thresholds) -> String {
    let shell: Vec<Vec<[f64; 2]>> = analysis
        .shell
        .iter()
        .map(|&i| footprint(scene, &[i]))
        .filter(|h| !h.is_empty())
        .collect();
    let mut objects: Vec<(u8, f64, Vec<[f64; 2]>, &str)> = analysis
        .objects
        .iter()
        .map(|o| (o.level, o.area, footprint(scene, &o.members), o.id.as_str()))
        .filter(|o| o.2.len() >= 2)
        .collect();
    objects.sort_by(|a, b| a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)));
    // Extent of the room: the walls (vertical shell surfaces, whose footprints are lines)
    // and the objects. Horizontal shell surfaces are left out of it because a ground plane
    // or site context would shrink the room to a dot; they are still drawn (and clipped).
    let walls: Vec<&Vec<[f64; 2]>> = shell.iter().filter(|h| h.len() == 2).collect();
    let extent: Vec<&Vec<[f64; 2]>> = if walls.is_empty() {
        shell.iter().chain(objects.iter().map(|o| &o.2)).collect()
    } else {
        walls
            .into_iter()
            .chain(objects.iter().map(|o| &o.2))
            .collect()
    };
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for p in extent.into_iter().flatten() {
        x0 = x0.min(p[0]);
        y0 = y0.min(p[1]);
        x1 = x1.max(p[0]);
        y1 = y1.max(p[1]);
    }
    if x0 > x1 {
        (x0, y0, x1, y1) = (0.0, 0.0, 1.0, 1.0);
    }
    let (w, h) = (
        (x1 - x0) * SCALE + 2.0 * MARGIN,
        (y1 - y0) * SCALE + 2.0 * MARGIN,
    );
    // North (+y) up: SVG's y grows downwards.
    let px = |p: &[f64; 2]| {
        format!(
            "{:.1},{:.1}",
            MARGIN + (p[0] - x0) * SCALE,
            MARGIN + (y1 - p[1]) * SCALE
        )
    };
    let poly = |pts: &[[f64; 2]]| pts.iter().map(px).collect::<Vec<_>>().join(" ");
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w:.0}\" height=\"{:.0}\" \
         font-family=\"sans-serif\" font-size=\"12\">",
        h + LEGEND_H
    );
    let _ = writeln!(s, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>");
    for p in &shell {
        let _ = writeln!(
            s,
            "<polygon class=\"shell\" points=\"{}\" fill=\"none\" stroke=\"#888\" stroke-width=\"2\"/>",
            poly(p)
        );
    }
    for (level, area, p, id) in &objects {
        let colour = LEVEL_COLOURS[usize::from(level.saturating_sub(1)).min(3)];
        let _ = writeln!(
            s,
            "<polygon class=\"glod{level}\" points=\"{}\" fill=\"{colour}\" fill-opacity=\"0.75\" \
             stroke=\"#222\" stroke-width=\"0.5\"><title>{} (GLoD{level}, OBB {area:.2} m2)</title></polygon>",
            poly(p),
            xml_escape(id)
        );
    }
    let (a, b, c) = (thresholds.glod1, thresholds.glod2, thresholds.glod3);
    let labels = [
        format!("GLoD1: OBB >= {a} m2"),
        format!("GLoD2: >= {b} m2"),
        format!("GLoD3: >= {c} m2"),
        "GLoD4: smaller".to_string(),
    ];
    for (k, (label, colour)) in labels.iter().zip(LEVEL_COLOURS).enumerate() {
        let x = MARGIN + (k % 2) as f64 * 170.0;
        let y = h + 10.0 + (k / 2) as f64 * 22.0;
        let _ = writeln!(
            s,
            "<rect x=\"{x:.0}\" y=\"{y:.0}\" width=\"14\" height=\"14\" fill=\"{colour}\"/>\
             <text x=\"{:.0}\" y=\"{:.0}\">{label}</text>",
            x + 20.0,
            y + 12.0
        );
    }
    let _ = writeln!(
        s,
        "<text x=\"{MARGIN:.0}\" y=\"{:.0}\" fill=\"#555\">grey: permanent shell (GLoD0); plan view, north up, {SCALE} px/m</text>",
        h + 64.0
    );
    s.push_str("</svg>\n");
    s
}

fn xml_escape(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Options, analyse};
    use rdaylight_formats::scene::{LoadOptions, parse_str};

    #[test]
    fn one_polygon_per_object_coloured_by_level() {
        let text = "void plastic grey 0 0 5 .5 .5 .5 0 0\n\
            grey polygon floor 0 0 12 0 0 0 4 0 0 4 4 0 0 4 0\n\
            grey polygon ceiling 0 0 12 0 0 3 0 4 3 4 4 3 4 0 3\n\
            grey polygon desk_1.top 0 0 12 1 1 .7 2.6 1 .7 2.6 1.8 .7 1 1.8 .7\n\
            grey polygon book_1.a 0 0 12 3 3 .9 3.2 3 .9 3.2 3.1 .9 3 3.1 .9\n";
        let scene = parse_str(
            text,
            "room.rad",
            std::path::Path::new(""),
            &LoadOptions::default(),
        )
        .unwrap();
        let a = analyse(&scene, &Options::default()).unwrap();
        let svg = svg(&scene, &a, &Options::default().thresholds);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        // The desk top (2.56 m2) is GLoD2, the book (0.04 m2) GLoD4, the shell two outlines.
        assert_eq!(svg.matches("class=\"glod2\"").count(), 1, "{svg}");
        assert_eq!(svg.matches("class=\"glod4\"").count(), 1, "{svg}");
        assert_eq!(svg.matches("class=\"shell\"").count(), 2, "{svg}");
        assert!(svg.contains(&format!("fill=\"{}\"", LEVEL_COLOURS[1])));
        // The desk's footprint: its four corners, north up (y = 1 m is 0.8 m below y = 1.8 m).
        assert!(svg.contains("80.0,200.0"), "{svg}");
        // A ground plane far beyond the room does not change the drawing's extent when walls
        // bound it.
        let walled = format!(
            "{text}grey polygon wall_s 0 0 12 0 0 0 0 0 3 4 0 3 4 0 0\n\
             grey polygon ground 0 0 12 -50 -50 -0.01 50 -50 -0.01 50 50 -0.01 -50 50 -0.01\n"
        );
        let scene = parse_str(
            &walled,
            "room.rad",
            std::path::Path::new(""),
            &LoadOptions::default(),
        )
        .unwrap();
        let a = analyse(&scene, &Options::default()).unwrap();
        let drawn = super::svg(&scene, &a, &Options::default().thresholds);
        assert!(drawn.contains("width=\"280\""), "{}", &drawn[..200]);
    }
}
