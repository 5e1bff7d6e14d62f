//! Validation of uplifting against measured reflectances.
//!
//! For each measured spectrum `m`: its RGB (CIE 1931 2 deg, under the space's illuminant) is
//! uplifted to `u`, then, per wavelength `l` over the `n` samples of a data set (seed
//! dissertation, Eq. 5.3 and 5.4, with `X_meth = u(l)`, `X_ref = m(l)`):
//!
//! ```text
//! MRB(l)   = 1/n sum_i (u_i(l) - m_i(l)) / m_i(l)
//! RMSRE(l) = sqrt( 1/n sum_i ((u_i(l) - m_i(l)) / m_i(l))^2 )
//! ```
//!
//! summarised over wavelengths (median and maximum of |MRB| and RMSRE, over 380-780 nm and
//! over 400-700 nm), plus the round-trip colour error Delta E*ab between `m` and `u` and the
//! deviation of reflected melanopic EDI and illuminance under CIE daylight
//! ([`crate::colour::melanopic`]).
//!
//! Data: Munsell (1269 chips; every 5th chip held out, [`basis::munsell_held_out`], the rest
//! trains the basis) and the 24 ColorChecker patches (all held out).

use rayon::prelude::*;
use std::fmt::Write;

use crate::colour::cie::{N, RgbSpace, Spectrum, daylight, wavelengths};
use crate::colour::melanopic::{illuminance, m_edi};
use crate::uplift::basis::{self, Basis, colorchecker, munsell, munsell_held_out};
use crate::uplift::{Method, Uplifter};
use rdaylight_base::stats::{median, percentile};

/// Errors of one method on one data set.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// Wavelength-wise MRB (fraction, not %).
    pub mrb: Spectrum,
    /// Wavelength-wise RMSRE (fraction).
    pub rmsre: Spectrum,
    /// Round-trip Delta E*ab per sample.
    pub delta_e: Vec<f64>,
    /// The uplifted spectra, in input order.
    pub uplifted: Vec<Spectrum>,
}

/// Uplift each measured spectrum's colour and compare.
pub fn evaluate(u: &Uplifter, measured: &[&Spectrum]) -> Evaluation {
    let results: Vec<(Spectrum, f64)> = measured
        .par_iter()
        .map(|m| {
            let up = u.uplift_xyz(u.observer.spectrum_xyz(m));
            let de = u.delta_e(m, &up.spectrum);
            (up.spectrum, de)
        })
        .collect();
    let n = measured.len().max(1) as f64;
    let mut mrb = [0.0; N];
    let mut rmsre = [0.0; N];
    for (m, (s, _)) in measured.iter().zip(&results) {
        for i in 0..N {
            let rel = (s[i] - m[i]) / m[i];
            mrb[i] += rel / n;
            rmsre[i] += rel * rel / n;
        }
    }
    Evaluation {
        mrb,
        rmsre: rmsre.map(f64::sqrt),
        delta_e: results.iter().map(|r| r.1).collect(),
        uplifted: results.into_iter().map(|r| r.0).collect(),
    }
}

/// Summary numbers of an evaluation (percent for MRB/RMSRE).
#[derive(Debug, Clone, Copy)]
pub struct Summary {
    pub mrb_median: f64,
    pub mrb_max: f64,
    pub rmsre_median: f64,
    pub rmsre_max: f64,
    /// Max |MRB| and max RMSRE over 400-700 nm.
    pub mrb_max_400_700: f64,
    pub rmsre_max_400_700: f64,
    pub de_mean: f64,
    pub de_max: f64,
}

impl Evaluation {
    pub fn summary(&self) -> Summary {
        let wl = wavelengths();
        let abs_mrb: Vec<f64> = self.mrb.iter().map(|v| 100.0 * v.abs()).collect();
        let rms: Vec<f64> = self.rmsre.iter().map(|v| 100.0 * v).collect();
        let inner = |v: &[f64]| {
            (0..N)
                .filter(|&i| (400.0..=700.0).contains(&wl[i]))
                .map(|i| v[i])
                .fold(0.0, f64::max)
        };
        Summary {
            mrb_median: median(&abs_mrb),
            mrb_max: abs_mrb.iter().copied().fold(0.0, f64::max),
            rmsre_median: median(&rms),
            rmsre_max: rms.iter().copied().fold(0.0, f64::max),
            mrb_max_400_700: inner(&abs_mrb),
            rmsre_max_400_700: inner(&rms),
            de_mean: self.delta_e.iter().sum::<f64>() / self.delta_e.len().max(1) as f64,
            de_max: self.delta_e.iter().copied().fold(0.0, f64::max),
        }
    }
}

/// Deviation (%) of reflected m-EDI and illuminance, uplifted vs measured, under CIE
/// daylight of `cct`: one `(m-EDI %, E_v %)` pair per sample.
pub fn light_deviation(
    measured: &[&Spectrum],
    uplifted: &[Spectrum],
    cct: f64,
) -> crate::Result<Vec<(f64, f64)>> {
    let e = daylight(cct)?;
    Ok(measured
        .iter()
        .zip(uplifted)
        .map(|(m, u)| {
            let mel = 100.0 * (m_edi(&e, u) / m_edi(&e, m) - 1.0);
            let ev = 100.0 * (illuminance(&e, u) / illuminance(&e, m) - 1.0);
            (mel, ev)
        })
        .collect())
}

/// Per wavelength, the median and the 90th percentile over the samples of the absolute
/// relative error `|u(l) - m(l)| / m(l)`, in %.
pub fn error_percentiles(measured: &[&Spectrum], uplifted: &[Spectrum]) -> (Spectrum, Spectrum) {
    let mut med = [0.0; N];
    let mut p90 = [0.0; N];
    for i in 0..N {
        let rel: Vec<f64> = measured
            .iter()
            .zip(uplifted)
            .map(|(m, u)| 100.0 * ((u[i] - m[i]) / m[i]).abs())
            .collect();
        med[i] = median(&rel);
        p90[i] = percentile(&rel, 90.0);
    }
    (med, p90)
}

/// The per-wavelength error plot of `docs/uplift-error-per-wavelength.png`: Radiance RGB,
/// held-out Munsell chips and the ColorChecker, median and 90th percentile of the absolute
/// relative error for both methods, with the seed's 20 % level.
pub fn error_plot() -> image::RgbImage {
    use super::plot::{Axes, Panel, Series, panels};
    let wl = wavelengths();
    let sets = datasets();
    let mut out = Vec::new();
    for (name, spectra) in sets.iter().take(2) {
        let mut series = Vec::new();
        for (method, label, colour) in [
            (Method::Basis, "BASIS", [31u8, 119, 180]),
            (Method::Jakob, "JAKOB-HANIKA", [230, 120, 20]),
        ] {
            let u = Uplifter::new(RgbSpace::Radiance, method);
            let ev = evaluate(&u, spectra);
            let (med, p90) = error_percentiles(spectra, &ev.uplifted);
            for (stat, v, dashed) in [("MEDIAN", med, false), ("90TH PERCENTILE", p90, true)] {
                series.push(Series {
                    label: format!("{label} {stat}"),
                    colour,
                    dashed,
                    points: wl.iter().zip(v).map(|(l, e)| (*l, e)).collect(),
                });
            }
        }
        out.push(Panel {
            title: name.to_string(),
            series,
        });
    }
    let axes = Axes {
        x_range: (380.0, 780.0),
        x_ticks: vec![400.0, 500.0, 600.0, 700.0],
        x_label: "WAVELENGTH (NM)".into(),
        y_range: (0.0, 100.0),
        y_ticks: vec![0.0, 20.0, 40.0, 60.0, 80.0, 100.0],
        y_label: "|RELATIVE ERROR| % (RADIANCE RGB, CLIPPED AT 100)".into(),
        reference: Some((20.0, "SEED 20 % LEVEL".into())),
    };
    panels(&out, &axes, 480, 300)
}

/// The data sets of the validation: name and spectra.
pub fn datasets() -> Vec<(&'static str, Vec<&'static Spectrum>)> {
    let held: Vec<&Spectrum> = munsell()
        .iter()
        .enumerate()
        .filter(|(i, _)| munsell_held_out(*i))
        .map(|(_, (_, s))| s)
        .collect();
    let cc: Vec<&Spectrum> = colorchecker().iter().map(|(_, s)| s).collect();
    let all: Vec<&Spectrum> = munsell().iter().map(|(_, s)| s).collect();
    vec![
        ("Munsell held-out (254)", held),
        ("ColorChecker (24)", cc),
        ("Munsell all (1269)", all),
    ]
}

/// Model selection for the basis: median wavelength-wise RMSRE (%) on an inner split of the
/// training chips (chips `i % 5 == 3` validate, `i % 5 < 3` train), for each K.
pub fn basis_k_sweep(ks: &[usize]) -> Vec<(usize, f64, f64)> {
    let m = munsell();
    let train: Vec<&Spectrum> = m
        .iter()
        .enumerate()
        .filter(|(i, _)| i % 5 < 3)
        .map(|(_, (_, s))| s)
        .collect();
    let val: Vec<&Spectrum> = m
        .iter()
        .enumerate()
        .filter(|(i, _)| i % 5 == 3)
        .map(|(_, (_, s))| s)
        .collect();
    ks.iter()
        .map(|&k| {
            let u = Uplifter::with_basis(
                RgbSpace::Radiance,
                Method::Basis,
                Some(Basis::learn(&train, k)),
            );
            let s = evaluate(&u, &val).summary();
            (k, s.rmsre_median, s.mrb_median)
        })
        .collect()
}

/// One row of the validation tables.
pub struct Row {
    pub space: RgbSpace,
    pub method: Method,
    pub dataset: &'static str,
    pub summary: Summary,
    /// (median |dev|, p95 |dev|, max |dev|) of m-EDI in %, at 6500 K and 4000 K.
    pub medi: [(f64, f64, f64); 2],
    /// Same for illuminance.
    pub ev: [(f64, f64, f64); 2],
}

/// Run the whole validation.
pub fn validate() -> crate::Result<Vec<Row>> {
    let mut rows = Vec::new();
    for space in [RgbSpace::Radiance, RgbSpace::Srgb] {
        for (dataset, spectra) in datasets() {
            for method in [Method::Jakob, Method::Basis] {
                let u = Uplifter::new(space, method);
                let ev = evaluate(&u, &spectra);
                let mut medi = [(0.0, 0.0, 0.0); 2];
                let mut evs = [(0.0, 0.0, 0.0); 2];
                for (j, cct) in [6500.0, 4000.0].into_iter().enumerate() {
                    let d = light_deviation(&spectra, &ev.uplifted, cct)?;
                    let stats = |v: Vec<f64>| {
                        (
                            median(&v),
                            percentile(&v, 95.0),
                            v.iter().copied().fold(0.0, f64::max),
                        )
                    };
                    medi[j] = stats(d.iter().map(|x| x.0.abs()).collect());
                    evs[j] = stats(d.iter().map(|x| x.1.abs()).collect());
                }
                rows.push(Row {
                    space,
                    method,
                    dataset,
                    summary: ev.summary(),
                    medi,
                    ev: evs,
                });
            }
        }
    }
    Ok(rows)
}

fn space_name(s: RgbSpace) -> &'static str {
    match s {
        RgbSpace::Radiance => "Radiance RGB (E)",
        RgbSpace::Srgb => "sRGB (D65)",
        RgbSpace::SrgbLinear => "linear sRGB (D65)",
    }
}

fn method_name(m: Method) -> &'static str {
    match m {
        Method::Jakob => "jakob",
        Method::Basis => "basis",
    }
}

/// The validation as Markdown tables.
pub fn report(rows: &[Row], sweep: &[(usize, f64, f64)]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "### Reflectance errors (wavelength-wise, Eq. 5.3-5.4; % over 380-780 nm unless noted)\n"
    );
    let _ = writeln!(
        s,
        "| space | data set | method | median abs MRB | max abs MRB | max abs MRB 400-700 | \
         median RMSRE | max RMSRE | max RMSRE 400-700 | mean dE*ab | max dE*ab |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let m = &r.summary;
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.2e} | {:.2e} |",
            space_name(r.space),
            r.dataset,
            method_name(r.method),
            m.mrb_median,
            m.mrb_max,
            m.mrb_max_400_700,
            m.rmsre_median,
            m.rmsre_max,
            m.rmsre_max_400_700,
            m.de_mean,
            m.de_max
        );
    }
    let _ = writeln!(
        s,
        "\n### Reflected light under CIE daylight: |deviation| of uplifted vs measured, %\n"
    );
    let _ = writeln!(
        s,
        "| space | data set | method | m-EDI 6500 K median / p95 / max | \
         m-EDI 4000 K median / p95 / max | E_v 6500 K median / p95 / max | \
         E_v 4000 K median / p95 / max |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    let f = |t: (f64, f64, f64)| format!("{:.2} / {:.2} / {:.2}", t.0, t.1, t.2);
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} |",
            space_name(r.space),
            r.dataset,
            method_name(r.method),
            f(r.medi[0]),
            f(r.medi[1]),
            f(r.ev[0]),
            f(r.ev[1])
        );
    }
    if !sweep.is_empty() {
        let _ = writeln!(
            s,
            "\n### Basis size K (inner split of the training chips, Radiance RGB; default K = {})\n",
            basis::DEFAULT_K
        );
        let _ = writeln!(s, "| K | median RMSRE % | median abs MRB % |");
        let _ = writeln!(s, "|---|---|---|");
        for (k, r, m) in sweep {
            let _ = writeln!(s, "| {k} | {r:.2} | {m:.2} |");
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles() {
        let v = [3.0, 1.0, 2.0, 4.0];
        assert_eq!(median(&v), 2.5);
        assert_eq!(percentile(&v, 100.0), 4.0);
        assert_eq!(percentile(&v, 0.0), 1.0);
        assert!(median(&[]).is_nan());
    }

    #[test]
    fn identity_has_zero_error() {
        // Uplifting a spectrum the model can represent exactly gives back that spectrum.
        let u = Uplifter::new(RgbSpace::Radiance, Method::Jakob);
        let m = crate::uplift::Jakob {
            c: [1.0, -0.5, 0.2],
        }
        .spectrum();
        let e = evaluate(&u, &[&m]);
        let s = e.summary();
        assert!(s.rmsre_max < 1e-3 && s.de_max < 1e-4, "{s:?}");
    }
}
