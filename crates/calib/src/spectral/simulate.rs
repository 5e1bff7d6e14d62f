//! # Spectral irradiance at the measured steps through N-band daylight coefficients
//!
//! The photopic simulation's method ([`crate::simulate`]) with `rdc -cs N -cw a b`
//! coefficients and spectral skies:
//!
//! ```text
//! v(s,t,b) = Σ_p DC(s,p,b) · Y_p(t) · S_p(t,b)  +  Vsun(s,t,b) · L_sun(t) · S_sun(t,b)
//! ```
//!
//! - `DC`: sky coefficients with all bounces, `N` bands (`rdc -I -m MF -cs N -cw a b`);
//!   `Vsun`: unit-radiance white sun discs at the steps' positions with all bounces (one
//!   `rdc -I --suns steps.wea --suns-ab -cs N` run), as the photopic `Vsun`.
//! - `Y_p(t)`, `L_sun(t)`: the photopic Perez sky (no sun) and sun-disc radiance of the
//!   step, exactly the photopic model's ([`StepSky`]).
//! - `S(t,b)`: the spectra of [`crate::sky::spectral`] (rspecsky): CIE daylight of a CCT
//!   that follows the Perez clearness (diffuse sky) and the sun altitude (sun); the ground
//!   patch gets their mix by diffuse and direct horizontal irradiance. Each is normalised to
//!   unit Radiance photopic value, so the spectral result weighted photopically is the
//!   photopic simulation (to Monte Carlo noise).
//!
//! Coefficients are cached with the photopic ones ([`Simulator::run`]).

use crate::error::{Error, Result};
use crate::radiometry::Channels;
use crate::scene::Scene;
use crate::simulate::{Kind, Simulator, StepSky, What};
use crate::sky::spectral::{daylight_bands, photopic_shares, sky_cct, sun_cct};

/// Simulated band values of every (sensor, step).
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralSim {
    pub ch: Channels,
    pub nsens: usize,
    pub nsteps: usize,
    /// `[s][t][b]`, Radiance band values (irradiance x 400 nm).
    pub values: Vec<f64>,
}

impl SpectralSim {
    /// Band values of one (sensor, step).
    pub fn at(&self, s: usize, t: usize) -> &[f64] {
        let n = self.ch.ncomp;
        let i = (s * self.nsteps + t) * n;
        self.values.get(i..i + n).unwrap_or(&[])
    }
}

/// Spectra (band values, unit photopic) of the sky, sun and ground of a step.
pub fn step_spectra(sk: &StepSky, ch: &Channels) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let shares = photopic_shares(ch);
    let s_sky = daylight_bands(sky_cct(sk.clearness.max(1.0)), ch, &shares);
    let alt = sk.sun_altitude_deg.to_radians();
    let s_sun = daylight_bands(sun_cct(alt), ch, &shares);
    let dir = sk.dni * alt.sin().max(0.0);
    let w = if sk.dhi + dir > 0.0 {
        dir / (sk.dhi + dir)
    } else {
        0.0
    };
    let ground = s_sky
        .iter()
        .zip(&s_sun)
        .map(|(a, b)| (1.0 - w) * a + w * b)
        .collect();
    (s_sky, s_sun, ground)
}

/// Spectral irradiance of `scene` at the simulator's sensors and the steps `skies`.
pub fn simulate(
    simulator: &Simulator,
    scene: &Scene,
    skies: &[StepSky],
    nsens: usize,
    ch: &Channels,
) -> Result<SpectralSim> {
    let n = ch.ncomp;
    let text = scene.to_string();
    let kind = Kind {
        what: What::Sky { direct_only: false },
        channels: *ch,
    };
    let dc = simulator.run(&text, &kind)?;
    let npatch = crate::sky::SkyPatches::new(simulator.settings.mf).len();
    if dc.len() != nsens * npatch * n {
        return Err(Error::Mismatch(format!(
            "rdc returned {} spectral sky coefficients for {nsens} sensors, {npatch} patches \
             and {n} bands",
            dc.len()
        )));
    }
    let nt = skies.len();
    // Vsun: every step's sun from one set of paths, exactly the photopic model's run
    // (same seed and settings) with N bands.
    let k = Kind {
        what: What::Suns { bounces: true },
        channels: *ch,
    };
    let vsun = simulator.run(&text, &k)?;
    if vsun.len() != nsens * nt * n {
        return Err(Error::Mismatch(format!(
            "rdc returned {} sun coefficients for {nsens} sensors, {nt} steps and {n} bands",
            vsun.len()
        )));
    }
    let mut values = vec![0.0; nsens * nt * n];
    for (t, sk) in skies.iter().enumerate() {
        let (s_sky, s_sun, s_ground) = step_spectra(sk, ch);
        for p in 0..npatch {
            let rgb = sk.sky.get(p * 3..p * 3 + 3).unwrap_or(&[0.0; 3]);
            let y = crate::radiometry::photopic([rgb[0], rgb[1], rgb[2]]);
            if y == 0.0 {
                continue;
            }
            let spec = if p == 0 { &s_ground } else { &s_sky };
            for s in 0..nsens {
                let c = &dc[(s * npatch + p) * n..][..n];
                let o = &mut values[(s * nt + t) * n..][..n];
                for b in 0..n {
                    o[b] += c[b] * y * spec[b];
                }
            }
        }
        if sk.sun_altitude_deg > 0.0 && sk.sun_radiance > 0.0 {
            for s in 0..nsens {
                let v = &vsun[(s * nt + t) * n..][..n];
                let o = &mut values[(s * nt + t) * n..][..n];
                for b in 0..n {
                    o[b] += v[b] * sk.sun_radiance * s_sun[b];
                }
            }
        }
    }
    Ok(SpectralSim {
        ch: *ch,
        nsens,
        nsteps: nt,
        values,
    })
}
