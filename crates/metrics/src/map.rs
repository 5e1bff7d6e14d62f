//! The plan map of one metric over the sensor grid: a report-page figure (1200 x 900 px, PNG
//! or SVG through [`crate::plot`]).
//!
//! Plan view: `+x` right (east), `+y` up (north: Radiance's convention, `+Y` = north, as
//! `gendaylit`/`gendaymtx` place the sun); `z` is ignored. Each sensor colours one cell of
//! the grid's spacing centred on it (the spacing in each axis is the smallest gap between
//! distinct coordinates; work-plane grids are regular, scattered points are refused), its
//! point is a small dot, and with `values` its number is written in the cell. Around it:
//! the room outline from the scene ([`Plan`]: walls dark grey, windows blue), a north arrow,
//! a scale bar in metres, and to the right a colour bar on a **fixed** range ([`MapSpec::range`];
//! per-metric defaults in [`crate::config::metric_scale`], `--range LO,HI` overrides), so
//! that maps of different designs compare by colour. Values beyond the range take the end
//! colour and a triangle on that end of the bar says so. NaN cells are mid grey.
//!
//! Layout (pixels, origin top left): title at (40, 18), subtitle at (40, 58); plan inside
//! [`PLAN`] keeping 1 m = 1 m in both axes; colour bar [`BAR_X`]..`BAR_X + BAR_W`,
//! [`BAR_TOP`]..[`BAR_BOTTOM`] (value `lo` at the bottom row, `hi` at the top row); keys and
//! a footer line (scale, palette, north convention) at the bottom.

use crate::error::{Error, Result};
use crate::formats::scene::{Primitive, Scene};
use crate::plot::{self, Figure, Palette, draw_err, font, nice_step, tick_label};
use image::RgbImage;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Figure size.
pub const WIDTH: u32 = 1200;
pub const HEIGHT: u32 = 900;
/// Plan area: left, top, right, bottom.
pub const PLAN: (i32, i32, i32, i32) = (40, 100, 930, 800);
/// Colour bar.
pub const BAR_X: i32 = 990;
pub const BAR_W: i32 = 36;
pub const BAR_TOP: i32 = 150;
pub const BAR_BOTTOM: i32 = 750;
/// At most this many cells (a guard against scattered, non-grid points).
pub const MAX_CELLS: u64 = 4_000_000;

/// What one map shows and how.
#[derive(Debug, Clone, PartialEq)]
pub struct MapSpec {
    /// First line, e.g. `Daylight autonomy, DA (E >= 300 lx)`.
    pub title: String,
    /// Second line (study, occupancy, sensors).
    pub subtitle: String,
    /// Colour-bar caption: the quantity and its unit, e.g. `DA (%)`.
    pub unit: String,
    /// Colour-bar range (lo, hi), lo < hi.
    pub range: (f64, f64),
    /// Whether `range` is the metric's fixed documented scale (said in the footer).
    pub fixed: bool,
    pub palette: Palette,
    /// Write each sensor's value in its cell.
    pub values: bool,
    /// Decimals of written values.
    pub decimals: usize,
}

impl MapSpec {
    /// A map of unnamed values on the data's own range (rglod's and rmcop's error maps).
    pub fn auto(title: &str, unit: &str, values: &[f64]) -> MapSpec {
        let finite = values.iter().copied().filter(|v| v.is_finite());
        let lo = finite.clone().fold(f64::INFINITY, f64::min);
        let hi = finite.fold(f64::NEG_INFINITY, f64::max);
        let (lo, hi) = if lo.is_finite() && hi > lo {
            (lo, hi)
        } else if lo.is_finite() {
            (lo - 1.0, lo + 1.0)
        } else {
            (0.0, 1.0)
        };
        MapSpec {
            title: title.into(),
            subtitle: String::new(),
            unit: unit.into(),
            range: (lo, hi),
            fixed: false,
            palette: Palette::Viridis,
            values: false,
            decimals: 1,
        }
    }
}

/// The room outline in plan: wall and window segments (vertical surfaces projected onto the
/// floor plane) and horizontal glazing (skylights) as polygons.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Plan {
    pub walls: Vec<[[f64; 2]; 2]>,
    pub windows: Vec<[[f64; 2]; 2]>,
    pub skylights: Vec<Vec<[f64; 2]>>,
}

fn newell(v: &[[f64; 3]]) -> [f64; 3] {
    let mut n = [0.0; 3];
    for i in 0..v.len() {
        let (a, b) = (v[i], v[(i + 1) % v.len()]);
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 0.0 { n.map(|c| c / l) } else { n }
}

impl Plan {
    /// The outline of the scene's polygons near the sensors: a vertical polygon (normal within
    /// ~11 degrees of horizontal) becomes the segment between its extreme points along the
    /// wall; glazing ([`Scene::is_glazing`]) is a window, the rest a wall; a horizontal
    /// glazing polygon is a skylight. Only surfaces whose plan extent reaches within `margin`
    /// metres of the sensors' bounding box `near` count (neighbouring buildings and the
    /// ground plane do not frame the map). Other primitives (spheres, cones, meshes) are not
    /// drawn.
    pub fn from_scene(scene: &Scene, near: ([f64; 2], [f64; 2]), margin: f64) -> Plan {
        let (lo, hi) = near;
        let touches = |pts: &[[f64; 2]]| {
            let (mut a, mut b) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for p in pts {
                for k in 0..2 {
                    a[k] = a[k].min(p[k]);
                    b[k] = b[k].max(p[k]);
                }
            }
            (0..2).all(|k| a[k] <= hi[k] + margin && b[k] >= lo[k] - margin)
        };
        let mut plan = Plan::default();
        for (i, o) in scene.surfaces() {
            let Primitive::Polygon { vertices } = &o.kind else {
                continue;
            };
            if vertices.len() < 3 {
                continue;
            }
            let n = newell(vertices);
            let glazing = scene.is_glazing(i);
            let flat: Vec<[f64; 2]> = vertices.iter().map(|v| [v[0], v[1]]).collect();
            if n[2].abs() < 0.2 {
                // Along the wall: horizontal direction perpendicular to the normal.
                let d = [-n[1], n[0]];
                let along = |p: &[f64; 2]| p[0] * d[0] + p[1] * d[1];
                let a = flat
                    .iter()
                    .copied()
                    .min_by(|p, q| along(p).total_cmp(&along(q)));
                let b = flat
                    .iter()
                    .copied()
                    .max_by(|p, q| along(p).total_cmp(&along(q)));
                if let (Some(a), Some(b)) = (a, b) {
                    if touches(&[a, b]) {
                        if glazing {
                            plan.windows.push([a, b]);
                        } else {
                            plan.walls.push([a, b]);
                        }
                    }
                }
            } else if glazing && n[2].abs() > 0.8 && touches(&flat) {
                plan.skylights.push(flat);
            }
        }
        plan
    }

    fn points(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        self.walls
            .iter()
            .chain(&self.windows)
            .flat_map(|s| s.iter().copied())
            .chain(self.skylights.iter().flatten().copied())
    }
}

fn spacing(vals: &mut Vec<f64>) -> f64 {
    vals.sort_by(f64::total_cmp);
    vals.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
    vals.windows(2)
        .map(|w| w[1] - w[0])
        .fold(f64::INFINITY, f64::min)
}

/// Where each cell of the map lies: grid size, spacing and each sensor's cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    pub nx: u32,
    pub ny: u32,
    /// Spacing in x and y (metres).
    pub dx: f64,
    pub dy: f64,
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
    // A single row or column: square cells of the other axis' spacing (or 1 m).
    let (dx, dy) = match (dx.is_finite(), dy.is_finite()) {
        (true, true) => (dx, dy),
        (true, false) => (dx, dx),
        (false, true) => (dy, dy),
        (false, false) => (1.0, 1.0),
    };
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
        dx,
        dy,
        cells,
    })
}

/// A plan map ready to draw.
pub struct MapFigure<'a> {
    pub points: &'a [[f64; 2]],
    pub values: &'a [f64],
    pub spec: &'a MapSpec,
    pub plan: &'a Plan,
    grid: Grid,
}

impl<'a> MapFigure<'a> {
    /// Check the inputs (one value per point, a regular grid, a usable range).
    pub fn new(
        points: &'a [[f64; 2]],
        values: &'a [f64],
        spec: &'a MapSpec,
        plan: &'a Plan,
    ) -> Result<Self> {
        if points.len() != values.len() {
            return Err(Error::Mismatch(format!(
                "map: {} sensor positions but {} values (one matrix row per sensor)",
                points.len(),
                values.len()
            )));
        }
        let (lo, hi) = spec.range;
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(Error::Usage(format!(
                "--range: expected LO,HI with LO < HI, found {lo},{hi}"
            )));
        }
        let grid = grid(points)?;
        Ok(MapFigure {
            points,
            values,
            spec,
            plan,
            grid,
        })
    }

    /// Normalised position of `v` on the colour bar.
    pub fn norm(&self, v: f64) -> f64 {
        let (lo, hi) = self.spec.range;
        (v - lo) / (hi - lo)
    }

    /// World extent: sensors' cells and the outline, with a margin.
    fn extent(&self) -> ([f64; 2], [f64; 2]) {
        let (hx, hy) = (self.grid.dx / 2.0, self.grid.dy / 2.0);
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in self.points {
            lo = [lo[0].min(p[0] - hx), lo[1].min(p[1] - hy)];
            hi = [hi[0].max(p[0] + hx), hi[1].max(p[1] + hy)];
        }
        for p in self.plan.points() {
            lo = [lo[0].min(p[0]), lo[1].min(p[1])];
            hi = [hi[0].max(p[0]), hi[1].max(p[1])];
        }
        let m = 0.04 * (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-9);
        ([lo[0] - m, lo[1] - m], [hi[0] + m, hi[1] + m])
    }
}

type Px = (i32, i32);

fn stroke(c: RGBColor, w: u32) -> ShapeStyle {
    ShapeStyle {
        color: c.to_rgba(),
        filled: false,
        stroke_width: w,
    }
}

const WALL: RGBColor = RGBColor(60, 60, 60);
const WINDOW: RGBColor = RGBColor(30, 120, 230);
const NAN_GREY: RGBColor = RGBColor(150, 150, 150);

/// Draw a vertical colour bar for `palette` on `(lo, hi)` with ticks and a caption, and the
/// over/under-range triangles when `over`/`under`.
#[allow(clippy::too_many_arguments)]
pub fn colour_bar<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    palette: Palette,
    (lo, hi): (f64, f64),
    caption: &str,
    (x, top, w, bottom): (i32, i32, i32, i32),
    under: bool,
    over: bool,
) -> Result<()> {
    let h = bottom - top;
    for k in 0..h {
        let t = 1.0 - (k as f64 + 0.5) / h as f64;
        root.draw(&Rectangle::new(
            [(x, top + k), (x + w, top + k + 1)],
            palette.rgb(t).filled(),
        ))
        .map_err(draw_err)?;
    }
    root.draw(&Rectangle::new(
        [(x, top), (x + w, bottom)],
        stroke(BLACK, 1),
    ))
    .map_err(draw_err)?;
    if over {
        let c = palette.rgb(1.0).filled();
        root.draw(&Polygon::new(
            vec![(x, top - 2), (x + w, top - 2), (x + w / 2, top - 22)],
            c,
        ))
        .map_err(draw_err)?;
    }
    if under {
        let c = palette.rgb(0.0).filled();
        root.draw(&Polygon::new(
            vec![
                (x, bottom + 2),
                (x + w, bottom + 2),
                (x + w / 2, bottom + 22),
            ],
            c,
        ))
        .map_err(draw_err)?;
    }
    let step = nice_step(hi - lo, 5);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    let label = font(18.0).pos(Pos::new(HPos::Left, VPos::Center));
    for k in first..=last {
        let v = k as f64 * step;
        let y = bottom - ((v - lo) / (hi - lo) * h as f64).round() as i32;
        root.draw(&PathElement::new(
            vec![(x + w, y), (x + w + 8, y)],
            stroke(BLACK, 1),
        ))
        .map_err(draw_err)?;
        let mut s = tick_label(v, step);
        if over && k == last && (hi - v).abs() < 1e-9 * step.max(1.0) {
            s = format!("≥ {s}");
        }
        root.draw(&Text::new(s, (x + w + 12, y), label.clone()))
            .map_err(draw_err)?;
    }
    let cap = font(20.0).pos(Pos::new(HPos::Center, VPos::Bottom));
    root.draw(&Text::new(
        caption.to_string(),
        (x + w / 2 + 20, top - 30),
        cap,
    ))
    .map_err(draw_err)?;
    Ok(())
}

impl Figure for MapFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (WIDTH, HEIGHT)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let spec = self.spec;
        root.draw(&Text::new(spec.title.clone(), (40, 18), font(30.0)))
            .map_err(draw_err)?;
        if !spec.subtitle.is_empty() {
            root.draw(&Text::new(
                spec.subtitle.clone(),
                (40, 58),
                font(18.0).color(&RGBColor(70, 70, 70)),
            ))
            .map_err(draw_err)?;
        }
        // World -> pixels, 1 m the same in x and y, centred in the plan area.
        let (lo, hi) = self.extent();
        let (l, t, r, b) = PLAN;
        let s = ((r - l) as f64 / (hi[0] - lo[0])).min((b - t) as f64 / (hi[1] - lo[1]));
        let ox = l as f64 + ((r - l) as f64 - s * (hi[0] - lo[0])) / 2.0;
        let oy = t as f64 + ((b - t) as f64 - s * (hi[1] - lo[1])) / 2.0;
        let px = |p: [f64; 2]| -> Px {
            (
                (ox + (p[0] - lo[0]) * s).round() as i32,
                (oy + (hi[1] - p[1]) * s).round() as i32,
            )
        };
        // Cells.
        let (hx, hy) = (self.grid.dx / 2.0, self.grid.dy / 2.0);
        for (p, &v) in self.points.iter().zip(self.values) {
            let c = if v.is_finite() {
                spec.palette.rgb(self.norm(v))
            } else {
                NAN_GREY
            };
            let a = px([p[0] - hx, p[1] + hy]);
            let z = px([p[0] + hx, p[1] - hy]);
            root.draw(&Rectangle::new([a, z], c.filled()))
                .map_err(draw_err)?;
        }
        // Outline: walls, then windows over them, skylights.
        for w in &self.plan.walls {
            root.draw(&PathElement::new(vec![px(w[0]), px(w[1])], stroke(WALL, 4)))
                .map_err(draw_err)?;
        }
        for w in &self.plan.windows {
            root.draw(&PathElement::new(
                vec![px(w[0]), px(w[1])],
                stroke(WINDOW, 9),
            ))
            .map_err(draw_err)?;
        }
        for sk in &self.plan.skylights {
            let mut v: Vec<Px> = sk.iter().map(|&p| px(p)).collect();
            v.push(v[0]);
            root.draw(&PathElement::new(v, stroke(WINDOW, 4)))
                .map_err(draw_err)?;
        }
        // Sensors and values.
        let cell_w = self.grid.dx * s;
        let cell_h = self.grid.dy * s;
        let fs = (cell_w / 3.4).min(cell_h * 0.42).min(15.0);
        for (p, &v) in self.points.iter().zip(self.values) {
            let c = px(*p);
            if spec.values && fs >= 7.0 {
                let bg = if v.is_finite() {
                    spec.palette.colour(self.norm(v))
                } else {
                    [150, 150, 150]
                };
                let luma = 0.2126 * bg[0] as f64 + 0.7152 * bg[1] as f64 + 0.0722 * bg[2] as f64;
                let ink = if luma > 120.0 { BLACK } else { WHITE };
                let txt = if v.is_finite() {
                    format!("{v:.*}", spec.decimals)
                } else {
                    "nan".into()
                };
                let f = font(fs)
                    .color(&ink)
                    .pos(Pos::new(HPos::Center, VPos::Center));
                root.draw(&Text::new(txt, c, f)).map_err(draw_err)?;
            } else {
                root.draw(&Circle::new(c, 2, BLACK.mix(0.6).filled()))
                    .map_err(draw_err)?;
            }
        }
        // North arrow (north = +Y) in the plan area's top right corner.
        let (nx, ny) = (r - 30, t + 30);
        root.draw(&PathElement::new(
            vec![(nx, ny + 60), (nx, ny + 12)],
            stroke(BLACK, 3),
        ))
        .map_err(draw_err)?;
        root.draw(&Polygon::new(
            vec![(nx - 10, ny + 16), (nx + 10, ny + 16), (nx, ny - 4)],
            BLACK.filled(),
        ))
        .map_err(draw_err)?;
        root.draw(&Text::new(
            "N",
            (nx, ny - 8),
            font(22.0).pos(Pos::new(HPos::Center, VPos::Bottom)),
        ))
        .map_err(draw_err)?;
        // Scale bar: a round length near a quarter of the plan's width.
        let len = nice_step((hi[0] - lo[0]) / 4.0, 1);
        let (sx, sy) = (l + 10, b - 14);
        let sw = (len * s).round() as i32;
        root.draw(&Rectangle::new(
            [(sx, sy - 6), (sx + sw / 2, sy)],
            BLACK.filled(),
        ))
        .map_err(draw_err)?;
        root.draw(&Rectangle::new(
            [(sx + sw / 2, sy - 6), (sx + sw, sy)],
            stroke(BLACK, 1),
        ))
        .map_err(draw_err)?;
        let f = font(16.0).pos(Pos::new(HPos::Center, VPos::Bottom));
        root.draw(&Text::new("0", (sx, sy - 8), f.clone()))
            .map_err(draw_err)?;
        root.draw(&Text::new(
            format!("{} m", tick_label(len, len)),
            (sx + sw, sy - 8),
            f,
        ))
        .map_err(draw_err)?;
        // Colour bar.
        let finite = self.values.iter().copied().filter(|v| v.is_finite());
        let over = finite.clone().any(|v| v > spec.range.1);
        let under = finite.clone().any(|v| v < spec.range.0);
        colour_bar(
            root,
            spec.palette,
            spec.range,
            &spec.unit,
            (BAR_X, BAR_TOP, BAR_W, BAR_BOTTOM),
            under,
            over,
        )?;
        // Keys and footer.
        let ky = 835;
        let key = font(17.0).pos(Pos::new(HPos::Left, VPos::Center));
        root.draw(&PathElement::new(vec![(40, ky), (80, ky)], stroke(WALL, 4)))
            .map_err(draw_err)?;
        root.draw(&Text::new("wall", (88, ky), key.clone()))
            .map_err(draw_err)?;
        root.draw(&PathElement::new(
            vec![(150, ky), (190, ky)],
            stroke(WINDOW, 9),
        ))
        .map_err(draw_err)?;
        root.draw(&Text::new("window (glazing)", (198, ky), key.clone()))
            .map_err(draw_err)?;
        root.draw(&Circle::new((350, ky), 3, BLACK.filled()))
            .map_err(draw_err)?;
        let mut stats = vals_summary(self.values);
        stats.insert_str(0, "sensor  ");
        root.draw(&Text::new(stats, (362, ky), key.clone()))
            .map_err(draw_err)?;
        let scale = if spec.fixed { "fixed scale" } else { "scale" };
        let footer = format!(
            "{scale} {}–{} ({}); palette {}; north = +Y (Radiance: +X east, +Y north); \
             grid {} x {} m",
            tick_label(spec.range.0, nice_step(spec.range.1 - spec.range.0, 5)),
            tick_label(spec.range.1, nice_step(spec.range.1 - spec.range.0, 5)),
            if spec.fixed {
                "--range LO,HI to change"
            } else {
                "range of the data"
            },
            spec.palette.name(),
            tick_label(self.grid.dx, self.grid.dx / 10.0),
            tick_label(self.grid.dy, self.grid.dy / 10.0),
        );
        root.draw(&Text::new(
            footer,
            (40, 868),
            font(15.0).color(&RGBColor(70, 70, 70)),
        ))
        .map_err(draw_err)?;
        Ok(())
    }
}

/// `n = 165, min 1.2, median 4.5, max 9.9` of the finite values.
fn vals_summary(values: &[f64]) -> String {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return format!("n = {}, no finite value", values.len());
    }
    v.sort_by(f64::total_cmp);
    let med = if v.len() % 2 == 1 {
        v[v.len() / 2]
    } else {
        (v[v.len() / 2 - 1] + v[v.len() / 2]) / 2.0
    };
    let step = nice_step(v[v.len() - 1] - v[0], 50).clamp(0.01, 1.0);
    format!(
        "n = {}: min {}, median {}, max {}",
        values.len(),
        tick_label(v[0], step),
        tick_label(med, step),
        tick_label(v[v.len() - 1], step)
    )
}

/// Render the map of `values` over `points` with a title, the values' unit, the data's own
/// range and no outline (the quick maps of rglod and rmcop).
pub fn render(points: &[[f64; 2]], values: &[f64], title: &str, unit: &str) -> Result<RgbImage> {
    let spec = MapSpec::auto(title, unit, values);
    let plan = Plan::default();
    plot::to_image(&MapFigure::new(points, values, &spec, &plan)?)
}

/// Encode as PNG bytes.
pub fn png_bytes(img: &RgbImage) -> Result<Vec<u8>> {
    plot::png_bytes(img)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_spacing_and_cells() {
        let pts = [
            [0.0, 0.0],
            [0.5, 0.0],
            [1.0, 0.0],
            [0.0, 0.5],
            [0.5, 0.5],
            [1.0, 0.5],
        ];
        let g = grid(&pts).unwrap();
        assert_eq!((g.nx, g.ny, g.dx, g.dy), (3, 2, 0.5, 0.5));
        assert_eq!(g.cells[5], (2, 1));
        assert!(grid(&[]).is_err());
        // A single row: square cells.
        let g = grid(&pts[..3]).unwrap();
        assert_eq!((g.dx, g.dy), (0.5, 0.5));
    }

    #[test]
    fn orientation_bar_and_outline() {
        // 3 x 2 grid, highest value top right (x max, y max); fixed range 0..5.
        let pts = [
            [0.0, 0.0],
            [0.5, 0.0],
            [1.0, 0.0],
            [0.0, 0.5],
            [0.5, 0.5],
            [1.0, 0.5],
        ];
        let vals = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        let mut spec = MapSpec::auto("t", "u", &vals);
        spec.fixed = true;
        let plan = Plan {
            walls: vec![[[-0.25, -0.25], [1.25, -0.25]]],
            windows: vec![[[0.0, 0.75], [1.0, 0.75]]],
            skylights: vec![],
        };
        let fig = MapFigure::new(&pts, &vals, &spec, &plan).unwrap();
        let img = plot::to_image(&fig).unwrap();
        assert_eq!((img.width(), img.height()), (WIDTH, HEIGHT));
        // The colour bar: palette(0) at the bottom row, palette(1) at the top row.
        let mid = (BAR_X + BAR_W / 2) as u32;
        let near = |a: [u8; 3], b: [u8; 3]| a.iter().zip(b).all(|(x, y)| x.abs_diff(y) <= 2);
        assert!(near(
            img.get_pixel(mid, BAR_BOTTOM as u32 - 1).0,
            Palette::Viridis.colour(0.0)
        ));
        // Row BAR_TOP is the bar's frame.
        assert!(near(
            img.get_pixel(mid, BAR_TOP as u32 + 1).0,
            Palette::Viridis.colour(1.0)
        ));
        // Find the plan's cells: the brightest (yellow) pixel must lie right of and above
        // the darkest cell's.
        let (mut top_right, mut bottom_left) = (None, None);
        for y in PLAN.1 as u32..PLAN.3 as u32 {
            for x in PLAN.0 as u32..PLAN.2 as u32 {
                let p = img.get_pixel(x, y).0;
                if p == Palette::Viridis.colour(1.0) && top_right.is_none() {
                    top_right = Some((x, y));
                }
                if p == Palette::Viridis.colour(0.0) {
                    bottom_left = Some((x, y));
                }
            }
        }
        let (tr, bl) = (top_right.unwrap(), bottom_left.unwrap());
        assert!(tr.0 > bl.0 && tr.1 < bl.1, "{tr:?} {bl:?}");
        // The window's blue is drawn above the cells (y = 0.75 is north of them).
        let blue = img
            .enumerate_pixels()
            .filter(|(_, y, p)| *y < tr.1 && p.0 == [WINDOW.0, WINDOW.1, WINDOW.2])
            .count();
        assert!(blue > 100, "{blue}");
        assert!(MapFigure::new(&pts, &vals[..5], &spec, &plan).is_err());
        let mut bad = spec.clone();
        bad.range = (3.0, 3.0);
        assert!(MapFigure::new(&pts, &vals, &bad, &plan).is_err());
        // SVG: text is text, the title is there.
        let svg = plot::to_svg(&fig).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.contains("<text") && svg.contains("window (glazing)"),
            "{}",
            &svg[..200]
        );
    }

    #[test]
    fn plan_from_scene() {
        let text = "void plastic w 0 0 5 .5 .5 .5 0 0\nvoid glass g 0 0 3 .9 .9 .9\n\
            w polygon south 0 0 12 0 0 0 6 0 0 6 0 3 0 0 3\n\
            g polygon win 0 0 12 1 0 1 1 0 2 5 0 2 5 0 1\n\
            w polygon floor 0 0 12 0 0 0 6 0 0 6 8 0 0 8 0\n\
            w polygon far 0 0 12 50 0 0 50 9 0 50 9 3 50 0 3\n";
        let scene = crate::formats::scene::parse_str(
            text,
            "t.rad",
            std::path::Path::new(""),
            &Default::default(),
        )
        .unwrap();
        let plan = Plan::from_scene(&scene, ([0.5, 0.5], [5.5, 7.5]), 1.0);
        assert_eq!(plan.walls.len(), 1, "{plan:?}");
        assert_eq!(plan.windows.len(), 1);
        let w = plan.windows[0];
        let xs = [w[0][0].min(w[1][0]), w[0][0].max(w[1][0])];
        assert_eq!(xs, [1.0, 5.0]);
    }
}
