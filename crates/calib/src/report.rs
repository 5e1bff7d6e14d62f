//! # Reports: one-screen text, JSON, self-contained HTML with inline SVG
//!
//! The HTML report puts the figures of one or two comparisons (before/after) side by side,
//! followed by the explanation (ranked effects with parameters, uncertainty, error removed,
//! BIC change and evidence) when there is one. The JSON holds the same data as the figures.

use super::compare::Comparison;
use super::explain::Explanation;
use super::stats::Stats;
use super::svg::{Plot, Series, diverging, plan};
use serde::Serialize;

fn line(s: &Stats) -> String {
    format!(
        "MBE_rel {:+6.1} %  RMSE_rel {:5.1} %  sigma_rel {:5.1} %  r {:.3}  MAE {:.0} lx  (n = {})",
        s.mbe_rel, s.rmse_rel, s.sigma_rel, s.r, s.mae, s.n
    )
}

/// The one-screen summary of a comparison.
pub fn text_summary(c: &Comparison) -> String {
    let mut out = format!("{}\n  all readings: {}\n", c.label, line(&c.overall));
    let mut worst: Vec<_> = c.sensors.iter().collect();
    worst.sort_by(|a, b| b.stats.rmse_rel.total_cmp(&a.stats.rmse_rel));
    out += "  worst sensors (depth from window wall):\n";
    for s in worst.iter().take(5) {
        out += &format!(
            "    {:>8} {:5.1} m  MBE_rel {:+6.1} %  RMSE_rel {:5.1} %\n",
            s.id, s.depth, s.stats.mbe_rel, s.stats.rmse_rel
        );
    }
    let mut steps: Vec<_> = c.steps.iter().collect();
    steps.sort_by(|a, b| b.stats.rmse_rel.total_cmp(&a.stats.rmse_rel));
    out += "  worst time steps (sun altitude, Perez clearness):\n";
    for s in steps.iter().take(3) {
        out += &format!(
            "    {:>2}/{:<2} {:5.2} h  alt {:5.1}  eps {:4.1}  MBE_rel {:+6.1} %  RMSE_rel {:5.1} %\n",
            s.day, s.month, s.hour, s.sun_altitude, s.clearness, s.stats.mbe_rel, s.stats.rmse_rel
        );
    }
    out
}

/// The one-screen summary of an explanation.
pub fn explain_summary(e: &Explanation) -> String {
    let mut out = format!("model as given: {}\n", line(&e.base));
    out += "candidate effects (best first; dBIC < -10 is significant):\n";
    for c in &e.ranking {
        let u = c
            .uncertainty
            .map_or("n/a".to_string(), |u| format!("{u:.3}"));
        out += &format!(
            "  {:18} dBIC {:8.1}  RMSE_rel {:5.1} -> {:5.1} %  {} (+- {u})\n",
            c.family, c.delta_bic, c.rmse_before, c.rmse_after, c.spec
        );
    }
    out += &format!(
        "selected: {}\n",
        if e.specs.is_empty() {
            "none".to_string()
        } else {
            e.specs.join("  ")
        }
    );
    out += &format!("{}\n", e.verdict);
    out
}

fn figures(c: &Comparison) -> Vec<String> {
    let color = "#1f77b4".to_string();
    let mut figs = Vec::new();
    figs.push(
        Plot {
            title: format!("{}: measured vs simulated", c.label),
            xlabel: "measured (lx)".into(),
            ylabel: "simulated (lx)".into(),
            logx: true,
            logy: true,
            diagonal: true,
            zero_line: false,
        }
        .render(&[Series {
            points: c.scatter.iter().map(|p| (p.0, p.1)).collect(),
            color: color.clone(),
            line: false,
            label: format!("RMSE_rel {:.1} %, r {:.3}", c.overall.rmse_rel, c.overall.r),
        }]),
    );
    let rel = |f: &dyn Fn(&Comparison) -> Vec<(f64, f64)>, title: &str, x: &str| {
        Plot {
            title: title.to_string(),
            xlabel: x.to_string(),
            ylabel: "MBE_rel (%)".into(),
            logx: false,
            logy: false,
            diagonal: false,
            zero_line: true,
        }
        .render(&[Series {
            points: f(c),
            color: color.clone(),
            line: false,
            label: String::new(),
        }])
    };
    figs.push(rel(
        &|c| {
            c.sensors
                .iter()
                .map(|s| (s.depth, s.stats.mbe_rel))
                .collect()
        },
        "bias per sensor vs distance from the window wall",
        "distance from window wall (m)",
    ));
    figs.push(rel(
        &|c| {
            c.steps
                .iter()
                .map(|s| (s.sun_altitude, s.stats.mbe_rel))
                .collect()
        },
        "bias per time step vs sun altitude",
        "sun altitude (deg)",
    ));
    figs.push(rel(
        &|c| {
            c.steps
                .iter()
                .map(|s| (s.clearness, s.stats.mbe_rel))
                .collect()
        },
        "bias per time step vs sky clearness",
        "Perez clearness epsilon (1 overcast .. 12 clear)",
    ));
    figs.push(rel(
        &|c| {
            c.steps
                .iter()
                .enumerate()
                .map(|(i, s)| (i as f64, s.stats.mbe_rel))
                .collect()
        },
        "bias per time step in time order",
        "time step (in order)",
    ));
    let segs: Vec<([f64; 2], [f64; 2], &str)> = c
        .windows
        .iter()
        .map(|w| ([w[0], w[1]], [w[2], w[3]], "#2ca02c"))
        .collect();
    let marks: Vec<(f64, f64, String, String)> = c
        .sensors
        .iter()
        .map(|s| {
            (
                s.x,
                s.y,
                diverging(s.stats.mbe_rel),
                format!("{} {:+.0}%", s.id, s.stats.mbe_rel),
            )
        })
        .collect();
    figs.push(plan(
        "bias per sensor on the plan (blue low, red high; green: windows)",
        &segs,
        &marks,
    ));
    figs
}

/// The HTML report of one or two comparisons and an optional explanation.
pub fn html(comparisons: &[&Comparison], explanation: Option<&Explanation>) -> String {
    let mut h = String::from(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>rcalib report</title>\n\
         <style>body{font-family:sans-serif;margin:1em}table{border-collapse:collapse}\
         td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}\
         .row{display:flex;gap:1em}.col{flex:1}</style></head><body>\n\
         <h1>rcalib: model against measurements</h1>\n",
    );
    h += "<table><tr><th>model</th><th>n</th><th>MBE_rel %</th><th>RMSE_rel %</th><th>sigma_rel %</th><th>r</th><th>MAE lx</th></tr>\n";
    for c in comparisons {
        let s = &c.overall;
        h += &format!(
            "<tr><td style=\"text-align:left\">{}</td><td>{}</td><td>{:+.1}</td><td>{:.1}</td><td>{:.1}</td><td>{:.3}</td><td>{:.0}</td></tr>\n",
            esc(&c.label),
            s.n,
            s.mbe_rel,
            s.rmse_rel,
            s.sigma_rel,
            s.r,
            s.mae
        );
    }
    h += "</table>\n<p>MBE_rel, RMSE_rel, sigma_rel: seed Eq. 6.2-6.4 (simulated minus measured, relative to measured); MAE: Eq. 6.1.</p>\n";
    let figs: Vec<Vec<String>> = comparisons.iter().map(|c| figures(c)).collect();
    let nfig = figs.first().map_or(0, Vec::len);
    for k in 0..nfig {
        h += "<div class=\"row\">";
        for f in &figs {
            h += &format!("<div class=\"col\">{}</div>", f[k]);
        }
        h += "</div>\n";
    }
    if let Some(e) = explanation {
        h += &format!("<h2>Explain</h2>\n<p><b>{}</b></p>\n", esc(&e.verdict));
        h += "<table><tr><th>effect</th><th>apply as</th><th>parameter</th><th>value</th><th>+-</th><th>RMSE_rel before</th><th>after</th><th>dBIC</th><th style=\"text-align:left\">evidence</th></tr>\n";
        for c in &e.ranking {
            h += &format!(
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.3}</td><td>{}</td><td>{:.1}</td><td>{:.1}</td><td>{:.1}</td><td style=\"text-align:left\">{}</td></tr>\n",
                c.family,
                esc(&c.spec),
                c.parameter,
                c.value,
                c.uncertainty.map_or("n/a".into(), |u| format!("{u:.3}")),
                c.rmse_before,
                c.rmse_after,
                c.delta_bic,
                esc(&c.evidence)
            );
        }
        h += "</table>\n";
        if !e.specs.is_empty() {
            h += &format!(
                "<p>Selected (greedy forward selection): <code>{}</code></p>\n",
                e.specs
                    .iter()
                    .map(|s| format!("--effect {}", esc(s)))
                    .collect::<Vec<_>>()
                    .join(" ")
            );
        }
    }
    h + "</body></html>\n"
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The JSON document: comparisons and explanation.
#[derive(Serialize)]
pub struct Json<'a> {
    pub comparisons: Vec<&'a Comparison>,
    pub explanation: Option<&'a Explanation>,
}
