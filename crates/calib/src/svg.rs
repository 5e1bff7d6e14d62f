//! # A small SVG plot writer for the report
//!
//! Scatter/line plots with linear or log axes and a floor plan with coloured markers, as
//! self-contained `<svg>` text (no fonts to install, no external files: the HTML report
//! inlines them). Only what the report draws.

use rdaylight_metrics::html::escape as esc;

/// One set of points.
pub struct Series {
    pub points: Vec<(f64, f64)>,
    pub color: String,
    /// Join the points with a line (else markers only).
    pub line: bool,
    pub label: String,
}

/// A plot's axes and labels.
pub struct Plot {
    pub title: String,
    pub xlabel: String,
    pub ylabel: String,
    pub logx: bool,
    pub logy: bool,
    /// Draw y = x.
    pub diagonal: bool,
    /// Draw y = 0.
    pub zero_line: bool,
    /// Points the axes must include without being drawn: the other comparisons' points,
    /// so that before and after figures share their axes.
    pub frame: Vec<(f64, f64)>,
}

const W: f64 = 420.0;
const H: f64 = 300.0;
const L: f64 = 60.0;
const R: f64 = 15.0;
const T: f64 = 30.0;
const B: f64 = 45.0;

/// "Nice" tick values covering [lo, hi].
fn ticks(lo: f64, hi: f64, log: bool) -> Vec<f64> {
    if log {
        let (a, b) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        return (a..=b)
            .map(|e| 10f64.powi(e))
            .filter(|v| *v >= lo * 0.999 && *v <= hi * 1.001)
            .collect();
    }
    let span = (hi - lo).max(1e-12);
    let raw = span / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| span / s <= 6.0)
        .unwrap_or(10.0 * mag);
    let mut v = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while v <= hi + 1e-9 * span && out.len() < 20 {
        out.push(if v.abs() < 1e-12 * span { 0.0 } else { v });
        v += step;
    }
    out
}

fn fmt_tick(v: f64) -> String {
    if v != 0.0 && (v.abs() >= 1e5 || v.abs() < 1e-2) {
        format!("{v:.0e}")
    } else if v.fract() == 0.0 {
        format!("{v:.0}")
    } else {
        format!("{v}")
    }
}

/// Range of values with a margin (positive values only on log axes).
fn range(vals: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let v: Vec<f64> = vals
        .filter(|x| x.is_finite() && (!log || *x > 0.0))
        .collect();
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() {
        return if log { (1.0, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        (
            10f64.powf(lo.log10().floor()),
            10f64.powf(hi.log10().ceil().max(lo.log10().floor() + 1.0)),
        )
    } else {
        let pad = ((hi - lo) * 0.05).max(1e-9 + hi.abs() * 0.05);
        (lo - pad, hi + pad)
    }
}

impl Plot {
    /// The plot as an `<svg>` element.
    pub fn render(&self, series: &[Series]) -> String {
        let all = || {
            series
                .iter()
                .flat_map(|s| s.points.iter())
                .chain(self.frame.iter())
        };
        let (mut x0, mut x1) = range(all().map(|p| p.0), self.logx);
        let (mut y0, mut y1) = range(all().map(|p| p.1), self.logy);
        if self.diagonal {
            (x0, y0) = (x0.min(y0), x0.min(y0));
            (x1, y1) = (x1.max(y1), x1.max(y1));
        }
        if self.zero_line && !self.logy {
            y0 = y0.min(0.0);
            y1 = y1.max(0.0);
        }
        let tx = |x: f64| {
            let f = if self.logx {
                (x.max(x0).log10() - x0.log10()) / (x1.log10() - x0.log10())
            } else {
                (x - x0) / (x1 - x0)
            };
            L + f * (W - L - R)
        };
        let ty = |y: f64| {
            let f = if self.logy {
                (y.max(y0).log10() - y0.log10()) / (y1.log10() - y0.log10())
            } else {
                (y - y0) / (y1 - y0)
            };
            H - B - f * (H - T - B)
        };
        let mut s = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{W}\" height=\"{H}\" \
             viewBox=\"0 0 {W} {H}\" font-family=\"sans-serif\" font-size=\"11\">\n\
             <text x=\"{}\" y=\"18\" text-anchor=\"middle\" font-size=\"13\">{}</text>\n\
             <rect x=\"{L}\" y=\"{T}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#444\"/>\n",
            W / 2.0,
            esc(&self.title),
            W - L - R,
            H - T - B
        );
        for v in ticks(x0, x1, self.logx) {
            let x = tx(v);
            s += &format!(
                "<line x1=\"{x:.1}\" y1=\"{}\" x2=\"{x:.1}\" y2=\"{T}\" stroke=\"#ddd\"/>\
                 <text x=\"{x:.1}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n",
                H - B,
                H - B + 14.0,
                fmt_tick(v)
            );
        }
        for v in ticks(y0, y1, self.logy) {
            let y = ty(v);
            s += &format!(
                "<line x1=\"{L}\" y1=\"{y:.1}\" x2=\"{}\" y2=\"{y:.1}\" stroke=\"#ddd\"/>\
                 <text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>\n",
                W - R,
                L - 4.0,
                y + 4.0,
                fmt_tick(v)
            );
        }
        s += &format!(
            "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n\
             <text x=\"14\" y=\"{}\" text-anchor=\"middle\" transform=\"rotate(-90 14 {})\">{}</text>\n",
            (L + W - R) / 2.0,
            H - 8.0,
            esc(&self.xlabel),
            (T + H - B) / 2.0,
            (T + H - B) / 2.0,
            esc(&self.ylabel)
        );
        if self.diagonal {
            s += &format!(
                "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"#888\" stroke-dasharray=\"4 3\"/>\n",
                tx(x0),
                ty(x0),
                tx(x1),
                ty(x1)
            );
        }
        if self.zero_line && !self.logy {
            s += &format!(
                "<line x1=\"{L}\" y1=\"{:.1}\" x2=\"{}\" y2=\"{:.1}\" stroke=\"#888\"/>\n",
                ty(0.0),
                W - R,
                ty(0.0)
            );
        }
        for (k, ser) in series.iter().enumerate() {
            let pts: Vec<(f64, f64)> = ser
                .points
                .iter()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .filter(|p| (!self.logx || p.0 > 0.0) && (!self.logy || p.1 > 0.0))
                .map(|p| (tx(p.0), ty(p.1)))
                .collect();
            if ser.line && pts.len() > 1 {
                let d: Vec<String> = pts
                    .iter()
                    .map(|p| format!("{:.1},{:.1}", p.0, p.1))
                    .collect();
                s += &format!(
                    "<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.2\"/>\n",
                    d.join(" "),
                    ser.color
                );
            }
            for p in &pts {
                s += &format!(
                    "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"2.5\" fill=\"{}\" fill-opacity=\"0.7\"/>\n",
                    p.0, p.1, ser.color
                );
            }
            if !ser.label.is_empty() {
                s += &format!(
                    "<text x=\"{}\" y=\"{}\" fill=\"{}\">{}</text>\n",
                    L + 8.0,
                    T + 14.0 + 13.0 * k as f64,
                    ser.color,
                    esc(&ser.label)
                );
            }
        }
        s + "</svg>\n"
    }
}

/// Diverging colour for a relative error in percent (blue low, red high, grey near 0).
pub fn diverging(pct: f64) -> String {
    let t = (pct / 50.0).clamp(-1.0, 1.0);
    let (r, g, b) = if t < 0.0 {
        (1.0 + t, 1.0 + t * 0.6, 1.0)
    } else {
        (1.0, 1.0 - t * 0.8, 1.0 - t)
    };
    format!(
        "rgb({},{},{})",
        (r * 230.0) as u8,
        (g * 230.0) as u8,
        (b * 230.0) as u8
    )
}

/// A floor plan: `segments` (walls/windows, drawn as lines with a colour) and `markers`
/// (x, y, colour, label) in plan coordinates (x east, y north: Radiance's convention),
/// with a north arrow and a scale bar.
pub fn plan(
    title: &str,
    segments: &[([f64; 2], [f64; 2], &str)],
    markers: &[(f64, f64, String, String)],
) -> String {
    let xs = segments
        .iter()
        .flat_map(|s| [s.0[0], s.1[0]])
        .chain(markers.iter().map(|m| m.0));
    let ys = segments
        .iter()
        .flat_map(|s| [s.0[1], s.1[1]])
        .chain(markers.iter().map(|m| m.1));
    let (x0, x1) = range(xs, false);
    let (y0, y1) = range(ys, false);
    let scale = ((W - 40.0) / (x1 - x0)).min((H - 60.0) / (y1 - y0));
    let tx = |x: f64| 20.0 + (x - x0) * scale;
    let ty = |y: f64| H - 30.0 - (y - y0) * scale;
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{W}\" height=\"{H}\" \
         viewBox=\"0 0 {W} {H}\" font-family=\"sans-serif\" font-size=\"10\">\n\
         <text x=\"{}\" y=\"18\" text-anchor=\"middle\" font-size=\"13\">{}</text>\n",
        W / 2.0,
        esc(title)
    );
    for (a, b, c) in segments {
        s += &format!(
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{c}\" stroke-width=\"3\"/>\n",
            tx(a[0]),
            ty(a[1]),
            tx(b[0]),
            ty(b[1])
        );
    }
    for (x, y, c, label) in markers {
        s += &format!(
            "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"9\" fill=\"{c}\" stroke=\"#333\"/>\
             <text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>\n",
            tx(*x),
            ty(*y),
            tx(*x),
            ty(*y) + 21.0,
            esc(label)
        );
    }
    // North arrow (+y is north in Radiance scenes) in the top right corner.
    let (ax, ay) = (W - 18.0, 32.0);
    s += &format!(
        "<path d=\"M{ax} {ay} l-6 16 l6 -4 l6 4 z\" fill=\"#333\"/>\
         <text x=\"{ax}\" y=\"{}\" text-anchor=\"middle\" font-size=\"11\">N</text>\n",
        ay + 28.0
    );
    // Scale bar: the largest of 1, 2, 5, 10 ... m that fits in a quarter of the width.
    let mut len = 1.0_f64;
    for l in [0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0] {
        if l * scale <= W / 4.0 {
            len = l;
        }
    }
    let (bx, by) = (20.0, H - 8.0);
    s += &format!(
        "<path d=\"M{bx} {} v4 h{:.1} v-4\" fill=\"none\" stroke=\"#333\"/>\
         <text x=\"{:.1}\" y=\"{}\" font-size=\"10\">{len} m</text>\n",
        by - 4.0,
        len * scale,
        bx + len * scale + 4.0,
        by
    );
    s + "</svg>\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_cover_the_range() {
        assert_eq!(ticks(0.0, 10.0, false), vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        assert_eq!(ticks(10.0, 1000.0, true), vec![10.0, 100.0, 1000.0]);
        let svg = Plot {
            title: "a<b".into(),
            xlabel: "x".into(),
            ylabel: "y".into(),
            logx: true,
            logy: true,
            diagonal: true,
            zero_line: false,
            frame: Vec::new(),
        }
        .render(&[Series {
            points: vec![(10.0, 12.0), (100.0, 90.0), (-1.0, 5.0)],
            color: "red".into(),
            line: false,
            label: String::new(),
        }]);
        assert!(svg.contains("a&lt;b"));
        assert_eq!(
            svg.matches("<circle").count(),
            2,
            "non-positive points dropped on log axes"
        );
    }

    /// Frame points widen the axes without being drawn (before/after share axes).
    #[test]
    fn frame_points_set_the_axes_only() {
        let plot = |frame: Vec<(f64, f64)>| {
            Plot {
                title: "t".into(),
                xlabel: "x".into(),
                ylabel: "y".into(),
                logx: false,
                logy: false,
                diagonal: false,
                zero_line: false,
                frame,
            }
            .render(&[Series {
                points: vec![(1.0, 1.0), (2.0, 2.0)],
                color: "red".into(),
                line: false,
                label: String::new(),
            }])
        };
        let (plain, framed) = (plot(Vec::new()), plot(vec![(0.0, 40.0)]));
        assert_eq!(plain.matches("<circle").count(), 2);
        assert_eq!(framed.matches("<circle").count(), 2);
        assert!(
            !plain.contains(">40<") && framed.contains(">40<"),
            "{framed}"
        );
    }

    #[test]
    fn plans_have_a_north_arrow_and_a_scale_bar() {
        let svg = plan(
            "p",
            &[([0.0, 0.0], [4.0, 0.0], "#999")],
            &[(1.0, 1.0, "red".into(), "s1".into())],
        );
        assert!(svg.contains(">N</text>"));
        assert!(svg.contains(" m</text>"));
    }
}
