//! Line plots of per-wavelength errors as PNG (`docs/uplift-error-per-wavelength.png`).
//!
//! Drawn directly into an `image::RgbImage` (the crate is already a dependency) with a
//! built-in 5 x 7 pixel upper-case font, so the plot needs no font files, no system
//! libraries and no plotting crate, and the same code gives the same pixels everywhere
//! (the committed PNG is checked by a test).
//!
//! Layout: panels side by side, each with a title, wavelength axis (nm) and value axis (%),
//! a horizontal reference line, and curves (solid or dashed); one legend under the panels.
//! Values above the axis are drawn at its top (clipped), so a large error at one end does
//! not flatten the rest.

use image::{Rgb, RgbImage};

/// One curve.
#[derive(Debug, Clone)]
pub struct Series {
    pub label: String,
    pub colour: [u8; 3],
    pub dashed: bool,
    /// `(x, y)` points, drawn in order.
    pub points: Vec<(f64, f64)>,
}

/// One panel.
#[derive(Debug, Clone)]
pub struct Panel {
    pub title: String,
    pub series: Vec<Series>,
}

/// Axes shared by all panels.
#[derive(Debug, Clone)]
pub struct Axes {
    pub x_range: (f64, f64),
    pub x_ticks: Vec<f64>,
    pub x_label: String,
    pub y_range: (f64, f64),
    pub y_ticks: Vec<f64>,
    pub y_label: String,
    /// A dashed grey horizontal line (e.g. the seed's 20 % level) and its legend text.
    pub reference: Option<(f64, String)>,
}

/// 5 x 7 glyphs, rows top to bottom, `#` = ink.
fn glyph(c: char) -> [&'static str; 7] {
    match c.to_ascii_uppercase() {
        'A' => [
            " ### ", "#   #", "#   #", "#####", "#   #", "#   #", "#   #",
        ],
        'B' => [
            "#### ", "#   #", "#   #", "#### ", "#   #", "#   #", "#### ",
        ],
        'C' => [
            " ### ", "#   #", "#    ", "#    ", "#    ", "#   #", " ### ",
        ],
        'D' => [
            "#### ", "#   #", "#   #", "#   #", "#   #", "#   #", "#### ",
        ],
        'E' => [
            "#####", "#    ", "#    ", "#### ", "#    ", "#    ", "#####",
        ],
        'F' => [
            "#####", "#    ", "#    ", "#### ", "#    ", "#    ", "#    ",
        ],
        'G' => [
            " ### ", "#   #", "#    ", "# ###", "#   #", "#   #", " ####",
        ],
        'H' => [
            "#   #", "#   #", "#   #", "#####", "#   #", "#   #", "#   #",
        ],
        'I' => [
            " ### ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### ",
        ],
        'J' => [
            "  ###", "   # ", "   # ", "   # ", "   # ", "#  # ", " ##  ",
        ],
        'K' => [
            "#   #", "#  # ", "# #  ", "##   ", "# #  ", "#  # ", "#   #",
        ],
        'L' => [
            "#    ", "#    ", "#    ", "#    ", "#    ", "#    ", "#####",
        ],
        'M' => [
            "#   #", "## ##", "# # #", "# # #", "#   #", "#   #", "#   #",
        ],
        'N' => [
            "#   #", "#   #", "##  #", "# # #", "#  ##", "#   #", "#   #",
        ],
        'O' => [
            " ### ", "#   #", "#   #", "#   #", "#   #", "#   #", " ### ",
        ],
        'P' => [
            "#### ", "#   #", "#   #", "#### ", "#    ", "#    ", "#    ",
        ],
        'Q' => [
            " ### ", "#   #", "#   #", "#   #", "# # #", "#  # ", " ## #",
        ],
        'R' => [
            "#### ", "#   #", "#   #", "#### ", "# #  ", "#  # ", "#   #",
        ],
        'S' => [
            " ####", "#    ", "#    ", " ### ", "    #", "    #", "#### ",
        ],
        'T' => [
            "#####", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ",
        ],
        'U' => [
            "#   #", "#   #", "#   #", "#   #", "#   #", "#   #", " ### ",
        ],
        'V' => [
            "#   #", "#   #", "#   #", "#   #", "#   #", " # # ", "  #  ",
        ],
        'W' => [
            "#   #", "#   #", "#   #", "# # #", "# # #", "# # #", " # # ",
        ],
        'X' => [
            "#   #", "#   #", " # # ", "  #  ", " # # ", "#   #", "#   #",
        ],
        'Y' => [
            "#   #", "#   #", " # # ", "  #  ", "  #  ", "  #  ", "  #  ",
        ],
        'Z' => [
            "#####", "    #", "   # ", "  #  ", " #   ", "#    ", "#####",
        ],
        '0' => [
            " ### ", "#   #", "#  ##", "# # #", "##  #", "#   #", " ### ",
        ],
        '1' => [
            "  #  ", " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### ",
        ],
        '2' => [
            " ### ", "#   #", "    #", "   # ", "  #  ", " #   ", "#####",
        ],
        '3' => [
            "#####", "   # ", "  #  ", "   # ", "    #", "#   #", " ### ",
        ],
        '4' => [
            "   # ", "  ## ", " # # ", "#  # ", "#####", "   # ", "   # ",
        ],
        '5' => [
            "#####", "#    ", "#### ", "    #", "    #", "#   #", " ### ",
        ],
        '6' => [
            "  ## ", " #   ", "#    ", "#### ", "#   #", "#   #", " ### ",
        ],
        '7' => [
            "#####", "    #", "   # ", "  #  ", " #   ", " #   ", " #   ",
        ],
        '8' => [
            " ### ", "#   #", "#   #", " ### ", "#   #", "#   #", " ### ",
        ],
        '9' => [
            " ### ", "#   #", "#   #", " ####", "    #", "   # ", " ##  ",
        ],
        '%' => [
            "##   ", "##  #", "   # ", "  #  ", " #   ", "#  ##", "   ##",
        ],
        '-' => [
            "     ", "     ", "     ", "#####", "     ", "     ", "     ",
        ],
        '.' => [
            "     ", "     ", "     ", "     ", "     ", " ##  ", " ##  ",
        ],
        ',' => [
            "     ", "     ", "     ", "     ", " ##  ", "  #  ", " #   ",
        ],
        ':' => [
            "     ", " ##  ", " ##  ", "     ", " ##  ", " ##  ", "     ",
        ],
        '(' => [
            "   # ", "  #  ", " #   ", " #   ", " #   ", "  #  ", "   # ",
        ],
        ')' => [
            " #   ", "  #  ", "   # ", "   # ", "   # ", "  #  ", " #   ",
        ],
        '/' => [
            "     ", "    #", "   # ", "  #  ", " #   ", "#    ", "     ",
        ],
        '|' => [
            "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ",
        ],
        '+' => [
            "     ", "  #  ", "  #  ", "#####", "  #  ", "  #  ", "     ",
        ],
        '=' => [
            "     ", "     ", "#####", "     ", "#####", "     ", "     ",
        ],
        _ => ["     "; 7],
    }
}

const SCALE: u32 = 2;
const CHAR_W: u32 = 6 * SCALE;
const CHAR_H: u32 = 7 * SCALE;
const INK: [u8; 3] = [30, 30, 30];
const GRID: [u8; 3] = [225, 225, 225];

fn put(img: &mut RgbImage, x: i64, y: i64, c: [u8; 3]) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, Rgb(c));
    }
}

/// Width in pixels of a text.
fn text_width(s: &str) -> u32 {
    s.chars().count() as u32 * CHAR_W
}

fn text(img: &mut RgbImage, x: i64, y: i64, s: &str, c: [u8; 3]) {
    for (i, ch) in s.chars().enumerate() {
        for (row, bits) in glyph(ch).iter().enumerate() {
            for (col, b) in bits.bytes().enumerate() {
                if b != b'#' {
                    continue;
                }
                for dy in 0..SCALE {
                    for dx in 0..SCALE {
                        put(
                            img,
                            x + (i as u32 * CHAR_W + col as u32 * SCALE + dx) as i64,
                            y + (row as u32 * SCALE + dy) as i64,
                            c,
                        );
                    }
                }
            }
        }
    }
}

/// A line 2 pixels wide (Bresenham on both offsets); `dash` = on/off length in pixels.
fn line(img: &mut RgbImage, a: (f64, f64), b: (f64, f64), c: [u8; 3], dash: Option<u32>) {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let steps = dx.abs().max(dy.abs()).ceil().max(1.0) as u32;
    for k in 0..=steps {
        if let Some(d) = dash {
            // The dash phase follows the step count along the segment.
            if (k / d) % 2 == 1 {
                continue;
            }
        }
        let t = k as f64 / steps as f64;
        let (x, y) = ((a.0 + t * dx).round() as i64, (a.1 + t * dy).round() as i64);
        put(img, x, y, c);
        put(img, x + 1, y, c);
        put(img, x, y + 1, c);
    }
}

/// Draw panels side by side with a shared legend.
pub fn panels(panels: &[Panel], axes: &Axes, panel_w: u32, panel_h: u32) -> RgbImage {
    let margin_l = 70;
    let margin_r = 20;
    let margin_t = 40;
    let margin_b = 60;
    let legend_rows =
        panels.first().map_or(0, |p| p.series.len()) as u32 + u32::from(axes.reference.is_some());
    // One row for the value label, then two legend entries per row.
    let legend_h = (1 + legend_rows.div_ceil(2)) * (CHAR_H + 8) + 10;
    let w = panels.len() as u32 * (margin_l + panel_w + margin_r);
    let h = margin_t + panel_h + margin_b + legend_h;
    let mut img = RgbImage::from_pixel(w.max(1), h, Rgb([255, 255, 255]));
    let (x0r, x1r) = axes.x_range;
    let (y0r, y1r) = axes.y_range;
    for (pi, panel) in panels.iter().enumerate() {
        let ox = (pi as u32 * (margin_l + panel_w + margin_r) + margin_l) as f64;
        let oy = margin_t as f64;
        let (pw, ph) = (panel_w as f64, panel_h as f64);
        let px = |x: f64| ox + (x - x0r) / (x1r - x0r) * pw;
        let py = |y: f64| oy + ph - (y.clamp(y0r, y1r) - y0r) / (y1r - y0r) * ph;
        // Grid and ticks.
        for &t in &axes.y_ticks {
            line(&mut img, (ox, py(t)), (ox + pw, py(t)), GRID, None);
            let s = format!("{t}");
            text(
                &mut img,
                ox as i64 - 8 - text_width(&s) as i64,
                py(t) as i64 - (CHAR_H / 2) as i64,
                &s,
                INK,
            );
        }
        for &t in &axes.x_ticks {
            line(&mut img, (px(t), oy), (px(t), oy + ph), GRID, None);
            let s = format!("{t}");
            text(
                &mut img,
                px(t) as i64 - (text_width(&s) / 2) as i64,
                (oy + ph) as i64 + 8,
                &s,
                INK,
            );
        }
        if let Some((v, _)) = &axes.reference {
            line(
                &mut img,
                (ox, py(*v)),
                (ox + pw, py(*v)),
                [120, 120, 120],
                Some(6),
            );
        }
        // Frame.
        line(&mut img, (ox, oy), (ox + pw, oy), INK, None);
        line(&mut img, (ox, oy + ph), (ox + pw, oy + ph), INK, None);
        line(&mut img, (ox, oy), (ox, oy + ph), INK, None);
        line(&mut img, (ox + pw, oy), (ox + pw, oy + ph), INK, None);
        // Curves.
        for s in &panel.series {
            for seg in s.points.windows(2) {
                line(
                    &mut img,
                    (px(seg[0].0), py(seg[0].1)),
                    (px(seg[1].0), py(seg[1].1)),
                    s.colour,
                    s.dashed.then_some(5),
                );
            }
        }
        text(&mut img, ox as i64, 12, &panel.title, INK);
        text(
            &mut img,
            (ox + pw / 2.0) as i64 - (text_width(&axes.x_label) / 2) as i64,
            (oy + ph) as i64 + 30,
            &axes.x_label,
            INK,
        );
    }
    // The value axis' label opens the legend block (a rotated label would need rotated
    // glyphs).
    let ly = (margin_t + panel_h + margin_b) as i64;
    text(&mut img, 10, ly, &axes.y_label, INK);
    let mut entries: Vec<(String, [u8; 3], bool)> = panels
        .first()
        .map(|p| {
            p.series
                .iter()
                .map(|s| (s.label.clone(), s.colour, s.dashed))
                .collect()
        })
        .unwrap_or_default();
    if let Some((_, l)) = &axes.reference {
        entries.push((l.clone(), [120, 120, 120], true));
    }
    let col_w = w as i64 / 2;
    for (i, (label, c, dashed)) in entries.iter().enumerate() {
        let x = 10 + (i as i64 % 2) * col_w;
        let y = ly + (CHAR_H + 8) as i64 * (1 + i as i64 / 2);
        let yy = (y + CHAR_H as i64 / 2) as f64;
        line(
            &mut img,
            (x as f64 + 20.0, yy),
            (x as f64 + 60.0, yy),
            *c,
            dashed.then_some(5),
        );
        text(&mut img, x + 70, y, label, INK);
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_glyph_is_5_by_7() {
        for c in "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789%-.,:()/|+= ".chars() {
            for row in glyph(c) {
                assert_eq!(row.len(), 5, "{c:?}");
            }
        }
        // Lower case is drawn as upper case; unknown characters are blank.
        assert_eq!(glyph('a'), glyph('A'));
        assert!(glyph('~').iter().all(|r| r.trim().is_empty()));
    }

    #[test]
    fn curves_land_where_they_should() {
        let axes = Axes {
            x_range: (0.0, 10.0),
            x_ticks: vec![0.0, 10.0],
            x_label: "X".into(),
            y_range: (0.0, 10.0),
            y_ticks: vec![0.0, 10.0],
            y_label: "Y".into(),
            reference: Some((5.0, "REF".into())),
        };
        let red = [255, 0, 0];
        let p = Panel {
            title: "T".into(),
            series: vec![Series {
                label: "S".into(),
                colour: red,
                dashed: false,
                // The second point is above the axis: clipped to the top.
                points: vec![(0.0, 0.0), (5.0, 5.0), (10.0, 50.0)],
            }],
        };
        let img = panels(&[p], &axes, 100, 100);
        // Panel origin (70, 40); (5, 5) maps to (120, 90); (10, 50) to the top right.
        assert_eq!(img.get_pixel(120, 90).0, red);
        assert_eq!(img.get_pixel(169, 41).0, red);
        // The reference line is dashed grey at y = 90, left part.
        assert_eq!(img.get_pixel(72, 90).0, [120, 120, 120]);
    }
}
