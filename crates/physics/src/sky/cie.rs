//! # CIE skies as `gensky` describes them, and `skybright.cal`
//!
//! Radiance's `gensky` (`LBNL-ETA/Radiance: src/gen/gensky.c`) turns a sun position and a
//! sky type into the arguments of the `skybright.cal` brightness function
//! (`src/gen/skybright.cal`) plus an optional sun source. Everything needed to evaluate that
//! sky at any direction natively is here.
//!
//! ```text
//! sky types (A1): 1 CIE clear, 2 CIE overcast, 3 uniform, 4 CIE intermediate
//! altitude capped at 87 deg except for overcast/uniform; sun = (-sin az cos alt,
//!   -cos az cos alt, sin alt), az west of south (see crate::sky::solar)
//! normalisation  uniform 1; overcast 0.777778;
//!   clear:  F2 = 0.274 (0.91 + 10 exp(-3 (pi/2 - alt)) + 0.45 sin^2 alt)
//!   inter.: F2 = (2.739 + 0.9891 sin(0.3119 + 2.6 alt)) exp(-(pi/2 - alt)(0.4441 + 1.48 alt))
//!   norm = P(x) / F2 / pi,  x = (alt - pi/4) / (pi/4), P a 4th-order polynomial
//!     clear {2.766521, 0.547665, -0.369832, 0.009237, 0.059229}
//!     inter.{3.5556, -2.7152, -1.3081, 1.0660, 0.60227}
//! zenith brightness (W/sr/m^2; -b given, or -B horizontal diffuse irradiance / (norm pi)):
//!   overcast/uniform 8.6 sin alt + 0.123; clear (1.376 T - 1.81) tan alt + 0.38;
//!   intermediate: mean of the two; negative -> 0, else x 1000 / 203 (SKYEFFICACY)
//! ground = zenith x norm  (printed "Ground ambient level")
//!   + 6e-5 / pi x solar x sin alt   (clear/intermediate with the sun above the horizon,
//!                                    even with -s/-i: only the sun source is left out)
//!   then x ground reflectance (-g, 0.2)
//! solar radiance = 1.5e9 / 208 (1.147 - 0.147 / max(sin alt, 0.16))  (x 0.15 intermediate),
//!   or -r radiance, or -R normal irradiance / (5.98e-5 sin alt)
//! skybright(dir) = wmean((Dz+1.01)^10, sky(dir), (Dz+1.01)^-10, A3)
//!   clear        A2 (0.91 + 10 e^{-3 gamma} + 0.45 cos^2 gamma)(1 - e^{-0.32/Dz}) / A4
//!                (the last factor is 1 when Dz <= 0.01)
//!   overcast     A2 (1 + 2 Dz) / 3
//!   uniform      A2
//!   intermediate A2 ((1.35 sin(5.631 - 3.59 eta) + 3.12) sin(4.396 - 2.6 zt) + 6.37 - eta)
//!                / 2.326 exp(-0.563 gamma ((2.629 - eta)(1.562 - zt) + 0.812)) / A4
//!   gamma = angle to the sun, eta = zenith angle of dir, zt = zenith angle of the sun
//! ```

use super::perez::horizon_blend;
use super::solar::SunPosition;
use crate::formats::weather::Site;
use std::f64::consts::PI;

/// Radiance's `SKYEFFICACY` (lm/W, `src/common/color.h`).
pub const SKY_EFFICACY: f64 = 203.0;
/// Radiance's `SUNEFFICACY` (lm/W, `src/common/color.h`).
pub const SUN_EFFICACY: f64 = 208.0;

/// gensky's sky type, numbered as `skybright.cal`'s `A1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CieSky {
    /// CIE clear sky (`+s`/`-s`), A1 = 1.
    Clear = 1,
    /// CIE overcast sky (`-c`), A1 = 2.
    Overcast = 2,
    /// Uniform cloudy sky (`-u`), A1 = 3.
    Uniform = 3,
    /// CIE intermediate sky (`+i`/`-i`), A1 = 4.
    Intermediate = 4,
}

impl CieSky {
    fn overcast(self) -> bool {
        matches!(self, CieSky::Overcast | CieSky::Uniform)
    }
}

/// How a brightness is given: gensky's lowercase option (radiance) or uppercase (irradiance).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Brightness {
    /// Computed by gensky's formulas (option not given).
    Default,
    /// `-b` zenith radiance / `-r` solar radiance (W/sr/m^2).
    Radiance(f64),
    /// `-B` diffuse horizontal irradiance / `-R` direct normal irradiance (W/m^2).
    Irradiance(f64),
}

/// gensky's options beyond the sun position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GenskyOptions {
    pub sky: CieSky,
    /// Whether the sun source is wanted (`+s`, `+i`); ignored for overcast skies.
    pub sun: bool,
    /// Zenith brightness (`-b`/`-B`).
    pub zenith: Brightness,
    /// Sun brightness (`-r`/`-R`).
    pub solar: Brightness,
    /// Linke turbidity (`-t`, 2.45).
    pub turbidity: f64,
    /// Ground reflectance (`-g`, 0.2).
    pub ground_reflectance: f64,
}

impl Default for GenskyOptions {
    fn default() -> Self {
        GenskyOptions {
            sky: CieSky::Clear,
            sun: true,
            zenith: Brightness::Default,
            solar: Brightness::Default,
            turbidity: 2.45,
            ground_reflectance: 0.2,
        }
    }
}

/// A sky as gensky describes it.
#[derive(Debug, Clone, PartialEq)]
pub struct CieSkyDescription {
    pub sky: CieSky,
    /// Solar altitude used (radians, after the 87 deg cap) and azimuth (west of south).
    pub altitude: f64,
    pub azimuth: f64,
    /// Unit vector toward the sun (A5..A7).
    pub sun_dir: [f64; 3],
    /// Zenith radiance (A2), W/sr/m^2.
    pub zenith: f64,
    /// Ground radiance (A3), W/sr/m^2, reflectance applied.
    pub ground: f64,
    /// Ground ambient level gensky prints (zenith x normalisation, before sun and reflectance).
    pub ambient: f64,
    /// Normalisation factor A4 (`F2`; 0 for overcast/uniform skies, which do not use it).
    pub f2: f64,
    /// Sun radiance (W/sr/m^2) if gensky writes a sun source.
    pub solar: Option<f64>,
    /// Whether gensky warned about (and applied) the 87 deg cap.
    pub capped: bool,
}

/// gensky's polynomial normalisation `P(x)` (`normsc`), shared with gendaylit.
pub(crate) fn normsc(sky: CieSky, alt: f64) -> f64 {
    const CLEAR: [f64; 5] = [2.766521, 0.547665, -0.369832, 0.009237, 0.059229];
    const INTER: [f64; 5] = [3.5556, -2.7152, -1.3081, 1.0660, 0.60227];
    let nf = if sky == CieSky::Intermediate {
        &INTER
    } else {
        &CLEAR
    };
    let x = (alt - PI / 4.0) / (PI / 4.0);
    nf.iter().rev().fold(0.0, |acc, &c| acc * x + c)
}

impl CieSkyDescription {
    /// gensky's computation for a solar altitude/azimuth (radians; azimuth west of south).
    pub fn new(altitude: f64, azimuth: f64, o: &GenskyOptions) -> CieSkyDescription {
        let sky = o.sky;
        let mut alt = altitude;
        let capped = !sky.overcast() && alt > 87f64.to_radians();
        if capped {
            alt = 87f64.to_radians();
        }
        let sun_dir = [
            -azimuth.sin() * alt.cos(),
            -azimuth.cos() * alt.cos(),
            alt.sin(),
        ];
        let mut f2 = 0.0;
        let norm = match sky {
            CieSky::Uniform => 1.0,
            CieSky::Overcast => 0.777778,
            CieSky::Clear => {
                f2 = 0.274
                    * (0.91
                        + 10.0 * (-3.0 * (PI / 2.0 - alt)).exp()
                        + 0.45 * sun_dir[2] * sun_dir[2]);
                normsc(sky, alt) / f2 / PI
            }
            CieSky::Intermediate => {
                f2 = (2.739 + 0.9891 * (0.3119 + 2.6 * alt).sin())
                    * (-(PI / 2.0 - alt) * (0.4441 + 1.48 * alt)).exp();
                normsc(sky, alt) / f2 / PI
            }
        };
        let zenith = match o.zenith {
            Brightness::Irradiance(e) => e / (norm * PI),
            Brightness::Radiance(l) => l,
            Brightness::Default => {
                let mut z = if sky.overcast() {
                    8.6 * sun_dir[2] + 0.123
                } else {
                    (1.376 * o.turbidity - 1.81) * alt.tan() + 0.38
                };
                if sky == CieSky::Intermediate {
                    z = (z + 8.6 * sun_dir[2] + 0.123) / 2.0;
                }
                if z < 0.0 {
                    0.0
                } else {
                    z * 1000.0 / SKY_EFFICACY
                }
            }
        };
        let ambient = zenith * norm;
        let mut ground = ambient;
        let solar_wanted =
            !matches!(o.solar, Brightness::Radiance(v) | Brightness::Irradiance(v) if v <= 0.0);
        let mut solar = None;
        if !sky.overcast() && sun_dir[2] > 0.0 && solar_wanted {
            let s = match o.solar {
                Brightness::Irradiance(e) => e / (5.98e-5 * sun_dir[2]),
                Brightness::Radiance(l) => l,
                Brightness::Default => {
                    let s = 1.5e9 / SUN_EFFICACY * (1.147 - 0.147 / sun_dir[2].max(0.16));
                    if sky == CieSky::Intermediate {
                        s * 0.15
                    } else {
                        s
                    }
                }
            };
            ground += 6e-5 / PI * s * sun_dir[2];
            if o.sun {
                solar = Some(s);
            }
        }
        CieSkyDescription {
            sky,
            altitude: alt,
            azimuth,
            sun_dir,
            zenith,
            ground: ground * o.ground_reflectance,
            ambient,
            f2,
            solar,
            capped,
        }
    }

    /// gensky's computation for a date and time (see [`SunPosition::gensky`]).
    pub fn for_date(
        site: &Site,
        month: u32,
        day: u32,
        hour: f64,
        solar_time: bool,
        year: Option<i32>,
        o: &GenskyOptions,
    ) -> (SunPosition, CieSkyDescription) {
        let pos = SunPosition::gensky(site, month, day, hour, solar_time, year);
        (pos, CieSkyDescription::new(pos.altitude, pos.azimuth, o))
    }

    /// The real arguments of `skybright.cal` as gensky writes them: 3 for overcast/uniform
    /// skies, 7 otherwise.
    pub fn args(&self) -> Vec<f64> {
        let mut a = vec![self.sky as u8 as f64, self.zenith, self.ground];
        if !self.sky.overcast() {
            a.extend([self.f2, self.sun_dir[0], self.sun_dir[1], self.sun_dir[2]]);
        }
        a
    }

    /// Sky radiance (W/sr/m^2) toward unit direction `dir` (`skybright.cal`'s `skybr`,
    /// evaluated with the full-precision arguments).
    pub fn radiance(&self, dir: [f64; 3]) -> f64 {
        skybright(dir, &self.args())
    }

    /// The scene text gensky prints after its comment lines (light/source for the sun,
    /// the `skyfunc` brightfunc), formatted exactly as gensky.
    pub fn to_rad(&self) -> String {
        let mut s = String::new();
        if let Some(b) = self.solar {
            let b = c_exp(b, 3);
            s.push_str(&format!("\nvoid light solar\n0\n0\n3 {b} {b} {b}\n"));
            s.push_str(&format!(
                "\nsolar source sun\n0\n0\n4 {:.6} {:.6} {:.6} 0.5\n",
                self.sun_dir[0], self.sun_dir[1], self.sun_dir[2]
            ));
        }
        s.push_str("\nvoid brightfunc skyfunc\n2 skybr skybright.cal\n0\n");
        if self.sky.overcast() {
            s.push_str(&format!(
                "3 {} {} {}\n",
                self.sky as u8,
                c_exp(self.zenith, 3),
                c_exp(self.ground, 3)
            ));
        } else {
            s.push_str(&format!(
                "7 {} {} {} {} {:.6} {:.6} {:.6}\n",
                self.sky as u8,
                c_exp(self.zenith, 3),
                c_exp(self.ground, 3),
                c_exp(self.f2, 3),
                self.sun_dir[0],
                self.sun_dir[1],
                self.sun_dir[2]
            ));
        }
        s
    }
}

/// C's `%.{prec}e` (exponent with sign and at least two digits).
pub fn c_exp(v: f64, prec: usize) -> String {
    let s = format!("{v:.prec$e}");
    match s.split_once('e') {
        Some((m, e)) => {
            let (sign, digits) = match e.strip_prefix('-') {
                Some(d) => ('-', d),
                None => ('+', e),
            };
            format!("{m}e{sign}{digits:0>2}")
        }
        None => s,
    }
}

/// `skybright.cal`'s `skybr` for a unit direction and gensky's real arguments `a`
/// (`A1..A3`, or `A1..A7`). Missing arguments read as 0.
pub fn skybright(dir: [f64; 3], a: &[f64]) -> f64 {
    let arg = |i: usize| a.get(i - 1).copied().unwrap_or(0.0);
    let acos = |x: f64| x.clamp(-1.0, 1.0).acos();
    let dz = dir[2];
    let sky = match arg(1).round() as i64 {
        2 => arg(2) * (1.0 + 2.0 * dz) / 3.0,
        3 => arg(2),
        t @ (1 | 4) => {
            let cosgamma = dir[0] * arg(5) + dir[1] * arg(6) + dz * arg(7);
            let gamma = acos(cosgamma);
            if t == 1 {
                let f = if dz - 0.01 > 0.0 {
                    1.0 - (-0.32 / dz).exp()
                } else {
                    1.0
                };
                arg(2) * (0.91 + 10.0 * (-3.0 * gamma).exp() + 0.45 * cosgamma * cosgamma) * f
                    / arg(4)
            } else {
                let zt = acos(arg(7));
                let eta = acos(dz);
                arg(2)
                    * ((1.35 * (5.631 - 3.59 * eta).sin() + 3.12) * (4.396 - 2.6 * zt).sin() + 6.37
                        - eta)
                    / 2.326
                    * (gamma * -0.563 * ((2.629 - eta) * (1.562 - zt) + 0.812)).exp()
                    / arg(4)
            }
        }
        _ => 0.0,
    };
    horizon_blend(dz, sky, arg(3))
}
