//! # Reports: one-screen text, JSON, self-contained HTML with inline SVG
//!
//! The HTML report puts the figures of one or two comparisons (before/after) side by side,
//! followed by the explanation (ranked effects with parameters, uncertainty, error removed,
//! BIC change and evidence) when there is one. The JSON holds the same data as the figures.

use super::compare::Comparison;
use super::explain::Explanation;
use super::stats::Stats;
use super::svg::{Plot, Series, diverging, plan};
use rdaylight_metrics::html::escape as esc;
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

/// How effects are kept, in the words the reports use.
pub const SELECTION_RULE: &str = "Each candidate is first fitted alone to the model as given \
     (the table's RMSE_rel and dBIC). Selection is greedy: the best candidate is kept when it \
     lowers the BIC by more than 10 (strong evidence, Kass & Raftery 1995) and removes at least \
     30 % of the squared error; the other families are then fitted again on top of it and the \
     next is kept only if it passes the same test. Candidates that explain the same residual \
     (an obstruction and a darker glazing both dim the back of the room) therefore drop out \
     once one of them is kept, even though each was significant alone. Kept effects are \
     re-fitted together, then refined against a re-simulation of the model with them applied, \
     so their parameters differ from the single fits.";

/// The one-screen summary of an explanation.
pub fn explain_summary(e: &Explanation) -> String {
    let mut out = format!("model as given: {}\n", line(&e.base));
    out += "candidate effects, each fitted alone (best first; kept only if dBIC < -10 and \
            >= 30 % less squared error on top of those kept before):\n";
    for c in &e.ranking {
        let u = c
            .uncertainty
            .map_or("n/a".to_string(), |u| format!("{u:.3}"));
        out += &format!(
            "  {:18} dBIC {:8.1}  RMSE_rel {:5.1} -> {:5.1} %  {} (+- {u})\n",
            c.family, c.delta_bic, c.rmse_before, c.rmse_after, c.params
        );
    }
    if e.selected.is_empty() {
        out += "selected: none\n";
    } else {
        out += "selected, re-fitted together:\n";
        for c in &e.selected {
            let u = c
                .uncertainty
                .map_or("n/a".to_string(), |u| format!("{u:.3}"));
            out += &format!(
                "  {:18} {} (+- {u})  --effect {}\n",
                c.family, c.params, c.spec
            );
        }
    }
    out += &format!("{}\n", e.verdict);
    out
}

/// The scatter and bias figures of one comparison, before rendering: (plot, series).
fn plots(c: &Comparison) -> Vec<(Plot, Vec<Series>)> {
    let color = "#1f77b4".to_string();
    let mut figs = vec![(
        Plot {
            title: format!("{}: measured vs simulated", c.label),
            xlabel: "measured (lx)".into(),
            ylabel: "simulated (lx)".into(),
            logx: true,
            logy: true,
            diagonal: true,
            zero_line: false,
            frame: Vec::new(),
        },
        vec![Series {
            points: c.scatter.iter().map(|p| (p.0, p.1)).collect(),
            color: color.clone(),
            line: false,
            label: format!("RMSE_rel {:.1} %, r {:.3}", c.overall.rmse_rel, c.overall.r),
        }],
    )];
    let rel = |points: Vec<(f64, f64)>, title: &str, x: &str| {
        (
            Plot {
                title: title.to_string(),
                xlabel: x.to_string(),
                ylabel: "MBE_rel (%)".into(),
                logx: false,
                logy: false,
                diagonal: false,
                zero_line: true,
                frame: Vec::new(),
            },
            vec![Series {
                points,
                color: color.clone(),
                line: false,
                label: String::new(),
            }],
        )
    };
    figs.push(rel(
        c.sensors
            .iter()
            .map(|s| (s.depth, s.stats.mbe_rel))
            .collect(),
        "bias per sensor vs distance from the window wall",
        "distance from window wall (m)",
    ));
    figs.push(rel(
        c.steps
            .iter()
            .map(|s| (s.sun_altitude, s.stats.mbe_rel))
            .collect(),
        "bias per time step vs sun altitude",
        "sun altitude (deg)",
    ));
    figs.push(rel(
        c.steps
            .iter()
            .map(|s| (s.clearness, s.stats.mbe_rel))
            .collect(),
        "bias per time step vs sky clearness",
        "Perez clearness epsilon (1 overcast .. 12 clear)",
    ));
    figs.push(rel(
        c.steps
            .iter()
            .enumerate()
            .map(|(i, s)| (i as f64, s.stats.mbe_rel))
            .collect(),
        "bias per time step in time order",
        "time step (in order)",
    ));
    figs
}

/// The bias of each sensor on the floor plan, with the room's outline and windows.
fn plan_figure(c: &Comparison) -> String {
    let mut segs: Vec<([f64; 2], [f64; 2], &str)> = c
        .outline
        .iter()
        .map(|e| ([e[0], e[1]], [e[2], e[3]], "#999"))
        .collect();
    segs.extend(
        c.windows
            .iter()
            .map(|w| ([w[0], w[1]], [w[2], w[3]], "#2ca02c")),
    );
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
    plan(
        "bias per sensor (blue low, red high); green: windows",
        &segs,
        &marks,
    )
}

/// The figures of every comparison, figure by figure (row k: figure k of each comparison),
/// each figure's axes shared by the comparisons so that before and after read alike.
fn figures(comparisons: &[&Comparison]) -> Vec<Vec<String>> {
    let mut all: Vec<Vec<(Plot, Vec<Series>)>> = comparisons.iter().map(|c| plots(c)).collect();
    let nfig = all.first().map_or(0, Vec::len);
    let mut rows = Vec::new();
    for k in 0..nfig {
        let frame: Vec<(f64, f64)> = all
            .iter()
            .flat_map(|f| f[k].1.iter().flat_map(|s| s.points.iter().copied()))
            .collect();
        rows.push(
            all.iter_mut()
                .map(|f| {
                    f[k].0.frame = frame.clone();
                    f[k].0.render(&f[k].1)
                })
                .collect(),
        );
    }
    rows.push(comparisons.iter().map(|c| plan_figure(c)).collect());
    rows
}

/// The HTML report of one or two comparisons and an optional explanation, on the shared
/// report frame (`rdaylight_metrics::html`: header, navigation, sections, provenance).
/// `inputs`: the files the comparison read (listed with their SHA-256).
pub fn html(
    comparisons: &[&Comparison],
    explanation: Option<&Explanation>,
    inputs: &[String],
) -> crate::error::Result<String> {
    use rdaylight_metrics::html::{Page, provenance, table};
    let title = match explanation {
        Some(_) => "rcalib explain: which effect the model is missing",
        None if comparisons.len() > 1 => "rcalib compare: the model before and after",
        None => "rcalib compare: model against measurements",
    };
    let mut page = Page::new(
        title,
        &comparisons
            .iter()
            .map(|c| c.label.clone())
            .collect::<Vec<_>>()
            .join(" | "),
    );
    let rows: Vec<Vec<String>> = comparisons
        .iter()
        .map(|c| {
            let s = &c.overall;
            vec![
                c.label.clone(),
                s.n.to_string(),
                format!("{:+.1}", s.mbe_rel),
                format!("{:.1}", s.rmse_rel),
                format!("{:.1}", s.sigma_rel),
                format!("{:.3}", s.r),
                format!("{:.0}", s.mae),
            ]
        })
        .collect();
    let mut h = table(
        &[
            "model",
            "n",
            "MBE_rel %",
            "RMSE_rel %",
            "sigma_rel %",
            "r",
            "MAE lx",
        ],
        &rows,
        &[1, 2, 3, 4, 5, 6],
    );
    h += "\n<p>Per reading, the relative error is <i>e</i> = (<i>s</i> - \
          <i>m</i>) / <i>m</i> (simulated <i>s</i>, measured <i>m</i>; readings under 1 lx are \
          left out). MBE_rel = 100 mean(<i>e</i>), the bias; RMSE_rel = 100 \
          &radic;mean(<i>e</i>&sup2;), the whole error; sigma_rel = 100 std(<i>e</i>), the \
          scatter left once the bias is removed; MAE = mean |<i>s</i> - <i>m</i>| in lux; r: \
          Pearson's correlation of <i>s</i> and <i>m</i>. These are Eqs. 6.1-6.4 of the seed, \
          the dissertation this project grew from (N. Forouzandeh, <i>Modelling Daylight for \
          Existing Indoor Spaces</i>, TU Delft, 2026, chapter 6).</p>\n";
    page.section("errors", "Errors", &h);
    let mut h = String::new();
    for row in figures(comparisons) {
        h += "<div class=\"grid\">";
        for f in row {
            h += &format!("<figure>{f}</figure>");
        }
        h += "</div>\n";
    }
    page.section("figures", "Where the model fails", &h);
    if let Some(e) = explanation {
        let mut h = format!("<p><b>{}</b></p>\n", esc(&e.verdict));
        if !e.selected.is_empty() {
            h += "<h3>Selected effects (re-fitted together)</h3>\n<table><tr><th>effect</th>\
                  <th style=\"text-align:left\">parameters</th><th>+- (first)</th>\
                  <th style=\"text-align:left\">what it means</th></tr>\n";
            for c in &e.selected {
                h += &format!(
                    "<tr><td>{}</td><td style=\"text-align:left\">{}</td><td>{}</td>\
                     <td style=\"text-align:left\">{}</td></tr>\n",
                    c.family,
                    esc(&c.params),
                    c.uncertainty.map_or("n/a".into(), |u| format!("{u:.3}")),
                    esc(&c.description)
                );
            }
            h += &format!(
                "</table>\n<p>Model with them: RMSE_rel {:.1} % as predicted (the daylight-coefficient \
                 model, corrected towards a re-simulation of the model with these effects; \
                 the second column of figures above). The fully re-simulated value is in the \
                 report of <code>rcalib compare</code> after <code>rcalib apply</code>. Apply with <code>rcalib apply MODEL --sensors \
                 SENSORS {}</code>, then compare the calibrated model with the same readings.</p>\n",
                e.final_stats.rmse_rel,
                e.specs
                    .iter()
                    .map(|s| format!("--effect {}", esc(s)))
                    .collect::<Vec<_>>()
                    .join(" ")
            );
        }
        h += "<h3>Candidates, each fitted alone to the model as given</h3>\n";
        h += "<table><tr><th>effect</th><th style=\"text-align:left\">parameters</th><th>+- (first)</th><th>RMSE_rel before %</th><th>after %</th><th>dBIC</th><th style=\"text-align:left\">evidence</th></tr>\n";
        for c in &e.ranking {
            h += &format!(
                "<tr><td>{}</td><td style=\"text-align:left\">{}</td><td>{}</td><td>{:.1}</td><td>{:.1}</td><td>{:.1}</td><td style=\"text-align:left\">{}</td></tr>\n",
                c.family,
                esc(&c.params),
                c.uncertainty.map_or("n/a".into(), |u| format!("{u:.3}")),
                c.rmse_before,
                c.rmse_after,
                c.delta_bic,
                esc(&c.evidence)
            );
        }
        h += &format!("</table>\n<p>{}</p>\n", esc(SELECTION_RULE));
        page.section("explain", "Explain", &h);
    } else if comparisons.len() == 1 {
        let h = "<p>To learn which physical effect the model is missing, run \
              <code>rcalib explain</code> with the same arguments and <code>--report \
              explain.html --effects-out effects.txt</code>; then <code>rcalib apply MODEL \
              --sensors SENSORS $(cat effects.txt) &gt; calibrated.rad</code> and <code>rcalib \
              compare calibrated.rad --before MODEL ...</code> to see the error fall. A residual \
              at the noise level (RMSE_rel close to the readings' own noise) needs nothing.</p>\n";
        page.section("next", "Next", h);
    }
    page.section(
        "provenance",
        "Provenance",
        &provenance(
            inputs,
            &[format!("rcalib {}", env!("CARGO_PKG_VERSION"))],
            &[],
        )?,
    );
    Ok(page.render())
}

/// The JSON document: comparisons and explanation.
#[derive(Serialize)]
pub struct Json<'a> {
    pub comparisons: Vec<&'a Comparison>,
    pub explanation: Option<&'a Explanation>,
}
