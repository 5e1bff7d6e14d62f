//! # Glazing spectral tint: a transmittance whose shape, not only its level, is wrong
//!
//! Coatings, laminates and body-tinted glass transmit some wavelengths more than others
//! (bluish low-e coatings, greenish float glass from iron oxide), and a model made with a
//! neutral glass gets the *colour* of the daylight indoors wrong as well as its level. The
//! effect multiplies the glazing transmittance at wavelength `λ` by
//!
//! ```text
//! T(λ) = scale · g(λ) / N,   g(λ) = max(G_MIN, 1 + slope·x + curvature·(x² - 1/3)),
//! x = (λ - 580 nm) / 200 nm           (-1 at 380 nm, +1 at 780 nm)
//! N = Σ ybar(λ) D65(λ) g(λ) / Σ ybar(λ) D65(λ)
//! ```
//!
//! a low-order (Legendre-like: 1, x, x² - 1/3) multiplier normalised so that daylight (CIE
//! D65) keeps its photopic transmission: `scale` is the photopic level (what the
//! [`transmittance`](super::transmittance) effect fits), `slope < 0` makes the glass bluish,
//! `slope > 0` yellowish/reddish, `curvature < 0` greenish (more in the middle). So photopic
//! readings see only `scale` (the model's photopic prediction multiplies the window's
//! contribution by it, uniformly); spectral readings see the shape in every reading's
//! channel ratios, which is the signature: residuals that depend on wavelength the same way
//! at every sensor and time, where the other effects (grey) change only the level.
//! [`crate::spectral::explain`] fits `slope` and `curvature` to those shape
//! residuals.
//!
//! `rcalib apply --effect tint:SCALE,SLOPE,CURVATURE` writes the factor as a Radiance 6
//! `spectrum` pattern (380-780 nm, 5 nm) on every glass material: Radiance's glass multiplies
//! its *transmission* coefficient only by the pattern colour (`glass.c`; see
//! [`crate::material::spectrum`]), so the traced light through the window scales by exactly
//! the band means of `T(λ)`, which is what the fit assumed.

use super::{Effect, golden};
use crate::colour::cie::{N, WL_MIN, WL_STEP, tables};
use crate::error::{Error, Result};
use crate::fit::{Fitter, without};
use crate::material::spectrum::Sampled;
use crate::model::{Model, Weights};
use crate::radiometry::Channels;
use crate::scene::{Primitive, Scene};

/// Centre and half span of the wavelength coordinate `x` (nm).
pub const PIVOT_NM: f64 = 580.0;
pub const HALF_SPAN_NM: f64 = 200.0;
/// Smallest relative shape value (keeps the transmittance positive for steep fits).
pub const G_MIN: f64 = 0.02;
/// Bounds of the fitted shape parameters (a factor of 3-4 between the ends of the range is
/// already a strongly coloured glass).
pub const SHAPE_BOUND: f64 = 0.9;

fn shape_raw(slope: f64, curvature: f64, nm: f64) -> f64 {
    let x = (nm - PIVOT_NM) / HALF_SPAN_NM;
    (1.0 + slope * x + curvature * (x * x - 1.0 / 3.0)).max(G_MIN)
}

/// `T(λ)` on the 5 nm grid of [`tables`] (380..780 nm), normalised as in the module doc.
pub fn grid(scale: f64, slope: f64, curvature: f64) -> Vec<f64> {
    let t = tables();
    let g: Vec<f64> = (0..N)
        .map(|i| shape_raw(slope, curvature, WL_MIN + i as f64 * WL_STEP))
        .collect();
    let (mut num, mut den) = (0.0, 0.0);
    for (i, gi) in g.iter().enumerate() {
        let w = t.cmf[1][i] * t.d65[i];
        num += w * gi;
        den += w;
    }
    let norm = if num > 0.0 { num / den } else { 1.0 };
    g.iter().map(|x| scale * x / norm).collect()
}

/// The factor per simulated band (the band means Radiance takes of the `spectrum` pattern
/// that [`tinted_scene`] writes).
pub fn band_factors(scale: f64, slope: f64, curvature: f64, ch: &Channels) -> Vec<f64> {
    let s = Sampled::new(
        WL_MIN,
        WL_MIN + (N - 1) as f64 * WL_STEP,
        grid(scale, slope, curvature),
    );
    s.to_channels(ch)
        .as_slice()
        .iter()
        .map(|&v| f64::from(v))
        .collect()
}

/// Photopic model: the glazing level only (the shape is photopically neutral for daylight).
pub fn apply(e: &Effect, _m: &Model, w: &mut Weights) {
    if let Effect::Tint { scale, .. } = *e {
        w.tau *= scale;
    }
}

/// Photopic fit: the level, with no shape (the shape needs spectral readings:
/// [`crate::spectral::explain`]).
pub fn fit(f: &Fitter, base: &[Effect]) -> Option<Effect> {
    let base = without(base, "tint");
    let (x, _) = golden(
        &mut |lt: f64| {
            let mut e = base.clone();
            e.push(Effect::Tint {
                scale: lt.exp(),
                slope: 0.0,
                curvature: 0.0,
            });
            f.score(&e).m2ll
        },
        0.05f64.ln(),
        2f64.ln(),
        40,
    );
    Some(Effect::Tint {
        scale: x.exp(),
        slope: 0.0,
        curvature: 0.0,
    })
}

/// `tint:SCALE,SLOPE,CURVATURE` parameters.
pub fn parse(params: &str) -> std::result::Result<Effect, String> {
    let v: Vec<f64> = params
        .split(',')
        .map(|x| {
            x.trim()
                .parse::<f64>()
                .map_err(|_| format!("'{x}' is not a number"))
        })
        .collect::<std::result::Result<_, _>>()?;
    match v.as_slice() {
        [s, a, c] if *s > 0.0 && s.is_finite() && a.abs() <= 2.0 && c.abs() <= 2.0 => {
            Ok(Effect::Tint {
                scale: *s,
                slope: *a,
                curvature: *c,
            })
        }
        _ => Err("expected tint:SCALE>0,SLOPE,CURVATURE (|slope|, |curvature| <= 2)".into()),
    }
}

/// `tint:SCALE,SLOPE,CURVATURE`.
pub fn spec(scale: f64, slope: f64, curvature: f64) -> String {
    format!("tint:{scale:.3},{slope:.3},{curvature:.3}")
}

/// Transmittance at `nm` relative to its photopic level.
pub fn relative_at(slope: f64, curvature: f64, nm: f64) -> f64 {
    let g = grid(1.0, slope, curvature);
    let i = (((nm - WL_MIN) / WL_STEP).round().max(0.0) as usize).min(N - 1);
    g[i]
}

/// One line: level and colour.
pub fn describe(scale: f64, slope: f64, curvature: f64) -> String {
    let (b, gr, r) = (
        relative_at(slope, curvature, 450.0),
        relative_at(slope, curvature, 540.0),
        relative_at(slope, curvature, 650.0),
    );
    let colour = if (b - r).abs() < 0.05 && (gr - 0.5 * (b + r)).abs() < 0.05 {
        "neutral"
    } else if gr > b.max(r) {
        "greenish"
    } else if b > r {
        "bluish"
    } else {
        "yellowish/reddish"
    };
    format!(
        "glazing tint: photopic transmission {:.0} % of the modelled value, {colour} \
         (relative transmittance at 450/540/650 nm: {b:.2}/{gr:.2}/{r:.2})",
        100.0 * scale
    )
}

/// The scene with a `spectrum` pattern `T(λ)` on every `glass` material (see the module
/// doc). Existing modifiers of the glass stay in its chain (the new pattern is modified by
/// them). The pattern is capped so the glass's normal-incidence transmission stays <= 1.
pub fn tinted_scene(scene: &Scene, scale: f64, slope: f64, curvature: f64) -> Result<Scene> {
    let values = grid(scale, slope, curvature);
    let mut out = Scene::default();
    let mut k = 0;
    for o in &scene.objects {
        if let Primitive::Glass {
            transmissivity,
            index,
        } = &o.kind
        {
            // The cap is a bound: the most transmissive channel must stay <= 1 (the pattern
            // multiplies every channel), hence `Max`, not the luminous figure.
            let t0 = super::transmittance::normal_transmittance(
                transmissivity,
                *index,
                super::transmittance::Summary::Max,
            );
            let cap = if t0 > 0.0 { 1.0 / t0 } else { 1.0 };
            let id = format!("rcalib_tint_{k}");
            k += 1;
            out.push(
                &o.modifier_name,
                id.clone(),
                Primitive::Spectrum {
                    nm_a: WL_MIN,
                    nm_b: WL_MIN + (N - 1) as f64 * WL_STEP,
                    values: values
                        .iter()
                        .map(|v| (v.min(cap) * 1e4).round() / 1e4)
                        .collect(),
                },
            )?;
            out.push(&id, o.id.clone(), o.kind.clone())?;
        } else {
            out.push(&o.modifier_name, o.id.clone(), o.kind.clone())
                .map_err(|e| Error::Usage(format!("tint: {e}")))?;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_is_photopically_neutral_for_daylight() {
        let t = tables();
        for (a, c) in [(-0.5, 0.0), (0.4, -0.3), (0.0, 0.0)] {
            let g = grid(0.7, a, c);
            let num: f64 = (0..N).map(|i| g[i] * t.cmf[1][i] * t.d65[i]).sum();
            let den: f64 = (0..N).map(|i| t.cmf[1][i] * t.d65[i]).sum();
            assert!((num / den - 0.7).abs() < 1e-12, "{a} {c}");
        }
        // Negative slope: more blue than red.
        assert!(relative_at(-0.5, 0.0, 420.0) > 1.5 * relative_at(-0.5, 0.0, 700.0));
        assert!(describe(1.0, -0.5, 0.0).contains("bluish"));
        assert!(describe(1.0, 0.0, -0.6).contains("greenish"));
    }

    #[test]
    fn tinted_scene_puts_a_pattern_on_the_glass() {
        let text = "void plastic wall 0 0 5 .5 .5 .5 0 0\nvoid glass glazing 0 0 3 .96 .96 .96\n\
                    glazing polygon w 0 0 9 0 0 0 1 0 0 1 0 1\n";
        let s = crate::scene::parse_str(
            text,
            "t.rad",
            std::path::Path::new(""),
            &crate::scene::LoadOptions::default(),
        )
        .unwrap();
        let t = tinted_scene(&s, 0.8, -0.5, 0.0).unwrap();
        let out = t.to_string();
        assert!(out.contains("void spectrum rcalib_tint_0"), "{out}");
        assert!(out.contains("rcalib_tint_0 glass glazing"), "{out}");
        // The surface still finds the glass; the pattern's band means are the factors.
        let back = crate::scene::parse_str(
            &out,
            "t.rad",
            std::path::Path::new(""),
            &crate::scene::LoadOptions::default(),
        )
        .unwrap();
        let ch = Channels::spectral(18, 380.0, 780.0).unwrap();
        let tau = crate::spectral::glass_transmittance(&back, &ch);
        let t0 = crate::spectral::glass_transmittance(&s, &ch);
        let f = band_factors(0.8, -0.5, 0.0, &ch);
        for b in 0..18 {
            assert!(
                (tau[b] / t0[b] - f[b]).abs() < 1e-3,
                "{b}: {} {}",
                tau[b] / t0[b],
                f[b]
            );
        }
    }

    #[test]
    fn parse_checks_parameters() {
        assert!(matches!(
            parse("0.8,-0.4,0.1"),
            Ok(Effect::Tint { scale, .. }) if (scale - 0.8).abs() < 1e-12
        ));
        assert!(parse("0.8,-0.4").is_err());
        assert!(parse("-1,0,0").is_err());
        assert!(parse("1,x,0").unwrap_err().contains("'x'"));
    }
}
