//! # Tables and figures of a study
//!
//! | file | what | seed |
//! |---|---|---|
//! | `cells.tsv` | per GLoD x MCoP cell: room TAI median, quartiles, 5/95 %, PE spread, MAPE, K2 and p, KS | Fig. 3.6, 3.8, 3.9, Appendix B |
//! | `sensors.tsv` | per cell and sensor: TAI median, quartiles, 5/95 %, MAPE | Fig. 3.10 |
//! | `convergence.tsv` | KS distance and p against the number of draws, every cell | Fig. 3.5 |
//! | `materials.tsv` | every varied material: property, value, bound, class | Fig. 3.2 |
//! | `results.json` | all of the above | |
//! | `boxplot.svg` | room TAI per cell: box = quartiles, whiskers = 5/95 %, dots beyond | Fig. 3.6 |
//! | `convergence.svg` | the KS curves of the top level's cells | Fig. 3.5 |
//! | `spread_GLoD{l}_s{sigma}.png` | per-sensor MAPE of TAI over the plan, top level | Fig. 3.10 |
//!
//! Every number is printed with a fixed number of decimals, so equal results give equal
//! bytes (what the shard merge test compares).

use crate::study::Results;
use rdaylight_base::{Error, Result};
use rdaylight_metrics::html::escape as esc;
use std::fmt::Write as _;

fn opt(v: Option<f64>, digits: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.digits$}"),
        _ => "NaN".into(),
    }
}

/// The seed-shaped cell table (TSV): what `rmcop study` prints.
pub fn cells_tsv(r: &Results) -> String {
    let hourly = r.cells.iter().any(|c| c.hourly.is_some());
    let mut s = String::from(
        "level\tsigma\tdraws\tfree_TAI_klxh\tTAI_median\tTAI_q25\tTAI_q75\tTAI_p5\tTAI_p95\tPE_median_%\tPE_p5_%\tPE_p95_%\tMAPE_%\tMAPE_vs_top_%\tK2\tp_normal\tKS_D",
    );
    if hourly {
        s += "\tUDIa_median_%\tDA_median_%\tsDA_median_%\tsDA_p5_%\tsDA_p95_%\tRMSE_A3_lx";
    }
    s.push('\n');
    for c in &r.cells {
        let t = &c.room_tai;
        let _ = write!(
            s,
            "GLoD{}\t{:.2}\t{}\t{:.3}\t{:.3}\t{:.3}\t{:.3}\t{:.3}\t{:.3}\t{:+.2}\t{:+.2}\t{:+.2}\t{:.2}\t{:.2}\t{}\t{}\t{}",
            c.level,
            c.sigma,
            t.n,
            c.free_room_tai,
            t.median,
            t.q25,
            t.q75,
            t.p5,
            t.p95,
            c.pe.median,
            c.pe.p5,
            c.pe.p95,
            c.mape,
            c.mape_vs_top,
            opt(c.normality.map(|n| n.k2), 3),
            opt(c.normality.map(|n| n.p), 4),
            opt(c.ks.map(|k| k.d), 4),
        );
        if let Some(h) = &c.hourly {
            let _ = write!(
                s,
                "\t{:.2}\t{:.2}\t{:.2}\t{:.2}\t{:.2}\t{:.2}",
                h.udi_a.median, h.da.median, h.sda.median, h.sda.p5, h.sda.p95, h.rmse_a3_lux
            );
        }
        s.push('\n');
    }
    s
}

/// Per cell and sensor (TSV).
pub fn sensors_tsv(r: &Results) -> String {
    let mut s = String::from(
        "level\tsigma\tsensor\tx\ty\tfree_TAI_klxh\tTAI_median\tTAI_q25\tTAI_q75\tTAI_p5\tTAI_p95\tMAPE_%\tUDIa_median_%\tDA_median_%\n",
    );
    for c in &r.sensors {
        let p = r.positions.get(c.sensor).copied().unwrap_or([f64::NAN; 2]);
        let _ = writeln!(
            s,
            "GLoD{}\t{:.2}\t{}\t{:.3}\t{:.3}\t{:.4}\t{:.4}\t{:.4}\t{:.4}\t{:.4}\t{:.4}\t{}\t{}\t{}",
            c.level,
            c.sigma,
            c.sensor,
            p[0],
            p[1],
            c.free_tai,
            c.tai.median,
            c.tai.q25,
            c.tai.q75,
            c.tai.p5,
            c.tai.p95,
            opt(Some(c.mape), 3),
            opt(c.udi_a.map(|u| u.median), 2),
            opt(c.da.map(|u| u.median), 2),
        );
    }
    s
}

/// KS convergence (TSV).
pub fn convergence_tsv(r: &Results) -> String {
    let mut s = String::from("level\tsigma\tdraws\tKS_D\tKS_p\n");
    for c in &r.cells {
        for k in &c.ks_curve {
            let _ = writeln!(
                s,
                "GLoD{}\t{:.2}\t{}\t{:.5}\t{:.5}",
                c.level, c.sigma, k.n, k.d, k.p
            );
        }
    }
    s
}

/// The varied materials (TSV).
pub fn materials_tsv(r: &Results) -> String {
    let mut s = String::from("level\tmaterial\tproperty\tvalue\tupper\tclass\n");
    for m in &r.materials {
        let p = &m.property;
        let _ = writeln!(
            s,
            "GLoD{}\t{}\t{:?}\t{:.4}\t{:.4}\t{}",
            m.level, p.name, p.kind, p.value, p.upper, p.class
        );
    }
    s
}

/// Everything as one JSON document.
pub fn json(r: &Results) -> Result<String> {
    serde_json::to_string_pretty(r).map_err(|e| Error::Usage(format!("results.json: {e}")))
}

/// Colours of the sigma classes (light to dark blue) and of levels' lines.
const PALETTE: [&str; 8] = [
    "#9ecae1", "#6baed6", "#3182bd", "#08519c", "#08306b", "#74c476", "#fd8d3c", "#969696",
];

/// A nice step for about `n` ticks over `span`.
fn tick_step(span: f64, n: f64) -> f64 {
    let raw = (span / n).max(1e-12);
    let mag = 10f64.powf(raw.log10().floor());
    let f = raw / mag;
    mag * if f < 1.5 {
        1.0
    } else if f < 3.5 {
        2.0
    } else if f < 7.5 {
        5.0
    } else {
        10.0
    }
}

/// Box plots of room TAI per cell (the seed's Fig. 3.6): levels along x, one box per sigma;
/// the box spans the quartiles with the median, whiskers reach the 5th and 95th percentiles,
/// the error-free model is a black tick per level.
pub fn boxplot_svg(r: &Results, draws_of: &dyn Fn(u8, f64) -> Vec<f64>) -> String {
    let (w, h, left, right, top, bottom) = (760.0, 420.0, 70.0, 20.0, 40.0, 60.0);
    let lo = r
        .cells
        .iter()
        .map(|c| c.room_tai.p5.min(c.free_room_tai))
        .fold(f64::INFINITY, f64::min);
    let hi = r
        .cells
        .iter()
        .map(|c| c.room_tai.p95.max(c.free_room_tai))
        .fold(f64::NEG_INFINITY, f64::max);
    let all: Vec<f64> = r
        .cells
        .iter()
        .flat_map(|c| draws_of(c.level, c.sigma))
        .collect();
    let lo = all.iter().copied().fold(lo, f64::min);
    let hi = all.iter().copied().fold(hi, f64::max);
    let pad = ((hi - lo) * 0.05).max(1e-9);
    let (lo, hi) = (lo - pad, hi + pad);
    let y = |v: f64| top + (h - top - bottom) * (1.0 - (v - lo) / (hi - lo));
    let nl = r.levels.len().max(1) as f64;
    let ns = r.sigmas.len().max(1) as f64;
    let group = (w - left - right) / nl;
    let bw = group * 0.8 / ns;
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<text x=\"{}\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">Room TAI per GLoD x MCoP ({} draws per cell): box = quartiles, whiskers = 5-95 %</text>\n",
        w / 2.0,
        r.draws
    );
    let step = tick_step(hi - lo, 6.0);
    let mut t = (lo / step).ceil() * step;
    while t <= hi {
        let _ = writeln!(
            s,
            "<line x1=\"{left}\" x2=\"{}\" y1=\"{y:.1}\" y2=\"{y:.1}\" stroke=\"#ddd\"/><text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>",
            w - right,
            left - 6.0,
            y(t) + 4.0,
            t,
            y = y(t)
        );
        t += step;
    }
    let _ = writeln!(
        s,
        "<text transform=\"translate(18 {}) rotate(-90)\" text-anchor=\"middle\">room TAI (klx h)</text>",
        (top + h - bottom) / 2.0
    );
    for (li, &level) in r.levels.iter().enumerate() {
        let gx = left + group * li as f64 + group * 0.1;
        for (si, &sigma) in r.sigmas.iter().enumerate() {
            let Some(c) = r
                .cells
                .iter()
                .find(|c| c.level == level && c.sigma == sigma)
            else {
                continue;
            };
            let x0 = gx + bw * si as f64 + bw * 0.1;
            let x1 = x0 + bw * 0.8;
            let xm = (x0 + x1) / 2.0;
            let t = &c.room_tai;
            let col = PALETTE[si % 5];
            let _ = writeln!(
                s,
                "<line x1=\"{xm:.1}\" x2=\"{xm:.1}\" y1=\"{:.1}\" y2=\"{:.1}\" stroke=\"#333\"/>\
                 <rect x=\"{x0:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"{col}\" stroke=\"#333\"/>\
                 <line x1=\"{x0:.1}\" x2=\"{x1:.1}\" y1=\"{:.1}\" y2=\"{:.1}\" stroke=\"black\" stroke-width=\"2\"/>",
                y(t.p95),
                y(t.p5),
                y(t.q75),
                x1 - x0,
                (y(t.q25) - y(t.q75)).max(0.5),
                y(t.median),
                y(t.median)
            );
            for v in draws_of(level, sigma) {
                if v < t.p5 || v > t.p95 {
                    let _ = writeln!(
                        s,
                        "<circle cx=\"{xm:.1}\" cy=\"{:.1}\" r=\"1.5\" fill=\"#555\" fill-opacity=\"0.4\"/>",
                        y(v)
                    );
                }
            }
        }
        if let Some(c) = r.cells.iter().find(|c| c.level == level) {
            let _ = writeln!(
                s,
                "<line x1=\"{:.1}\" x2=\"{:.1}\" y1=\"{:.1}\" y2=\"{:.1}\" stroke=\"black\" stroke-dasharray=\"4 2\"/>",
                gx,
                gx + group * 0.8,
                y(c.free_room_tai),
                y(c.free_room_tai)
            );
        }
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{}\" text-anchor=\"middle\">GLoD{level}</text>",
            gx + group * 0.4,
            h - bottom + 18.0
        );
    }
    for (si, &sigma) in r.sigmas.iter().enumerate() {
        let x = left + 10.0 + 110.0 * si as f64;
        let _ = writeln!(
            s,
            "<rect x=\"{x}\" y=\"{}\" width=\"12\" height=\"12\" fill=\"{}\" stroke=\"#333\"/><text x=\"{}\" y=\"{}\">MCoP {sigma:.2}</text>",
            h - 24.0,
            PALETTE[si % 5],
            x + 16.0,
            h - 14.0
        );
    }
    let _ = writeln!(
        s,
        "<line x1=\"{}\" x2=\"{}\" y1=\"{}\" y2=\"{}\" stroke=\"black\" stroke-dasharray=\"4 2\"/><text x=\"{}\" y=\"{}\">error-free model</text>",
        w - 200.0,
        w - 170.0,
        h - 18.0,
        h - 18.0,
        w - 165.0,
        h - 14.0
    );
    s + "</svg>\n"
}

/// The KS convergence curves (Fig. 3.5) of `level`'s cells.
pub fn convergence_svg(r: &Results, level: u8) -> String {
    let (w, h, left, right, top, bottom) = (640.0, 380.0, 60.0, 20.0, 40.0, 50.0);
    let cells: Vec<_> = r.cells.iter().filter(|c| c.level == level).collect();
    let nmax = cells
        .iter()
        .flat_map(|c| c.ks_curve.iter().map(|k| k.n))
        .max()
        .unwrap_or(10) as f64;
    let dmax = cells
        .iter()
        .flat_map(|c| c.ks_curve.iter().map(|k| k.d))
        .fold(0.0, f64::max)
        .max(1e-6)
        * 1.1;
    let x = |n: f64| left + (w - left - right) * n / nmax;
    let y = |d: f64| top + (h - top - bottom) * (1.0 - d / dmax);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<text x=\"{}\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">GLoD{level}: KS distance of the PE to its fitted normal vs draws</text>\n",
        w / 2.0
    );
    let step = tick_step(dmax, 5.0);
    let mut t = 0.0;
    while t <= dmax {
        let _ = writeln!(
            s,
            "<line x1=\"{left}\" x2=\"{}\" y1=\"{:.1}\" y2=\"{:.1}\" stroke=\"#ddd\"/><text x=\"{}\" y=\"{:.1}\" text-anchor=\"end\">{}</text>",
            w - right,
            y(t),
            y(t),
            left - 6.0,
            y(t) + 4.0,
            esc(&format!("{t:.3}"))
        );
        t += step;
    }
    let nstep = tick_step(nmax, 6.0);
    let mut n = 0.0;
    while n <= nmax {
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{}\" text-anchor=\"middle\">{n}</text>",
            x(n),
            h - bottom + 16.0
        );
        n += nstep;
    }
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">draws</text>",
        (left + w - right) / 2.0,
        h - 8.0
    );
    for (i, c) in cells.iter().enumerate() {
        let pts: Vec<String> = c
            .ks_curve
            .iter()
            .map(|k| format!("{:.1},{:.1}", x(k.n as f64), y(k.d)))
            .collect();
        let col = PALETTE[i % 5];
        let _ = writeln!(
            s,
            "<polyline fill=\"none\" stroke=\"{col}\" stroke-width=\"1.5\" points=\"{}\"/><text x=\"{}\" y=\"{}\" fill=\"{col}\">MCoP {:.2}</text>",
            pts.join(" "),
            w - right - 90.0,
            top + 16.0 * (i as f64 + 1.0),
            c.sigma
        );
    }
    s + "</svg>\n"
}

/// The per-sensor MAPE of TAI (%) of one cell over the plan (Fig. 3.10), a PNG.
pub fn spread_png(r: &Results, level: u8, sigma: f64) -> Result<Vec<u8>> {
    let values: Vec<f64> = r
        .sensors
        .iter()
        .filter(|c| c.level == level && c.sigma == sigma)
        .map(|c| c.mape)
        .collect();
    let img = rdaylight_metrics::map::render(
        &r.positions,
        &values,
        &format!("Spread of TAI per sensor: GLoD{level}, MCoP sigma {sigma}"),
        "MAPE (%)",
    )?;
    rdaylight_metrics::map::png_bytes(&img)
}
