//! The other figures annual studies show beside the plan maps ([`crate::map`]), drawn with
//! the same font, palettes and outputs ([`crate::plot`]):
//!
//! - [`TemporalFigure`]: a temporal map (carpet plot), day of the year (x, 1 January at the
//!   left) by hour of the day (y, midnight at the bottom), each time step one cell coloured
//!   by a value (illuminance of the room median or of one sensor) on a fixed range, with
//!   the occupied hours marked by two dashed lines.
//! - [`CdfFigure`]: the distribution of a metric over the floor, as the share of sensors
//!   (= of the work plane on a regular grid) reaching **at least** each value: the curve a
//!   reader takes "x % of the floor has DA >= y" from.
//!
//! Both are 1200 x 700 px.

use crate::error::{Error, Result};
use crate::map::colour_bar;
use crate::plot::{Figure, Palette, draw_err, font, nice_step, tick_label};
use crate::schedule::{Stamp, day_of_year};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Size of the temporal map and the distribution.
pub const WIDTH: u32 = 1200;
pub const HEIGHT: u32 = 700;
/// Temporal map's plot area (left, top, right, bottom).
pub const CARPET: (i32, i32, i32, i32) = (90, 90, 1000, 610);

/// One value per time step, placed by its stamp.
pub struct TemporalFigure<'a> {
    pub title: String,
    pub subtitle: String,
    /// Colour-bar caption, e.g. `E (lx)`.
    pub unit: String,
    pub stamps: &'a [Stamp],
    pub values: &'a [f64],
    pub range: (f64, f64),
    pub palette: Palette,
    /// Occupied hours (start, end) to mark.
    pub occupied: Option<(f64, f64)>,
}

impl<'a> TemporalFigure<'a> {
    pub fn check(&self) -> Result<()> {
        if self.stamps.len() != self.values.len() {
            return Err(Error::Mismatch(format!(
                "temporal map: {} time stamps but {} values",
                self.stamps.len(),
                self.values.len()
            )));
        }
        let (lo, hi) = self.range;
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(Error::Usage(format!(
                "temporal map: range {lo},{hi} is not LO < HI"
            )));
        }
        Ok(())
    }
}

fn stroke(c: RGBColor, w: u32) -> ShapeStyle {
    ShapeStyle {
        color: c.to_rgba(),
        filled: false,
        stroke_width: w,
    }
}

const MONTHS: [&str; 12] = [
    "Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec",
];

impl Figure for TemporalFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (WIDTH, HEIGHT)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        self.check()?;
        root.draw(&Text::new(self.title.clone(), (40, 18), font(28.0)))
            .map_err(draw_err)?;
        root.draw(&Text::new(
            self.subtitle.clone(),
            (40, 54),
            font(17.0).color(&RGBColor(70, 70, 70)),
        ))
        .map_err(draw_err)?;
        let (l, t, r, b) = CARPET;
        let leap = self.stamps.iter().any(|s| s.month == 2 && s.day == 29);
        let ndays = if leap { 366.0 } else { 365.0 };
        let step = crate::schedule::step_hours(self.stamps);
        let dw = (r - l) as f64 / ndays;
        let hh = (b - t) as f64 / 24.0;
        root.draw(&Rectangle::new(
            [(l, t), (r, b)],
            RGBColor(235, 235, 235).filled(),
        ))
        .map_err(draw_err)?;
        let (lo, hi) = self.range;
        for (s, &v) in self.stamps.iter().zip(self.values) {
            let d = day_of_year(s.month, s.day, leap) as f64;
            // A step's stamp is its middle (gendaymtx and the weather file's convention).
            let h0 = s.hour - step / 2.0;
            let x0 = l as f64 + d * dw;
            let y1 = b as f64 - h0 * hh;
            let y0 = y1 - step * hh;
            let c = if v.is_finite() {
                self.palette.rgb((v - lo) / (hi - lo))
            } else {
                RGBColor(150, 150, 150)
            };
            root.draw(&Rectangle::new(
                [
                    (x0.floor() as i32, y0.floor() as i32),
                    ((x0 + dw).ceil() as i32, y1.ceil() as i32),
                ],
                c.filled(),
            ))
            .map_err(draw_err)?;
        }
        root.draw(&Rectangle::new([(l, t), (r, b)], stroke(BLACK, 1)))
            .map_err(draw_err)?;
        // Axes: months along x, hours along y.
        let lab = font(16.0).pos(Pos::new(HPos::Center, VPos::Top));
        let mut first = 0u32;
        for (m, name) in MONTHS.iter().enumerate() {
            let d = day_of_year(m as u8 + 1, 1, leap);
            let x = l + (d as f64 * dw).round() as i32;
            root.draw(&PathElement::new(
                vec![(x, b), (x, b + 6)],
                stroke(BLACK, 1),
            ))
            .map_err(draw_err)?;
            let next = if m == 11 {
                ndays as u32
            } else {
                day_of_year(m as u8 + 2, 1, leap)
            };
            let xm = l + (((d + next) as f64 / 2.0) * dw).round() as i32;
            root.draw(&Text::new(name.to_string(), (xm, b + 8), lab.clone()))
                .map_err(draw_err)?;
            first = first.max(d);
        }
        let ylab = font(16.0).pos(Pos::new(HPos::Right, VPos::Center));
        for h in (0..=24).step_by(3) {
            let y = b - (h as f64 * hh).round() as i32;
            root.draw(&PathElement::new(
                vec![(l - 6, y), (l, y)],
                stroke(BLACK, 1),
            ))
            .map_err(draw_err)?;
            root.draw(&Text::new(format!("{h}:00"), (l - 9, y), ylab.clone()))
                .map_err(draw_err)?;
        }
        if let Some((a, z)) = self.occupied {
            for h in [a, z] {
                let y = b - (h * hh).round() as i32;
                let mut x = l;
                while x < r {
                    root.draw(&PathElement::new(
                        vec![(x, y), ((x + 8).min(r), y)],
                        stroke(WHITE, 2),
                    ))
                    .map_err(draw_err)?;
                    x += 14;
                }
            }
        }
        root.draw(&Text::new(
            "day of the year",
            ((l + r) / 2, b + 34),
            font(17.0).pos(Pos::new(HPos::Center, VPos::Top)),
        ))
        .map_err(draw_err)?;
        root.draw(&Text::new(
            "hour (local standard time)",
            (22, (t + b) / 2),
            font(17.0)
                .transform(FontTransform::Rotate270)
                .pos(Pos::new(HPos::Center, VPos::Center)),
        ))
        .map_err(draw_err)?;
        let finite = self.values.iter().copied().filter(|v| v.is_finite());
        let over = finite.clone().any(|v| v > hi);
        let under = finite.clone().any(|v| v < lo);
        colour_bar(
            root,
            self.palette,
            self.range,
            &self.unit,
            (1050, t + 40, 32, b),
            under,
            over,
        )?;
        let note = match self.occupied {
            Some((a, z)) => format!(
                "dashed: occupied hours {}–{} h; grey: no step; fixed scale (--temporal-range); \
                 palette {}",
                tick_label(a, if a.fract() == 0.0 { 1.0 } else { 0.5 }),
                tick_label(z, if z.fract() == 0.0 { 1.0 } else { 0.5 }),
                self.palette.name()
            ),
            None => format!("grey: no step; palette {}", self.palette.name()),
        };
        root.draw(&Text::new(
            note,
            (40, 668),
            font(15.0).color(&RGBColor(70, 70, 70)),
        ))
        .map_err(draw_err)?;
        Ok(())
    }
}

/// The share of sensors reaching at least each value of one metric.
pub struct CdfFigure<'a> {
    pub title: String,
    pub subtitle: String,
    /// x-axis caption: metric and unit.
    pub unit: String,
    pub values: &'a [f64],
    /// x range (the metric's fixed scale).
    pub range: (f64, f64),
    /// Dotted reference lines at these values (e.g. sDA's 50 % DA criterion).
    pub marks: Vec<(f64, String)>,
}

/// `(value, share of sensors with at least that value in %)` steps of the finite values,
/// sorted by value: the exceedance curve.
pub fn exceedance(values: &[f64]) -> Vec<(f64, f64)> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    let n = v.len() as f64;
    v.iter()
        .enumerate()
        .map(|(i, &x)| (x, 100.0 * (n - i as f64) / n))
        .collect()
}

impl Figure for CdfFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (WIDTH, HEIGHT)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()> {
        let (lo, hi) = self.range;
        let pts = exceedance(self.values);
        if pts.is_empty() {
            return Err(Error::Usage("distribution: no finite value to plot".into()));
        }
        let xmax = hi.max(pts[pts.len() - 1].0);
        let xmin = lo.min(pts[0].0);
        let mut chart = ChartBuilder::on(root)
            .caption(self.title.clone(), font(28.0))
            .margin(30)
            .margin_bottom(45)
            .x_label_area_size(60)
            .y_label_area_size(80)
            .build_cartesian_2d(xmin..xmax, 0.0..100.0)
            .map_err(draw_err)?;
        let xs = nice_step(xmax - xmin, 10);
        chart
            .configure_mesh()
            .x_desc(self.unit.clone())
            .y_desc("share of sensors (floor) reaching at least x (%)")
            .axis_desc_style(font(18.0))
            .label_style(font(16.0))
            .x_labels(((xmax - xmin) / xs).round() as usize + 1)
            .x_label_formatter(&|v| tick_label(*v, xs))
            .y_label_formatter(&|v| tick_label(*v, 10.0))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(draw_err)?;
        // A step curve: at x just above a sensor's value, that sensor no longer counts.
        let mut line = vec![(xmin, 100.0)];
        for &(x, share) in &pts {
            line.push((x, share));
            line.push((x, share - 100.0 / pts.len() as f64));
        }
        line.push((xmax, 0.0_f64.max(line.last().map_or(0.0, |p| p.1))));
        chart
            .draw_series(LineSeries::new(line, stroke(RGBColor(31, 119, 180), 3)))
            .map_err(draw_err)?;
        for (x, label) in &self.marks {
            chart
                .draw_series(LineSeries::new(
                    vec![(*x, 0.0), (*x, 100.0)],
                    stroke(RGBColor(200, 60, 60), 2),
                ))
                .map_err(draw_err)?;
            chart
                .draw_series(std::iter::once(Text::new(
                    label.clone(),
                    (*x, 97.0),
                    font(16.0).color(&RGBColor(200, 60, 60)),
                )))
                .map_err(draw_err)?;
        }
        root.draw(&Text::new(
            self.subtitle.clone(),
            (40, 668),
            font(15.0).color(&RGBColor(70, 70, 70)),
        ))
        .map_err(draw_err)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot;

    #[test]
    fn exceedance_steps() {
        let e = exceedance(&[30.0, 10.0, f64::NAN, 20.0, 40.0]);
        assert_eq!(
            e,
            vec![(10.0, 100.0), (20.0, 75.0), (30.0, 50.0), (40.0, 25.0)]
        );
    }

    #[test]
    fn temporal_cells_land_by_day_and_hour() {
        // Two days: 1 January 12:30 (value hi) and 2 July 6:30 (value lo).
        let stamps = [
            Stamp {
                month: 1,
                day: 1,
                hour: 12.5,
            },
            Stamp {
                month: 7,
                day: 2,
                hour: 6.5,
            },
        ];
        let values = [1000.0, 0.0];
        let fig = TemporalFigure {
            title: "E".into(),
            subtitle: String::new(),
            unit: "E (lx)".into(),
            stamps: &stamps,
            values: &values,
            range: (0.0, 1000.0),
            palette: Palette::Viridis,
            occupied: None,
        };
        let img = plot::to_image(&fig).unwrap();
        let (l, t, r, b) = CARPET;
        let dw = (r - l) as f64 / 365.0;
        let hh = (b - t) as f64 / 24.0;
        let at = |day: f64, hour: f64| {
            img.get_pixel(
                (l as f64 + (day + 0.5) * dw) as u32,
                (b as f64 - hour * hh) as u32,
            )
            .0
        };
        assert_eq!(at(0.0, 12.5), Palette::Viridis.colour(1.0));
        assert_eq!(at(182.0, 6.5), Palette::Viridis.colour(0.0));
        assert_eq!(at(100.0, 12.5), [235, 235, 235]);
        let short = TemporalFigure {
            values: &values[..1],
            ..fig
        };
        assert!(short.check().is_err());
    }

    #[test]
    fn cdf_draws() {
        let fig = CdfFigure {
            title: "DA".into(),
            subtitle: "s".into(),
            unit: "DA (%)".into(),
            values: &[10.0, 50.0, 90.0],
            range: (0.0, 100.0),
            marks: vec![(50.0, "sDA criterion".into())],
        };
        let img = plot::to_image(&fig).unwrap();
        let blue = img.pixels().filter(|p| p.0 == [31, 119, 180]).count();
        assert!(blue > 500, "{blue}");
        assert!(plot::to_svg(&fig).unwrap().contains("sDA criterion"));
    }
}
