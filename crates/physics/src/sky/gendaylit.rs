//! # gendaylit's Perez sky (one point in time), evaluated natively
//!
//! Radiance's `gendaylit` (`LBNL-ETA/Radiance: src/gen/gendaylit.c`, J.-J. Delaunay 1994,
//! revised by J. Wienold and W. Sprenger) describes a Perez all-weather sky (Perez, Seals,
//! Michalsky 1993, Solar Energy 50(3)) as the 10 arguments of `perezlum.cal` plus a sun
//! source. This computes the same arguments so that [`crate::sky::perez::perezlum`] can
//! evaluate the sky at any direction. It is a different implementation from gendaymtx's
//! ([`crate::sky::perez`]) and differs from it in details that change the numbers:
//!
//! ```text
//! default dew point 10.97353115 C (precipitable water exactly 2.0 cm; gendaymtx: 11 C)
//! epsilon clamped to [1, 12.009], delta to [0.01, 0.6] (gendaymtx: [1, 11.9])
//! solar zenith Z = 90 deg - altitude (no 3 deg floor; altitude capped at 87 deg unless -c)
//! Perez 1993 coefficients and the 145 integration directions are C floats
//! normalisation: A1 = E_dif / (179 I),  I = 2 pi / 145 sum_j lv(theta_j, gamma_j) cos theta_j
//!   over the 145 Tregenza directions with the sun at azimuth 0 (-O1: E_dif irradiance,
//!   no 179; -O2: luminance)
//! sun radiance = E_dir / (179 * 2 pi (1 - cos 0.2665 deg))
//! ground A2 = lv(zenith) A1 * norm (+ 6.8e-5 / pi * sun * sin alt if epsilon > 1 and sun)
//!   * ground reflectance, norm = gensky's clear (epsilon >= 6), intermediate (1 < epsilon
//!   < 6) or overcast (0.777778) normalisation for the same altitude
//! error sky (all zero A1..A7) when the sun is below the horizon for the date, when both
//!   components are 0 with the sun up, when the direct exceeds the solar constant, or when
//!   Perez b > 0
//! ```
//!
//! Photometric input (`-L`) is converted by 9 rounds of inverting the efficacy model
//! (gendaylit's loop condition never ends earlier once the parameters are clamped).

use super::cie::{CieSky, normsc};
/// gendaylit's efficacy categories (the direct table's last edge is 12.1 there).
use super::efficacy::CLEARNESS_EDGES as EDGES;
use super::efficacy::SOLAR_CONSTANT as SOLAR_CONSTANT_E;
use super::efficacy::{self, Flavour};
use super::patches::SkyPatches;
use super::perez::{PEREZ_1993, perezlum};
use super::solar::{SunPosition, sunrise_sunset};
use crate::formats::weather::Site;
use crate::radiometry::WHITE_EFFICACY;
use std::f64::consts::PI;

/// gendaylit's default dew point (deg C): precipitable water `exp(0.07 Td - 0.075) = 2`.
pub use super::efficacy::GENDAYLIT_DEW_POINT;

/// gendaylit's clearness limits: the first and last category edges.
const CLEAR_INF: f64 = EDGES[0];
const CLEAR_SUP: f64 = EDGES[8];
const SOLAR_CONSTANT_L: f64 = 127500.0;
const HALF_SUN_ANGLE_DEG: f64 = 0.2665;
const BRIGHT_INF: f64 = 0.01;
const BRIGHT_SUP: f64 = 0.6;

/// The 145 Tregenza directions gendaylit integrates over: (zenith angle, azimuth) in degrees.
fn tregenza_directions() -> impl Iterator<Item = (f64, f64)> {
    const ROWS: [(f64, usize); 8] = [
        (84.0, 30),
        (72.0, 30),
        (60.0, 24),
        (48.0, 24),
        (36.0, 18),
        (24.0, 12),
        (12.0, 6),
        (0.0, 1),
    ];
    ROWS.into_iter()
        .flat_map(|(theta, n)| (0..n).map(move |j| (theta, 360.0 / n as f64 * j as f64)))
}

/// What gendaylit is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GendaylitInput {
    /// `-P epsilon delta`.
    Perez { epsilon: f64, delta: f64 },
    /// `-W` direct normal and diffuse horizontal irradiance (W/m^2).
    DirectNormalIrradiance { direct: f64, diffuse: f64 },
    /// `-G` direct horizontal and diffuse horizontal irradiance (W/m^2).
    DirectHorizontalIrradiance { direct: f64, diffuse: f64 },
    /// `-L` direct normal and diffuse horizontal illuminance (lx).
    DirectNormalIlluminance { direct: f64, diffuse: f64 },
    /// `-E` global horizontal irradiance (W/m^2), split with the Erbs model.
    GlobalHorizontalIrradiance(f64),
}

/// gendaylit's `-O` output unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GendaylitOutput {
    /// `-O0`: visible radiance W/sr/m^2 (luminance / 179), the default.
    #[default]
    Visible,
    /// `-O1`: solar radiance W/sr/m^2.
    Solar,
    /// `-O2`: luminance cd/m^2.
    Luminance,
}

/// gendaylit's options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GendaylitOptions {
    pub input: GendaylitInput,
    pub output: GendaylitOutput,
    /// `+s` (default) / `-s`: write the sun source.
    pub sun: bool,
    /// `-c`: no sun and no 87 deg altitude cap.
    pub cloudy: bool,
    /// `-g` ground reflectance (0.2).
    pub ground_reflectance: f64,
    /// `-d` dew point (deg C); values outside [-40, 40] fall back to the default.
    pub dew_point: f64,
}

impl GendaylitOptions {
    pub fn new(input: GendaylitInput) -> Self {
        GendaylitOptions {
            input,
            output: GendaylitOutput::Visible,
            sun: true,
            cloudy: false,
            ground_reflectance: 0.2,
            dew_point: GENDAYLIT_DEW_POINT,
        }
    }
}

/// A sky as gendaylit describes it.
#[derive(Debug, Clone, PartialEq)]
pub struct GendaylitSky {
    /// `perezlum.cal` arguments A1..A10 (all of A1..A7 zero for an error sky).
    pub args: [f64; 10],
    /// Sun source radiance if gendaylit writes a sun (`Some(0.0)`: a black sun, which it
    /// writes when epsilon is 1).
    pub solar: Option<f64>,
    /// Sky clearness, brightness and precipitable water as printed in its comment.
    pub epsilon: f64,
    pub delta: f64,
    pub precip_water: f64,
    /// True for gendaylit's "error sky" (only the sky function, all zero).
    pub error: bool,
}

impl GendaylitSky {
    /// Sky radiance toward unit direction `dir` (`perezlum.cal`'s `skybright`).
    pub fn radiance(&self, dir: [f64; 3]) -> f64 {
        perezlum(dir, &self.args)
    }

    /// The sky as daylight-coefficient bins see it: per bin of `patches`, the mean radiance
    /// over the bin's solid angle (`n` x `n` stratified directions, uniform in solid angle,
    /// [`SkyPatches::sample`]); bin 0 is the whole lower hemisphere. A daylight coefficient
    /// is the bin's light per unit uniform radiance, so the solid-angle mean is the value
    /// that reproduces the continuous sky for a sensor that sees the bin evenly. The mean
    /// rather than the value at the centre matters around the horizon, where
    /// `perezlum.cal` blends the sky into the ground brightness A2 (`(Dz + 1.01)^10`
    /// weights: 10 % ground at the lowest Tregenza centre, 6 deg up, 45 % at the horizon).
    pub fn bin_radiances(&self, patches: &SkyPatches, n: usize) -> Vec<f64> {
        (0..patches.len())
            .map(|i| self.bin_radiance(patches, i, n))
            .collect()
    }

    /// [`GendaylitSky::bin_radiances`] of bin `i` alone.
    pub fn bin_radiance(&self, patches: &SkyPatches, i: usize, n: usize) -> f64 {
        let n = n.max(1);
        let k = 1.0 / n as f64;
        let mut sum = 0.0;
        for a in 0..n {
            for b in 0..n {
                let d = patches.sample(i, (a as f64 + 0.5) * k, (b as f64 + 0.5) * k);
                sum += self.radiance(d);
            }
        }
        sum * k * k
    }

    /// gendaylit for a date and time (local standard time, or solar time), gensky's site
    /// conventions. Returns the sun position too.
    pub fn for_date(
        site: &Site,
        month: u32,
        day: u32,
        hour: f64,
        solar_time: bool,
        year: Option<i32>,
        o: &GendaylitOptions,
    ) -> (SunPosition, GendaylitSky) {
        let pos = SunPosition::gensky(site, month, day, hour, solar_time, year);
        let (rise, set) = sunrise_sunset(site, month, day);
        if pos.solar_time < rise || pos.solar_time > set {
            return (pos, error_sky(pos.altitude, pos.azimuth, 0.0, 0.0, o));
        }
        let jd = super::solar::day_of_year(month, day) as f64;
        (pos, GendaylitSky::new(pos.altitude, pos.azimuth, jd, o))
    }

    /// gendaylit for a solar altitude and azimuth (radians, azimuth west of south) on day
    /// `daynumber` (gendaylit's `-ang` uses day 0).
    pub fn new(altitude: f64, azimuth: f64, daynumber: f64, o: &GendaylitOptions) -> Self {
        let mut s = State::new(altitude, daynumber, o);
        s.compute(azimuth, o)
            .unwrap_or_else(|| error_sky(s.altitude, azimuth, s.eps, s.delta, o))
    }
}

fn sun_dir(alt: f64, azi: f64) -> [f64; 3] {
    [-azi.sin() * alt.cos(), -azi.cos() * alt.cos(), alt.sin()]
}

fn error_sky(alt: f64, azi: f64, eps: f64, delta: f64, o: &GendaylitOptions) -> GendaylitSky {
    let d = sun_dir(alt, azi);
    GendaylitSky {
        args: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, d[0], d[1], d[2]],
        solar: None,
        epsilon: eps,
        delta,
        precip_water: Flavour::Gendaylit.precipitable_water(o.dew_point),
        error: true,
    }
}

/// gendaylit's globals for one run.
struct State {
    altitude: f64,
    /// Solar zenith angle in degrees (clamped to 90 by the air mass, as gendaylit).
    zenith_deg: f64,
    daynumber: f64,
    w: f64,
    eps: f64,
    delta: f64,
    dir_irr: f64,
    dif_irr: f64,
    dir_ill: f64,
    dif_ill: f64,
}

impl State {
    fn new(altitude: f64, daynumber: f64, o: &GendaylitOptions) -> State {
        let altitude = if !o.cloudy && altitude > 87f64.to_radians() {
            87f64.to_radians()
        } else {
            altitude
        };
        State {
            altitude,
            zenith_deg: 90.0 - altitude * 180.0 / PI,
            daynumber,
            w: Flavour::Gendaylit.precipitable_water(o.dew_point),
            eps: 0.0,
            delta: 0.0,
            dir_irr: 0.0,
            dif_irr: 0.0,
            dir_ill: 0.0,
            dif_ill: 0.0,
        }
    }

    fn z(&self) -> f64 {
        self.zenith_deg * PI / 180.0
    }

    fn air_mass(&mut self) -> f64 {
        if self.zenith_deg > 90.0 {
            self.zenith_deg = 90.0;
        }
        efficacy::air_mass(self.z())
    }

    fn brightness(&mut self) -> f64 {
        self.dif_irr * self.air_mass() / (SOLAR_CONSTANT_E * efficacy::eccentricity(self.daynumber))
    }

    fn clearness(&self) -> f64 {
        efficacy::clearness(self.dif_irr, self.dir_irr, self.z())
    }

    fn clamp_parameters(&mut self) {
        self.eps = Flavour::Gendaylit.clamp_clearness(self.eps);
        self.delta = self.delta.clamp(BRIGHT_INF, BRIGHT_SUP);
    }

    /// Efficacy category (`None` when epsilon is outside every bin).
    fn category(&self) -> Option<usize> {
        Some(efficacy::category(self.eps)).filter(|&c| c < 8)
    }

    fn diffuse_efficacy(&mut self) -> Option<f64> {
        self.clamp_parameters();
        let cat = self.category()?;
        Some(efficacy::diffuse_efficacy(
            cat,
            self.w,
            self.z(),
            self.delta,
        ))
    }

    fn direct_efficacy(&self) -> f64 {
        // gendaylit's direct table's last edge is 12.1, so a clamped epsilon always finds a bin.
        let cat = self.category().unwrap_or(7);
        efficacy::direct_efficacy(cat, self.w, self.z(), self.delta)
    }

    /// `check_irradiances`: negative values become 0; `None` = error sky.
    fn check_irradiances(&mut self) -> Option<()> {
        self.dir_irr = self.dir_irr.max(0.0);
        self.dif_irr = self.dif_irr.max(0.0);
        if (self.dir_irr + self.dif_irr == 0.0 && self.altitude > 0.0)
            || self.dir_irr > SOLAR_CONSTANT_E
        {
            return None;
        }
        Some(())
    }

    fn check_illuminances(&mut self) -> Option<()> {
        self.dir_ill = self.dir_ill.max(0.0);
        self.dif_ill = self.dif_ill.max(0.0);
        if (self.dir_ill + self.dif_ill == 0.0 && self.altitude > 0.0)
            || self.dir_ill > SOLAR_CONSTANT_L
        {
            return None;
        }
        Some(())
    }

    fn illuminances(&mut self, output: GendaylitOutput) -> Option<()> {
        if output != GendaylitOutput::Solar {
            self.dif_ill = self.dif_irr * self.diffuse_efficacy()?;
            self.dir_ill = self.dir_irr * self.direct_efficacy();
            self.check_illuminances()?;
        }
        Some(())
    }

    fn irradiance_input(&mut self, output: GendaylitOutput) -> Option<()> {
        self.check_irradiances()?;
        self.delta = self.brightness();
        self.eps = self.clearness();
        self.clamp_parameters();
        self.illuminances(output)
    }

    /// Perez coefficients a..e from gendaylit's float table.
    fn coefficients(&self) -> [f64; 5] {
        let mut delta = self.delta;
        if self.eps > 1.065 && self.eps < 2.8 && delta < 0.2 {
            delta = 0.2;
        }
        // gendaylit's get_numlin takes epsilon as a float and compares it with doubles.
        let e = self.eps as f32 as f64;
        let lin = EDGES[1..8].iter().take_while(|&&edge| e >= edge).count();
        let x = |k: usize| PEREZ_1993[lin][k] as f32 as f64;
        let z = self.z();
        let l = |i: usize| x(4 * i) + x(4 * i + 1) * z + delta * (x(4 * i + 2) + x(4 * i + 3) * z);
        let mut p = [l(0), l(1), l(2), l(3), l(4)];
        if lin == 0 {
            p[2] = (delta * (x(8) + x(9) * z)).powf(x(10)).exp() - x(11);
            p[3] = -(delta * (x(12) + x(13) * z)).exp() + x(14) + delta * x(15);
        }
        p
    }

    fn compute(&mut self, azimuth: f64, o: &GendaylitOptions) -> Option<GendaylitSky> {
        match o.input {
            GendaylitInput::Perez { epsilon, delta } => {
                self.eps = epsilon;
                self.delta = delta;
                self.clamp_parameters();
                let m = self.air_mass();
                self.dif_irr =
                    self.delta / m * (SOLAR_CONSTANT_E * efficacy::eccentricity(self.daynumber));
                let z3 = self.z().powi(3);
                self.dir_irr = self.dif_irr * ((self.eps - 1.0) * (1.0 + 1.041 * z3));
                self.check_irradiances()?;
                self.illuminances(o.output)?;
            }
            GendaylitInput::DirectNormalIrradiance { direct, diffuse } => {
                self.dir_irr = direct;
                self.dif_irr = diffuse;
                self.irradiance_input(o.output)?;
            }
            GendaylitInput::DirectHorizontalIrradiance { direct, diffuse } => {
                if self.altitude <= 0.0 {
                    self.dir_irr = 0.0;
                    self.dif_irr = 0.0;
                } else {
                    self.dir_irr = direct / self.altitude.sin();
                    self.dif_irr = diffuse;
                }
                self.irradiance_input(o.output)?;
            }
            GendaylitInput::GlobalHorizontalIrradiance(glob) => {
                if self.altitude <= 0.0 {
                    self.dir_irr = 0.0;
                    self.dif_irr = 0.0;
                } else {
                    let s0 = SOLAR_CONSTANT_E
                        * efficacy::eccentricity(self.daynumber)
                        * self.altitude.sin();
                    let glob = if glob > s0 { s0 * 0.999 } else { glob };
                    let kt = glob / s0;
                    // Erbs et al. (1982) diffuse fraction, as gendaylit -E (no branch for
                    // kt >= 1, which the clamp above prevents).
                    self.dif_irr = if kt <= 0.22 {
                        glob * (1.0 - 0.09 * kt)
                    } else if kt <= 0.8 {
                        glob * (0.9511 - 0.1604 * kt + 4.388 * kt.powi(2) - 16.638 * kt.powi(3)
                            + 12.336 * kt.powi(4))
                    } else {
                        glob * 0.165
                    };
                    self.dir_irr = (glob - self.dif_irr) / self.altitude.sin();
                }
                self.irradiance_input(o.output)?;
            }
            GendaylitInput::DirectNormalIlluminance { direct, diffuse } => {
                self.dir_ill = direct;
                self.dif_ill = diffuse;
                self.check_illuminances()?;
                self.dif_irr = self.dif_ill * SOLAR_CONSTANT_E / SOLAR_CONSTANT_L;
                self.dir_irr = self.dir_ill * SOLAR_CONSTANT_E / SOLAR_CONSTANT_L;
                self.eps = self.clearness();
                self.delta = self.brightness();
                self.clamp_parameters();
                let (mut t1, mut t2) = (0.1, 0.1);
                let mut counter = 0;
                while ((self.dif_irr - t1).abs() > 10.0
                    || (self.dir_irr - t2).abs() > 10.0
                    || !(self.eps < CLEAR_INF || self.eps > CLEAR_SUP)
                    || !(self.delta < BRIGHT_INF || self.delta > BRIGHT_SUP))
                    && counter != 9
                {
                    t1 = self.dif_irr;
                    t2 = self.dir_irr;
                    counter += 1;
                    self.dif_irr = self.dif_ill / self.diffuse_efficacy()?;
                    let d_eff = self.direct_efficacy();
                    self.dir_irr = if d_eff < 0.1 {
                        0.0
                    } else {
                        self.dir_ill / d_eff
                    };
                    self.delta = self.brightness();
                    self.eps = self.clearness();
                    self.clamp_parameters();
                }
                self.clamp_parameters();
            }
        }

        if !(CLEAR_INF..CLEAR_SUP).contains(&self.eps) {
            return None;
        }
        let p = self.coefficients();
        let z = self.z();
        let lv = |dzeta: f64, gamma: f64| {
            (1.0 + p[0] * (p[1] / dzeta.cos()).exp())
                * (1.0 + p[2] * (p[3] * gamma).exp() + p[4] * gamma.cos() * gamma.cos())
        };
        let mut integ = 0.0;
        for (theta, phi) in tregenza_directions() {
            let (t, f) = (theta * (PI / 180.0), phi * (PI / 180.0));
            let c = z.cos() * t.cos() + z.sin() * t.sin() * f.cos();
            let gamma = if c > 1.0 { 0.0 } else { c.acos() };
            // gendaylit stores the 145 luminances as float.
            integ += (lv(t, gamma) as f32 as f64) * t.cos();
        }
        integ *= 2.0 * PI / 145.0;
        let a1 = match o.output {
            GendaylitOutput::Visible => self.dif_ill / integ / WHITE_EFFICACY,
            GendaylitOutput::Solar => self.dif_irr / integ,
            GendaylitOutput::Luminance => self.dif_ill / integ,
        };
        let disc = 2.0 * PI * (1.0 - (HALF_SUN_ANGLE_DEG * PI / 180.0).cos());
        let solar = match o.output {
            GendaylitOutput::Visible => self.dir_ill / disc / WHITE_EFFICACY,
            GendaylitOutput::Solar => self.dir_irr / disc,
            GendaylitOutput::Luminance => self.dir_ill / disc,
        };
        let zenith = lv(0.0, z) * a1;
        let alt = self.altitude;
        let norm = if self.eps >= 6.0 {
            let f2 =
                0.274 * (0.91 + 10.0 * (-3.0 * (PI / 2.0 - alt)).exp() + 0.45 * alt.sin().powi(2));
            normsc(CieSky::Clear, alt) / f2 / PI
        } else if self.eps > 1.0 {
            let f2 = (2.739 + 0.9891 * (0.3119 + 2.6 * alt).sin())
                * (-(PI / 2.0 - alt) * (0.4441 + 1.48 * alt)).exp();
            normsc(CieSky::Intermediate, alt) / f2 / PI
        } else {
            0.777778
        };
        let sun = o.sun && !o.cloudy;
        let d = sun_dir(alt, azimuth);
        let mut ground = zenith * norm;
        if sun && self.eps > 1.0 {
            ground += 6.8e-5 / PI * solar * d[2];
        }
        ground *= o.ground_reflectance;
        if p[1] > 0.0 {
            return None;
        }
        Some(GendaylitSky {
            args: [a1, ground, p[0], p[1], p[2], p[3], p[4], d[0], d[1], d[2]],
            solar: sun.then_some(if self.eps > 1.0 { solar } else { 0.0 }),
            epsilon: self.eps,
            delta: self.delta,
            precip_water: self.w,
            error: false,
        })
    }
}
