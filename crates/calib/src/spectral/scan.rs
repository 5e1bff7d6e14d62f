//! # The seed's chapter-6 workflow with spectral readings
//!
//! 1. **Options** (seed sec. 6.3.4): the base glazing transmittance spectrum `τ_b` (the
//!    model's glass at normal incidence, with its spectral patterns) multiplied or divided
//!    by `1 + step x 0.125`, `step = 1..7`, each band kept within 0..1: fifteen options
//!    whose shape is the base's (except where a band is clipped at 1), named as the photopic
//!    scan ([`crate::tmscan`]): `window_neg_7` .. `window_base` .. `window_pos_7`.
//!    An option acts on the simulation as the per-band factor `τ'_b / τ_b` (see
//!    [`super`]).
//! 2. **Selection** by the 18-channel mean absolute error at the control sensor (Eq. 6.1):
//!    `MAE = 1/T Σ_t 1/CS Σ_i |y_meas(i,t) - y_sim(i,t)|`, in the channels' unit.
//! 3. **Evaluation** (Table 6.4): per sensor, before (the base) and after (the selected
//!    option), MBE_rel, RMSE_rel and sigma_rel (Eq. 6.2-6.4, [`Stats`]) of photopic
//!    illuminance, m-EDI and M/P, plus the spectral-shape Pearson r between the measured and
//!    simulated channel vectors of each reading (mean over the sensor's readings; a level
//!    change leaves it unchanged, a shape change does not).
//!
//! The selected option is applied with `rcalib apply --effect tint:F,0,0` (the base spectrum
//! times `F` as a `spectrum` pattern on the glass, capped so no band exceeds 1).

use super::SpectralModel;
use crate::stats::{Stats, pearson};
use rdaylight_metrics::html::escape as esc;
use serde::Serialize;

/// One window option.
#[derive(Debug, Clone, Serialize)]
pub struct SpecOption {
    pub name: String,
    /// Multiplier of the base spectrum before clipping.
    pub factor: f64,
    /// Photopic (ybar-weighted) transmittance of the option.
    pub vlt: f64,
    /// Eq. 6.1 at the control sensor, in the channels' unit.
    pub mae: f64,
    /// Mean spectral-shape Pearson r at the control sensor.
    pub r: f64,
    /// Per-band factor on the model's light.
    #[serde(skip)]
    pub band_factors: Vec<f64>,
}

/// Table 6.4 rows of one sensor.
#[derive(Debug, Clone, Serialize)]
pub struct SensorRow {
    pub sensor: String,
    pub control: bool,
    /// Distance from the nearest window plane (m), for ordering.
    pub depth: f64,
    pub before: Quality,
    pub after: Quality,
}

/// Errors of one model variant at one sensor (or all sensors).
#[derive(Debug, Clone, Copy, Serialize, Default)]
pub struct Quality {
    pub ev: Stats,
    pub medi: Stats,
    pub mp: Stats,
    /// Mean spectral-shape Pearson r over the readings.
    pub shape_r: f64,
    /// Eq. 6.1 over these readings.
    pub mae: f64,
}

/// The whole workflow's outcome.
#[derive(Debug, Clone, Serialize)]
pub struct SpectralScan {
    pub control: String,
    pub unit: String,
    pub options: Vec<SpecOption>,
    pub best: usize,
    /// Sensors sorted by distance from the facade, the control first.
    pub table: Vec<SensorRow>,
    /// All sensors together.
    pub all: SensorRow,
    /// `--effect` for `rcalib apply`.
    pub effect: String,
}

/// Per-band factors of the option `step` (-7..=7) on the base spectrum `tau`.
pub fn option_factors(tau: &[f64], step: i32) -> (f64, Vec<f64>) {
    let f = 1.0 + f64::from(step.unsigned_abs()) * 0.125;
    let mult = if step >= 0 { f } else { 1.0 / f };
    let v = tau
        .iter()
        .map(|&t| {
            if t > 0.0 {
                (t * mult).clamp(0.0, 1.0) / t
            } else {
                mult
            }
        })
        .collect();
    (mult, v)
}

/// Option name as the seed writes them.
pub fn option_name(step: i32) -> String {
    match step {
        0 => "window_base".to_string(),
        s if s > 0 => format!("window_pos_{s}"),
        s => format!("window_neg_{}", -s),
    }
}

/// Quality of the readings `which` (observation indices) under `factors`.
pub fn quality(m: &SpectralModel, which: &[usize], factors: Option<&[f64]>) -> Quality {
    let (mut ev, mut medi, mut mp) = (Vec::new(), Vec::new(), Vec::new());
    let (mut rs, mut abs, mut nabs) = (0.0, 0.0, 0usize);
    for &i in which {
        let q = m.quantities(i, factors);
        ev.push((q.sim.ev, q.ev_meas));
        medi.push((q.sim.medi, q.medi_meas));
        mp.push((q.sim.mp(), q.mp_meas()));
        let sim = m.channels(i, factors);
        let pairs: Vec<(f64, f64)> = sim.iter().copied().zip(m.meas[i].iter().copied()).collect();
        rs += pearson(&pairs);
        for (a, b) in &pairs {
            abs += (a - b).abs();
            nabs += 1;
        }
    }
    Quality {
        ev: Stats::of(&ev),
        medi: Stats::of(&medi),
        mp: Stats::of(&mp),
        shape_r: if which.is_empty() {
            0.0
        } else {
            rs / which.len() as f64
        },
        mae: if nabs > 0 { abs / nabs as f64 } else { 0.0 },
    }
}

/// Run the workflow with `control` as the control sensor (index).
pub fn scan(
    m: &SpectralModel,
    control: usize,
    window_depth: &dyn Fn(usize) -> f64,
) -> SpectralScan {
    let ctl: Vec<usize> = (0..m.obs.len())
        .filter(|&i| m.obs[i].sensor == control)
        .collect();
    let ybar = crate::colour::bands::band_integrals(&crate::colour::cie::tables().cmf[1], &m.ch());
    let ysum: f64 = ybar.iter().sum();
    let mut options = Vec::new();
    for step in -7..=7 {
        let (factor, f) = option_factors(&m.base_tau, step);
        let q = quality(m, &ctl, Some(&f));
        let vlt = m
            .base_tau
            .iter()
            .zip(&f)
            .zip(&ybar)
            .map(|((t, k), y)| t * k * y)
            .sum::<f64>()
            / ysum.max(1e-12);
        options.push(SpecOption {
            name: option_name(step),
            factor,
            vlt,
            mae: q.mae,
            r: q.shape_r,
            band_factors: f,
        });
    }
    let best = (0..options.len())
        .min_by(|a, b| options[*a].mae.total_cmp(&options[*b].mae))
        .unwrap_or(7);
    let ns = m.sensors.len();
    let after = options[best].band_factors.clone();
    let mut table: Vec<SensorRow> = (0..ns)
        .map(|s| {
            let which: Vec<usize> = (0..m.obs.len()).filter(|&i| m.obs[i].sensor == s).collect();
            SensorRow {
                sensor: m.sensors[s].id.clone(),
                control: s == control,
                depth: window_depth(s),
                before: quality(m, &which, None),
                after: quality(m, &which, Some(&after)),
            }
        })
        .filter(|r| r.before.ev.n + r.before.ev.excluded > 0)
        .collect();
    table.sort_by(|a, b| b.control.cmp(&a.control).then(a.depth.total_cmp(&b.depth)));
    let every: Vec<usize> = (0..m.obs.len()).collect();
    let all = SensorRow {
        sensor: "all".into(),
        control: false,
        depth: 0.0,
        before: quality(m, &every, None),
        after: quality(m, &every, Some(&after)),
    };
    SpectralScan {
        control: m
            .sensors
            .get(control)
            .map_or(String::new(), |s| s.id.clone()),
        unit: m.map.unit.to_string(),
        effect: format!("tint:{:.4},0,0", options[best].factor),
        options,
        best,
        table,
        all,
    }
}

/// Table 6.3 and Table 6.4 as text.
pub fn text(s: &SpectralScan) -> String {
    let mut out = String::new();
    out.push_str(&format!(
        "Window options (seed Table 6.3): MAE (Eq. 6.1, 18-channel, {}) at control sensor {}\n",
        s.unit, s.control
    ));
    out.push_str("option          factor    VLT        MAE       r\n");
    for (i, o) in s.options.iter().enumerate() {
        out.push_str(&format!(
            "{:14} {:7.3} {:6.3} {:10.4e} {:7.3}{}\n",
            o.name,
            o.factor,
            o.vlt,
            o.mae,
            o.r,
            if i == s.best { "  <- lowest MAE" } else { "" }
        ));
    }
    out.push_str(
        "\nRelative errors per sensor (seed Table 6.4; % ; sorted by distance from the facade)\n",
    );
    out.push_str("sensor        metric     step      Ev (%)   m-EDI (%)   M/P (%)   shape r\n");
    for r in s.table.iter().chain(std::iter::once(&s.all)) {
        let name = if r.control {
            format!("{} (control)", r.sensor)
        } else {
            r.sensor.clone()
        };
        for (metric, get) in [
            ("MBE_rel", (|x: &Stats| x.mbe_rel) as fn(&Stats) -> f64),
            ("RMSE_rel", |x: &Stats| x.rmse_rel),
            ("sigma_rel", |x: &Stats| x.sigma_rel),
        ] {
            for (step, q) in [("before", &r.before), ("after", &r.after)] {
                out.push_str(&format!(
                    "{:13} {:10} {:7} {:9.2} {:11.2} {:9.2} {:9.3}\n",
                    name,
                    metric,
                    step,
                    get(&q.ev),
                    get(&q.medi),
                    get(&q.mp),
                    q.shape_r
                ));
            }
        }
    }
    out.push_str(&format!(
        "lowest MAE of the scan: {} (x{:.3}, --effect {})\n",
        s.options[s.best].name, s.options[s.best].factor, s.effect
    ));
    out
}

/// A self-contained HTML page with Table 6.3 and Table 6.4 (and the explanation text).
pub fn html(s: &SpectralScan, explanation: Option<&str>) -> String {
    use rdaylight_metrics::html::Page;
    let mut page = Page::new(
        "rcalib spectral: calibration with spectral readings",
        "the seed's chapter-6 window scan, Table 6.3 and Table 6.4",
    );
    let mut h = String::new();
    h += &format!(
        "<h2>Window options</h2><p>MAE: Eq. 6.1 over the channels and time steps at the \
         control sensor {} ({}); r: spectral-shape Pearson correlation.</p>\n<table>\
         <tr><th>option</th><th>factor</th><th>VLT</th><th>MAE</th><th>r</th></tr>\n",
        esc(&s.control),
        esc(&s.unit)
    );
    for (i, o) in s.options.iter().enumerate() {
        h += &format!(
            "<tr{}><td style=\"text-align:left\">{}</td><td>{:.3}</td><td>{:.3}</td>\
             <td>{:.4e}</td><td>{:.3}</td></tr>\n",
            if i == s.best { " class=\"best\"" } else { "" },
            o.name,
            o.factor,
            o.vlt,
            o.mae,
            o.r
        );
    }
    h += "</table>\n<h2>Relative errors per sensor (Table 6.4)</h2>\n<table><tr><th>sensor</th>\
          <th>metric</th><th>step</th><th>Ev %</th><th>m-EDI %</th><th>M/P %</th>\
          <th>shape r</th></tr>\n";
    for r in s.table.iter().chain(std::iter::once(&s.all)) {
        for (metric, get) in [
            ("MBE_rel", (|x: &Stats| x.mbe_rel) as fn(&Stats) -> f64),
            ("RMSE_rel", |x: &Stats| x.rmse_rel),
            ("sigma_rel", |x: &Stats| x.sigma_rel),
        ] {
            for (step, q) in [("before", &r.before), ("after", &r.after)] {
                h += &format!(
                    "<tr><td style=\"text-align:left\">{}{}</td><td>{metric}</td><td>{step}</td>\
                     <td>{:.2}</td><td>{:.2}</td><td>{:.2}</td><td>{:.3}</td></tr>\n",
                    esc(&r.sensor),
                    if r.control { " (control)" } else { "" },
                    get(&q.ev),
                    get(&q.medi),
                    get(&q.mp),
                    q.shape_r
                );
            }
        }
    }
    h += &format!(
        "</table>\n<p>Lowest MAE of the scan: {} (x{:.3}, <code>--effect {}</code>).{}</p>\n",
        s.options[s.best].name,
        s.options[s.best].factor,
        esc(&s.effect),
        if explanation.is_some() {
            " The effects to apply are the explanation's, below."
        } else {
            " Apply it with <code>rcalib apply MODEL --sensors SENSORS --effect ...</code>."
        }
    );
    page.section("scan", "Window options and errors", &h);
    if let Some(t) = explanation {
        page.section("explain", "Explain", &format!("<pre>{}</pre>\n", esc(t)));
    }
    page.render()
}
