//! Glare metrics from the detected sources, with evalglare 3.06's formulas and constants
//! (`get_dgp`, `get_dgi`, `get_dgi_mod`, `get_ugr`, `get_ugr_exp`, `get_ugp`, `get_ugp2`,
//! `get_cgi`, `get_dgr`, `get_vcp`, `get_disability` in `src/util/evalglare.c`; notes §9.4).
//! Lᵢ, ωᵢ, Pᵢ: source luminance, solid angle, position index; E_v vertical illuminance;
//! L_b background luminance; L_a = E_v/π.
//!
//! - DGP (Wienold & Christoffersen 2006): `c1·E_v^a5 + c3 + c2·log10(1 + Σ Lᵢ^a1 ωᵢ^a2 /
//!   (E_v^a3 Pᵢ^a4))`, a = (2, 1, 1.87, 2, 1), c = (5.87e−5, 0.092, 0.159) (`-w`); without
//!   sources `c3 + c1·E_v`; ≤ 1. Low-light correction (`-C l+`, off by default): below
//!   1000 lx × `e^(0.024E_v − 4)/(1 + e^(0.024E_v − 4))`.
//! - DGI (Hopkinson/Chauvel): `10 log10 Σ 0.478 Lᵢ^1.6 (ωᵢ/Pᵢ²)^0.8 / (L_b + 0.07 ωᵢ^0.5 Lᵢ)`;
//!   DGI_mod (Fisekis 2003): `L_a^0.85` instead of L_b.
//! - UGR (CIE 117): `8 log10(0.25/L_b Σ Lᵢ²ωᵢ/Pᵢ²)` (0 if the sum is 0, −99 if L_b ≤ 0);
//!   UGR_exp: `8 log10 L_a + 8 log10(Σ Lᵢωᵢ/Pᵢ² / L_b)`; UGP `0.26 log10(0.25/L_b Σ …)`;
//!   UGP2 `1/(1 + 2/7 (Σ/L_b)^−0.2)^10`.
//! - CGI (Einhorn): `8 log10(2(1 + E_dir/500)/E_v Σ Lᵢ²ωᵢ/Pᵢ²)`.
//! - DGR (Hopkinson/Bradley) with the mean luminance `L̄`: `(Σ 0.5 Lᵢ(20.4ωᵢ + 1.52ωᵢ^0.2 −
//!   0.075)/(Pᵢ L̄^0.44))^(n^−0.0914)`; VCP = `50 erf((6.374 − 1.3227 ln DGR)/√2) + 50`, 0 if
//!   DGR > 750, 100 if DGR < 20.
//! - Lveil (Poynter): `5 Σ Lᵢ cos(σᵢ) ωᵢ / σᵢ(deg)`.
//! - No sources: DGI, UGR, UGP, UGP2, UGR_exp, DGI_mod, CGI, DGR = 0 and VCP = 100.
//!
//! evalglare returns most of these as `float`; we round the same ones to `f32` so printed
//! values agree to the last digit.

pub use rdaylight_base::stats::erf;

/// DGP coefficients `a1..a5, c1..c3` (`-w`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DgpCoefficients {
    /// Exponents a1 (L), a2 (ω), a3 (E_v), a4 (P), a5 (E_v linear term).
    pub a: [f64; 5],
    /// c1 (linear E_v), c2 (log term), c3 (constant).
    pub c: [f64; 3],
}

impl DgpCoefficients {
    /// dcglare's rounded constants (`cmglare.c`): c2 = 0.0918, c3 = 0.16.
    pub const DCGLARE: DgpCoefficients = DgpCoefficients {
        a: [2.0, 1.0, 1.87, 2.0, 1.0],
        c: [5.87e-5, 0.0918, 0.16],
    };
}

impl Default for DgpCoefficients {
    /// Wienold & Christoffersen (2006), as evalglare uses them.
    fn default() -> Self {
        DgpCoefficients {
            a: [2.0, 1.0, 1.87, 2.0, 1.0],
            c: [5.87e-5, 0.092, 0.159],
        }
    }
}

/// What a metric needs of one source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SourceTerm {
    /// Mean luminance (cd/m²).
    pub lum: f64,
    /// Solid angle (sr).
    pub omega: f64,
    /// Position index.
    pub pos: f64,
    /// Angle from the view direction (rad).
    pub sigma: f64,
}

/// The metrics evalglare prints.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Metrics {
    /// Daylight glare probability (after the low-light correction when asked for).
    pub dgp: f64,
    /// DGP before the low-light correction (used for `r_dgp`).
    pub dgp_raw: f64,
    /// Daylight glare index.
    pub dgi: f64,
    /// Unified glare rating.
    pub ugr: f64,
    /// Visual comfort probability.
    pub vcp: f64,
    /// CIE glare index.
    pub cgi: f64,
    /// Disability glare veiling luminance (Poynter).
    pub lveil: f64,
    /// Discomfort glare rating.
    pub dgr: f64,
    /// Unified glare probability.
    pub ugp: f64,
    /// UGR with L_a.
    pub ugr_exp: f64,
    /// Modified DGI.
    pub dgi_mod: f64,
    /// Second UGP form.
    pub ugp2: f64,
}

fn f32r(v: f64) -> f64 {
    v as f32 as f64
}

/// evalglare's π (`3.1415927`), used for L_b and L_a (deliberately not `f64::consts::PI`:
/// its rounding shows in the 6th digit of L_b).
#[allow(clippy::approx_constant)]
pub const PI_EG: f64 = 3.1415927;

/// DGP from E_v and the sources.
pub fn dgp(e_v: f64, s: &[SourceTerm], k: &DgpCoefficients) -> f64 {
    let [a1, a2, a3, a4, a5] = k.a;
    let [c1, c2, c3] = k.c;
    let d = if s.is_empty() {
        c3 + c1 * e_v.powf(a5)
    } else {
        let sum: f64 = s
            .iter()
            .map(|t| t.lum.powf(a1) / t.pos.powf(a4) * t.omega.powf(a2))
            .sum();
        c1 * e_v.powf(a5) + c3 + c2 * (1.0 + sum / e_v.powf(a3)).log10()
    };
    d.min(1.0)
}

/// The low-light factor applied to DGP below 1000 lx (`-C l+`).
pub fn low_light_factor(e_v: f64) -> f64 {
    if e_v < 1000.0 {
        let t = (0.024 * e_v - 4.0).exp();
        t / (1.0 + t)
    } else {
        1.0
    }
}

/// Every metric. `lum_backg` per `-q`, `lum_backg_cos` = (E_v − E_dir)/π (UGR_exp always
/// uses it), `avlum` the picture's mean luminance (DGR, Lveil).
#[allow(clippy::too_many_arguments)]
pub fn metrics(
    s: &[SourceTerm],
    e_v: f64,
    e_dir: f64,
    lum_backg: f64,
    lum_backg_cos: f64,
    avlum: f64,
    k: &DgpCoefficients,
    low_light: bool,
) -> Metrics {
    let dgp_raw = dgp(e_v, s, k);
    let dgp = if low_light {
        dgp_raw * low_light_factor(e_v)
    } else {
        dgp_raw
    };
    if s.is_empty() {
        return Metrics {
            dgp,
            dgp_raw,
            vcp: 100.0,
            ..Metrics::default()
        };
    }
    let lum_a = e_v / PI_EG;
    // Σ L²ω/P², shared by UGR, UGP, UGP2 and CGI
    let sum_l2: f64 = s.iter().map(|t| (t.lum / t.pos).powi(2) * t.omega).sum();
    let lb32 = f32r(lum_backg);
    let dgi_sum = |bg: f64| -> f64 {
        // evalglare sums in float here
        let mut acc = 0f32;
        for t in s {
            let om = t.omega / t.pos / t.pos;
            let term = 0.478 * t.lum.powf(1.6) * (om as f32 as f64).powf(0.8)
                / (bg + 0.07 * t.omega.powf(0.5) * t.lum);
            acc = (acc as f64 + term) as f32;
        }
        acc as f64
    };
    let dgi = f32r(10.0 * dgi_sum(lb32).log10());
    let dgi_mod = f32r(10.0 * dgi_sum(f32r(lum_a).powf(0.85)).log10());
    let mut ugr = 8.0 * (0.25 / lum_backg * sum_l2).log10();
    if sum_l2 == 0.0 {
        ugr = 0.0;
    }
    if lum_backg <= 0.0 {
        ugr = -99.0;
    }
    let ugp = 0.26 * (0.25 / lum_backg * sum_l2).log10();
    let ugp2 = 1.0 / (1.0 + 2.0 / 7.0 * (sum_l2 / lum_backg).powf(-0.2)).powf(10.0);
    let sum_lw: f64 = s
        .iter()
        .map(|t| (1.0 / t.pos).powi(2) * t.lum * t.omega)
        .sum();
    let ugr_exp = 8.0 * lum_a.log10() + 8.0 * (sum_lw / lum_backg_cos).log10();
    let cgi = 8.0 * ((2.0 * (1.0 + e_dir / 500.0) / e_v) * sum_l2).log10();
    let dgr_sum: f64 = s
        .iter()
        .map(|t| {
            0.5 * t.lum * (20.4 * t.omega + 1.52 * t.omega.powf(0.2) - 0.075)
                / (t.pos * avlum.powf(0.44))
        })
        .sum();
    let dgr = f32r(dgr_sum.powf((s.len() as f64).powf(-0.0914)));
    let vcp = if dgr > 750.0 {
        0.0
    } else if dgr < 20.0 {
        100.0
    } else {
        f32r(50.0 * erf((6.374 - 1.3227 * dgr.ln()) / std::f64::consts::SQRT_2) + 50.0)
    };
    let lveil = 5.0
        * s.iter()
            .map(|t| {
                t.lum * (t.sigma + 0.00000000001).cos() * t.omega
                    / (super::posindex::DEG * t.sigma + 0.00000000001)
            })
            .sum::<f64>();
    Metrics {
        dgp,
        dgp_raw,
        dgi,
        ugr: f32r(ugr),
        vcp,
        cgi: f32r(cgi),
        lveil: f32r(lveil),
        dgr,
        ugp: f32r(ugp),
        ugr_exp: f32r(ugr_exp),
        dgi_mod,
        ugp2: f32r(ugp2),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erf_matches_tabulated_values() {
        // Abramowitz & Stegun table 7.1
        for (x, want) in [
            (0.0, 0.0),
            (0.5, 0.5204998778),
            (1.0, 0.8427007929),
            (2.0, 0.9953222650),
            (-1.0, -0.8427007929),
            (3.5, 0.9999992569),
        ] {
            assert!((erf(x) - want).abs() < 1e-9, "erf({x}) = {}", erf(x));
        }
    }

    #[test]
    fn dgp_without_sources_is_linear_in_ev() {
        let k = DgpCoefficients::default();
        assert!((dgp(1000.0, &[], &k) - (0.159 + 0.0587)).abs() < 1e-12);
        assert_eq!(dgp(1e6, &[], &k), 1.0);
    }

    #[test]
    fn low_light_factor_at_466_lx() {
        // radiance-notes §9 "Verified by running": 0.99924 at 466 lx
        assert!((low_light_factor(466.0) - 0.99924).abs() < 1e-5);
        assert_eq!(low_light_factor(1000.0), 1.0);
    }
}
