//! Falsecolor map of one metric over the sensor grid's floor plan, as a PNG.
//!
//! Layout: the sensors' `x, y` (plan view, `+y` up, `+x` right; `z` is ignored) are placed on
//! a regular grid whose spacing in each axis is the smallest gap between distinct
//! coordinates (work-plane grids are regular); each sensor colours one square cell of
//! [`CELL`] pixels; cells without a sensor are light grey, a NaN value is mid grey. To the
//! right, a legend bar runs from the minimum (bottom) to the maximum (top) with both values
//! written beside it in a built-in 5x7 pixel font (digits, `.`, `-`, `e`, `+`; drawn at twice
//! the size): no font crate is needed for two numbers.
//!
//! Image size: width `M + nx*CELL + M + BAR + GAP + label + M`, height
//! `M + max(ny*CELL, MIN_BAR) + M`, with `M` = 8, `BAR` = 16, `GAP` = 4, `label` = 12 px per
//! character of the longer label, `MIN_BAR` = 64.
//!
//! Colour scale ([`ramp`]): piecewise linear through blue (0,0,255) at the minimum, cyan,
//! green, yellow, to **red (255,0,0) at the maximum**: higher values are redder, as in
//! Radiance's `falsecolor` default scale.

use crate::error::{Error, Result};
use image::{Rgb, RgbImage};

/// Pixels per sensor cell.
pub const CELL: u32 = 16;
const M: u32 = 8;
const BAR: u32 = 16;
const GAP: u32 = 4;
const MIN_BAR: u32 = 64;
const SCALE: u32 = 2;
const ADVANCE: u32 = 6 * SCALE;
/// At most this many cells (a guard against scattered, non-grid points).
pub const MAX_CELLS: u64 = 4_000_000;

const STOPS: [[f64; 3]; 5] = [
    [0.0, 0.0, 255.0],
    [0.0, 255.0, 255.0],
    [0.0, 255.0, 0.0],
    [255.0, 255.0, 0.0],
    [255.0, 0.0, 0.0],
];

/// Colour of a normalised value `t` in [0, 1] (clamped): blue at 0, red at 1.
pub fn ramp(t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (STOPS.len() - 1) as f64;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - i as f64;
    let c = |k: usize| (STOPS[i][k] + f * (STOPS[i + 1][k] - STOPS[i][k])).round() as u8;
    [c(0), c(1), c(2)]
}

/// 5x7 glyphs: 7 rows of 5 bits (bit 4 = leftmost column).
fn glyph(c: char) -> Option<[u8; 7]> {
    Some(match c {
        '0' => [0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E],
        '1' => [0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E],
        '2' => [0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F],
        '3' => [0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E],
        '4' => [0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02],
        '5' => [0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E],
        '6' => [0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E],
        '7' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E],
        '9' => [0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C],
        '.' => [0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C],
        '-' => [0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00],
        '+' => [0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00],
        'e' => [0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E],
        'n' => [0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11],
        'a' => [0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F],
        _ => return None,
    })
}

fn draw_text(img: &mut RgbImage, x0: u32, y0: u32, s: &str) {
    for (k, c) in s.chars().enumerate() {
        let Some(g) = glyph(c) else { continue };
        for (row, bits) in g.iter().enumerate() {
            for col in 0..5u32 {
                if bits & (0x10 >> col) == 0 {
                    continue;
                }
                for dy in 0..SCALE {
                    for dx in 0..SCALE {
                        let x = x0 + k as u32 * ADVANCE + col * SCALE + dx;
                        let y = y0 + row as u32 * SCALE + dy;
                        if x < img.width() && y < img.height() {
                            img.put_pixel(x, y, Rgb([0, 0, 0]));
                        }
                    }
                }
            }
        }
    }
}

/// A legend label: 4 significant digits, plain or with an exponent.
pub fn label(v: f64) -> String {
    if !v.is_finite() {
        return "nan".into();
    }
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e6).contains(&a) {
        return format!("{v:.2e}");
    }
    let decimals = if a >= 1000.0 {
        0
    } else if a >= 100.0 {
        1
    } else if a >= 10.0 {
        2
    } else {
        3
    };
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

fn spacing(vals: &mut Vec<f64>) -> f64 {
    vals.sort_by(f64::total_cmp);
    vals.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    vals.windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min)
        .min(f64::MAX)
}

/// Where each cell of the map lies: grid size and each sensor's cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    pub nx: u32,
    pub ny: u32,
    /// (column from the left, row from the bottom) per sensor.
    pub cells: Vec<(u32, u32)>,
}

/// Place sensors on their regular grid.
pub fn grid(points: &[[f64; 2]]) -> Result<Grid> {
    if points.is_empty() {
        return Err(Error::Usage("map: no sensor positions".into()));
    }
    if points
        .iter()
        .any(|p| !p[0].is_finite() || !p[1].is_finite())
    {
        return Err(Error::Usage("map: a sensor position is not finite".into()));
    }
    let mut xs: Vec<f64> = points.iter().map(|p| p[0]).collect();
    let mut ys: Vec<f64> = points.iter().map(|p| p[1]).collect();
    let (dx, dy) = (spacing(&mut xs), spacing(&mut ys));
    let (x0, y0) = (xs[0], ys[0]);
    let dx = if dx.is_finite() { dx } else { 1.0 };
    let dy = if dy.is_finite() { dy } else { 1.0 };
    let nx = ((xs[xs.len() - 1] - x0) / dx).round() + 1.0;
    let ny = ((ys[ys.len() - 1] - y0) / dy).round() + 1.0;
    if nx * ny > MAX_CELLS as f64 {
        return Err(Error::Usage(format!(
            "map: the sensor points do not lie on a regular grid ({nx} x {ny} cells at the \
             smallest spacings {dx} x {dy}); maps need a work-plane grid"
        )));
    }
    let cells = points
        .iter()
        .map(|p| {
            (
                ((p[0] - x0) / dx).round() as u32,
                ((p[1] - y0) / dy).round() as u32,
            )
        })
        .collect();
    Ok(Grid {
        nx: nx as u32,
        ny: ny as u32,
        cells,
    })
}

/// Render the map of `values` (one per point; NaN allowed) over `points` (x, y).
pub fn render(points: &[[f64; 2]], values: &[f64]) -> Result<RgbImage> {
    if points.len() != values.len() {
        return Err(Error::Mismatch(format!(
            "map: {} sensor positions but {} values (one matrix row per sensor)",
            points.len(),
            values.len()
        )));
    }
    let g = grid(points)?;
    let finite = values.iter().copied().filter(|v| v.is_finite());
    let lo = finite.clone().fold(f64::INFINITY, f64::min);
    let hi = finite.fold(f64::NEG_INFINITY, f64::max);
    let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 0.0) };
    let norm = |v: f64| if hi > lo { (v - lo) / (hi - lo) } else { 0.5 };
    let (lmin, lmax) = (label(lo), label(hi));
    let label_w = ADVANCE * lmin.len().max(lmax.len()) as u32;
    let (pw, ph) = (g.nx * CELL, g.ny * CELL);
    let bar_h = ph.max(MIN_BAR);
    let width = M + pw + M + BAR + GAP + label_w + M;
    let height = M + bar_h + M;
    let mut img = RgbImage::from_pixel(width, height, Rgb([255, 255, 255]));
    for cy in 0..g.ny {
        for cx in 0..g.nx {
            fill(
                &mut img,
                M + cx * CELL,
                M + cy * CELL,
                CELL,
                CELL,
                [230, 230, 230],
            );
        }
    }
    for (&(cx, cy), &v) in g.cells.iter().zip(values) {
        let colour = if v.is_finite() {
            ramp(norm(v))
        } else {
            [128, 128, 128]
        };
        // +y is up: row 0 of the grid is the bottom row of the picture.
        let top = M + (g.ny - 1 - cy) * CELL;
        fill(&mut img, M + cx * CELL, top, CELL, CELL, colour);
    }
    let bx = M + pw + M;
    for k in 0..bar_h {
        let t = 1.0 - k as f64 / (bar_h - 1).max(1) as f64;
        fill(&mut img, bx, M + k, BAR, 1, ramp(t));
    }
    let tx = bx + BAR + GAP;
    draw_text(&mut img, tx, M, &lmax);
    draw_text(&mut img, tx, M + bar_h - 7 * SCALE, &lmin);
    Ok(img)
}

fn fill(img: &mut RgbImage, x0: u32, y0: u32, w: u32, h: u32, c: [u8; 3]) {
    for y in y0..(y0 + h).min(img.height()) {
        for x in x0..(x0 + w).min(img.width()) {
            img.put_pixel(x, y, Rgb(c));
        }
    }
}

/// Encode as PNG bytes.
pub fn png_bytes(img: &RgbImage) -> Result<Vec<u8>> {
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(|e| Error::io("<png>", std::io::Error::other(e)))?;
    Ok(out.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_ends() {
        assert_eq!(ramp(0.0), [0, 0, 255]);
        assert_eq!(ramp(1.0), [255, 0, 0]);
        assert_eq!(ramp(0.5), [0, 255, 0]);
        assert_eq!(ramp(7.0), [255, 0, 0]);
    }

    #[test]
    fn labels() {
        assert_eq!(label(1234.56), "1235");
        assert_eq!(label(12.5), "12.5");
        assert_eq!(label(0.0), "0");
        assert_eq!(label(1.5e7), "1.50e7");
        for c in label(-0.001234).chars() {
            assert!(glyph(c).is_some(), "{c}");
        }
    }

    #[test]
    fn grid_and_orientation() {
        // 3 x 2 grid, 0.5 m spacing; the highest value at the top right (x max, y max).
        let pts = [
            [0.0, 0.0],
            [0.5, 0.0],
            [1.0, 0.0],
            [0.0, 0.5],
            [0.5, 0.5],
            [1.0, 0.5],
        ];
        let vals = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let img = render(&pts, &vals).unwrap();
        let label_w = ADVANCE;
        assert_eq!(img.width(), M + 3 * CELL + M + BAR + GAP + label_w + M);
        assert_eq!(img.height(), M + MIN_BAR + M);
        // top-right cell: red; bottom-left cell (row 1 of a 2-row plan): blue.
        assert_eq!(img.get_pixel(M + 2 * CELL + 8, M + 8).0, [255, 0, 0]);
        assert_eq!(img.get_pixel(M + 8, M + CELL + 8).0, [0, 0, 255]);
        // legend: red on top, blue at the bottom.
        let bx = M + 3 * CELL + M + 4;
        assert_eq!(img.get_pixel(bx, M).0, [255, 0, 0]);
        assert_eq!(img.get_pixel(bx, M + MIN_BAR - 1).0, [0, 0, 255]);
        assert!(render(&pts, &vals[..5]).is_err());
        assert!(grid(&[]).is_err());
    }
}
