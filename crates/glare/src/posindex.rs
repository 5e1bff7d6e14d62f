//! Position index P of a direction in the field of view, as evalglare 3.06 computes it
//! (`get_posindex` in `src/util/evalglare.c`, angles from `pict_get_sigma`, `pict_get_tau`,
//! `pict_get_vangle` in `src/util/pictool.c`).
//!
//! σ = angle between the view direction D and the source direction d; τ = angle between the
//! view up U and the projection of d on the plane through D (`d/cos σ − D`, normalised);
//! φ = vertical angle (`acos(V·d) − π/2` with `H = D×U`, `V = D×H`, not normalised, as
//! pictool has it). Angles in degrees below.
//! - Guth (IES Lighting Handbook): `P = exp[(35.2 − 0.31889τ − 1.22e^(−2τ/9))·1e−3·σ +
//!   (21 + 0.26667τ − 0.002963τ²)·1e−5·σ²]`;
//! - below the line of sight (φ < 0): Iwata & Osterhaus (CIE 2010) with Kikuchi's coordinate
//!   conversion: `β = atan(tan σ·√(1 + 0.3225 cos²τ))`, `P = exp(6.49e−3 β + 21e−5 β²)`;
//! - P is capped at 16;
//! - Kim's model (`-P 1`): `P = exp((σ − (−9e−6τ³ + 0.0014τ² + 0.0866τ + 21.633)) /
//!   (−9e−6τ³ + 0.0013τ² + 0.0853τ + 8.772))` (not capped, as evalglare).
//!
//! evalglare converts with `deg = 180/3.1415927` and returns P as a `float`; both are kept.

use crate::vec3::{V3, cross, dot, normalized as normalize};

/// Which position-index model (`-P`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PosModel {
    /// Guth above the line of sight, Iwata below (evalglare's default, `-P 0`).
    #[default]
    GuthIwata,
    /// Kim's model (`-P 1`).
    Kim,
}

/// The angles of direction `d` in a view with unit direction `vdir` and up `vup`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Angles {
    /// σ (rad).
    pub sigma: f64,
    /// τ (rad).
    pub tau: f64,
    /// φ (rad), negative below the line of sight.
    pub phi: f64,
}

/// σ, τ and φ of `d` (see the module documentation).
pub fn angles(vdir: V3, vup: V3, d: V3) -> Angles {
    Frame::new(vdir, vup).angles(d)
}

/// The view's axes as [`angles`] uses them, made once for many directions (a position index
/// per pixel): the same numbers as [`angles`] and [`posindex`], bit for bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Unit view direction D.
    vdir: V3,
    /// Unit view up U.
    vup: V3,
    /// `V = D × (D × U)` (not normalised, as pictool has it).
    v: V3,
}

impl Frame {
    /// The frame of a view direction and up vector (normalised here).
    pub fn new(vdir: V3, vup: V3) -> Frame {
        let vdir = normalize(vdir);
        let vup = normalize(vup);
        let h = cross(vdir, vup);
        Frame {
            vdir,
            vup,
            v: cross(vdir, h),
        }
    }

    /// σ, τ and φ of `d`.
    pub fn angles(&self, d: V3) -> Angles {
        let vdir = self.vdir;
        let sigma = dot(vdir, d).acos();
        let c = sigma.cos();
        let hv = normalize([d[0] / c - vdir[0], d[1] / c - vdir[1], d[2] / c - vdir[2]]);
        let tau = dot(self.vup, hv).acos();
        let phi = dot(self.v, d).acos() - std::f64::consts::FRAC_PI_2;
        Angles { sigma, tau, phi }
    }

    /// Position index of direction `d` ([`posindex`]).
    pub fn posindex(&self, d: V3, model: PosModel) -> f64 {
        let a = self.angles(d);
        let tau = a.tau * DEG;
        let sigma = a.sigma.abs() * DEG;
        let phi = if a.phi == 0.0 { 0.00001 } else { a.phi };
        let p = match model {
            PosModel::Kim => ((sigma
                - (-0.000009 * tau.powi(3) + 0.0014 * tau * tau + 0.0866 * tau + 21.633))
                / (-0.000009 * tau.powi(3) + 0.0013 * tau * tau + 0.0853 * tau + 8.772))
                .exp(),
            PosModel::GuthIwata => {
                // evalglare evaluates Guth everywhere and overwrites it below the line of
                // sight; it is only computed where it is kept
                let p = if phi < 0.0 {
                    let beta = ((sigma / DEG).tan()
                        * (1.0 + 0.3225 * (tau / DEG).cos().powi(2)).sqrt())
                    .atan()
                        * DEG;
                    (6.49 / 1000.0 * beta + 21.0 / 100000.0 * beta * beta).exp()
                } else {
                    guth(tau, sigma)
                };
                p.min(16.0)
            }
        };
        // evalglare returns a float
        p as f32 as f64
    }
}

/// Guth's position index (IES Lighting Handbook) for the angle τ from the vertical and σ
/// from the line of sight, both in degrees, uncapped (formula in the module documentation).
/// evalglare and dcglare both use it above the line of sight; they measure τ differently.
pub fn guth(tau: f64, sigma: f64) -> f64 {
    ((35.2 - 0.31889 * tau - 1.22 * (-2.0 * tau / 9.0).exp()) / 1000.0 * sigma
        + (21.0 + 0.26667 * tau - 0.002963 * tau * tau) / 100000.0 * sigma * sigma)
        .exp()
}

/// dcglare's position index (`get_guth` in `src/util/cmglare.c`, Radiance 6): [`guth`]
/// above the line of sight, with τ measured from `D + d/cos σ` (where evalglare uses
/// `d/cos σ − D`); below it the Iwata/Osterhaus form `P = 1 + f r`,
/// `r = min(3, √((1 + s²)/d²))`, `d = 1/tan φ`, `s = tan θ/tan φ`, θ the horizontal angle,
/// `f = 0.8`, 1.2 when `r > 0.6`; capped at 16; not rounded to `float`.
pub fn dcglare_posindex(dir: V3, forward: V3, up: V3) -> f64 {
    let angle = |a: V3, b: V3| dot(a, b).clamp(-1.0, 1.0).acos();
    let hv = normalize(cross(forward, up));
    let vert = cross(forward, hv);
    let phi = angle(dir, vert) - std::f64::consts::FRAC_PI_2;
    let p = if phi >= 0.0 {
        let sigma = angle(dir, forward).abs().to_degrees();
        let c = dot(dir, forward);
        let h = normalize([
            forward[0] + dir[0] / c,
            forward[1] + dir[1] / c,
            forward[2] + dir[2] / c,
        ]);
        guth(angle(h, up).to_degrees(), sigma)
    } else {
        let mut teta = std::f64::consts::FRAC_PI_2 - angle(dir, hv);
        if teta == 0.0 {
            teta = 1e-9;
        }
        let d = 1.0 / phi.tan();
        let s = teta.tan() / phi.tan();
        let r = ((1.0 + s * s) / (d * d)).sqrt();
        let fact = if r > 0.6 { 1.2 } else { 0.8 };
        1.0 + fact * r.min(3.0)
    };
    p.min(16.0)
}

/// evalglare's degrees per radian (`180/3.1415927`).
pub const DEG: f64 = 180.0 / super::metrics::PI_EG;

/// Position index of direction `d` (see the module documentation).
pub fn posindex(vdir: V3, vup: V3, d: V3, model: PosModel) -> f64 {
    Frame::new(vdir, vup).posindex(d, model)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn guth_grows_off_axis_and_is_capped() {
        let up = [0.0, 0.0, 1.0];
        let d = [0.0, 1.0, 0.0];
        let off = |deg: f64| {
            let a = deg.to_radians();
            posindex(d, up, [a.sin(), a.cos(), 0.0], PosModel::GuthIwata)
        };
        assert!(off(10.0) > 1.0 && off(30.0) > off(10.0) && off(60.0) > off(30.0));
        // straight up (τ = 0) at 80°: exp(33.98e−3·80 + 21e−5·6400) = 105, capped at 16
        let a = 80f64.to_radians();
        assert_eq!(
            posindex(d, up, [0.0, a.cos(), a.sin()], PosModel::GuthIwata),
            16.0
        );
        // Guth at τ = 90° (horizontal), σ = 30°: exp((35.2 − 28.7001 − 1.22e−20)·0.03 +
        // (21 + 24.0003 − 24.0003)·1e−5·900)
        let tau = 90.0;
        let want = ((35.2 - 0.31889 * tau - 1.22 * (-2.0f64 * tau / 9.0).exp()) / 1000.0 * 30.0
            + (21.0 + 0.26667 * tau - 0.002963 * tau * tau) / 1e5 * 900.0)
            .exp();
        assert!(
            (off(30.0) - want).abs() < 2e-3 * want,
            "{} {}",
            off(30.0),
            want
        );
    }

    #[test]
    fn below_the_line_of_sight_uses_iwata() {
        let a = 20f64.to_radians();
        let d = [0.0, a.cos(), -a.sin()];
        let p = posindex([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], d, PosModel::GuthIwata);
        // straight below: τ = 180°, cos²τ = 1
        let beta = (a.tan() * 1.3225f64.sqrt()).atan().to_degrees();
        let want = (6.49e-3 * beta + 21e-5 * beta * beta).exp();
        assert!((p - want).abs() < 1e-4 * want, "{p} {want}");
    }
}
