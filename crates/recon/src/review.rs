//! Review pictures: one SVG per wall with the wall's points (their density shows where the
//! scanner saw the wall) and the numbered window candidates, so that a person can choose
//! with `--windows wall3:1,2` on the next run (the seed's lasso step, chapter 4.3.1.3).
//! Candidates `--auto` would take are drawn in blue, the others in orange; each carries its
//! area and the reason for `--auto`'s choice as a tooltip (occlusion shadow, reaches the
//! floor, ...).

use super::model::{FaceKind, Frame};
use super::pipeline::Reconstruction;
use crate::geometry::Vec3;
use std::fmt::Write as _;

/// SVG text for wall face `fi`, or `None` for other faces.
pub fn wall_svg(r: &Reconstruction, fi: usize, band: f64) -> Option<String> {
    let f = r.model.faces.get(fi)?;
    if f.kind != FaceKind::Wall {
        return None;
    }
    let fr = Frame::of_polygon(&f.polygon);
    let wall: Vec<[f64; 2]> = f.polygon.iter().map(|&v| fr.to_2d(v)).collect();
    let (u0, u1) = wall
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
            (a.min(q[0]), b.max(q[0]))
        });
    let (v0, v1) = wall
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| {
            (a.min(q[1]), b.max(q[1]))
        });
    let px = 200.0; // pixels per metre
    let (w, h) = ((u1 - u0) * px + 40.0, (v1 - v0) * px + 40.0);
    let x = |u: f64| 20.0 + (u - u0) * px;
    let y = |v: f64| 20.0 + (v1 - v) * px;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" viewBox="0 0 {w:.0} {h:.0}">"#
    );
    let _ = writeln!(
        s,
        r##"<rect width="100%" height="100%" fill="white"/><title>{} seen from inside</title>"##,
        f.name
    );
    let outline: Vec<String> = wall
        .iter()
        .map(|q| format!("{:.1},{:.1}", x(q[0]), y(q[1])))
        .collect();
    let _ = writeln!(
        s,
        r##"<polygon points="{}" fill="#eee" stroke="black"/>"##,
        outline.join(" ")
    );
    let _ = write!(s, r##"<g fill="#333">"##);
    for p in &r.cloud.points {
        let v = Vec3::from(*p);
        if fr.height(v).abs() > band {
            continue;
        }
        let q = fr.to_2d(v);
        if q[0] < u0 || q[0] > u1 || q[1] < v0 || q[1] > v1 {
            continue;
        }
        let _ = write!(
            s,
            r#"<rect x="{:.1}" y="{:.1}" width="1" height="1"/>"#,
            x(q[0]),
            y(q[1])
        );
    }
    let _ = writeln!(s, "</g>");
    for c in &r.candidates[fi] {
        let colour = if c.auto { "#1f6fd1" } else { "#e08a1e" };
        let _ = write!(
            s,
            r#"<g fill="{colour}" fill-opacity="0.35" stroke="{colour}" stroke-width="0.5"><title>{}: {:.2} m2, {}</title>"#,
            c.id,
            c.area,
            c.reason.replace('&', "&amp;").replace('<', "&lt;")
        );
        for t in &c.triangles {
            let pts: Vec<String> = t
                .iter()
                .map(|q| format!("{:.1},{:.1}", x(q[0]), y(q[1])))
                .collect();
            let _ = write!(s, r#"<polygon points="{}"/>"#, pts.join(" "));
        }
        let o: Vec<String> = c
            .outline
            .iter()
            .map(|q| format!("{:.1},{:.1}", x(q[0]), y(q[1])))
            .collect();
        let _ = write!(
            s,
            r#"<polygon points="{}" fill="none" stroke-width="2"/>"#,
            o.join(" ")
        );
        let (cx, cy) = (
            x(0.5 * (c.rect[0] + c.rect[2])),
            y(0.5 * (c.rect[1] + c.rect[3])),
        );
        let size = if c.area > 0.05 { 28 } else { 10 };
        let _ = writeln!(
            s,
            r#"<text x="{cx:.1}" y="{cy:.1}" font-family="sans-serif" font-size="{size}" text-anchor="middle" fill="{colour}" fill-opacity="1" stroke="none">{}</text></g>"#,
            c.id
        );
    }
    let _ = writeln!(s, "</svg>");
    Some(s)
}
