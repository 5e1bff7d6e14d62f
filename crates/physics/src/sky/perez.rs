//! # Perez all-weather sky model (gendaymtx, gendaylit's `perezlum.cal`)
//!
//! Perez, R., R. Seals, J. Michalsky (1993), "All-Weather Model for Sky Luminance
//! Distribution - Preliminary Configuration and Validation", Solar Energy 50(3):235-245
//! (and its erratum, Solar Energy 51(5):423), as Radiance's `gendaymtx` applies it per time
//! step (`LBNL-ETA/Radiance: src/gen/gendaymtx.c: ComputeSky, AddDirect`).
//!
//! Relative luminance of a sky point at zenith angle `zeta` and angle `gamma` from the sun:
//!
//! ```text
//! lv(zeta, gamma) = (1 + a exp(b / cos zeta)) (1 + c exp(d gamma) + e cos^2 gamma)
//! x = x1 + x2 Z + delta (x3 + x4 Z)    for x in a..e           (eq. 6, Table 1)
//! category 0 only:  c = exp((delta (c1 + c2 Z))^c3) - c4       (eq. 7)
//!                   d = -exp(delta (d1 + d2 Z)) + d3 + delta d4 (eq. 8)
//! delta floored at 0.2 when 1.065 < epsilon < 2.8 (gendaymtx)
//! ```
//!
//! with `Z` the clamped solar zenith angle and epsilon, delta, the category and the
//! illuminances from [`crate::sky::efficacy`]. One gendaymtx column (one time step):
//!
//! ```text
//! ground (bin 0)  = (E_dif + E_dir sin(alt)+) / (pi 179)           x ground reflectance
//! sky patch i     = lv_i E_dif / (179 sum_k lv_k sin(alt_k) omega_k)  x sky colour
//!                   (lv at the patch centre; uniform lv = 1, sum = pi, if the sum <= 1e-6)
//! sun             = E_dir / 179 spread over the nsuns = 4 patches nearest the sun
//!                   (largest centre . sun), weights w = 1 / (1.002 - centre . sun),
//!                   patch k gets w_k / sum w  E_dir / (179 omega_k)   x sun colour
//!                   (-5 deg: 1 patch and a fixed omega = pi (deg pi / 360)^2)
//! ```
//!
//! Colour is applied last: [`SkyVector`] holds the scalar parts (ground, sky, sun) and
//! [`SkyVector::to_channels`] multiplies each by its own colour of any channel count
//! (gendaymtx: ground `-g .2 .2 .2`, sky `-c .96 1.004 1.118`, sun white; `-d` zeroes the
//! sky and ground colours, `-s` the sun's). Radiance units: W sr^-1 m^-2 (luminance / 179).

use super::efficacy::{DEFAULT_DEW_POINT, SkyState};
use super::patches::{SkyPatches, direction};
use super::solar::SunPosition;
use crate::formats::weather::Site;
use crate::radiometry::WHITE_EFFICACY;
use std::f64::consts::PI;

/// Perez 1993 coefficients per clearness category: rows `a1 a2 a3 a4, b1.., c1.., d1..,
/// e1..` (Perez, Seals, Michalsky 1993, Solar Energy 50(3), Table 1), as used by gendaymtx.
pub const PEREZ_1993: [[f64; 20]; 8] = [
    // epsilon 1.000 - 1.065
    [
        1.3525, -0.2576, -0.2690, -1.4366, -0.7670, 0.0007, 1.2734, -0.1233, 2.8000, 0.6004,
        1.2375, 1.0000, 1.8734, 0.6297, 0.9738, 0.2809, 0.0356, -0.1246, -0.5718, 0.9938,
    ],
    // 1.065 - 1.230
    [
        -1.2219, -0.7730, 1.4148, 1.1016, -0.2054, 0.0367, -3.9128, 0.9156, 6.9750, 0.1774, 6.4477,
        -0.1239, -1.5798, -0.5081, -1.7812, 0.1080, 0.2624, 0.0672, -0.2190, -0.4285,
    ],
    // 1.230 - 1.500
    [
        -1.1000, -0.2515, 0.8952, 0.0156, 0.2782, -0.1812, -4.5000, 1.1766, 24.7219, -13.0812,
        -37.7000, 34.8438, -5.0000, 1.5218, 3.9229, -2.6204, -0.0156, 0.1597, 0.4199, -0.5562,
    ],
    // 1.500 - 1.950
    [
        -0.5484, -0.6654, -0.2672, 0.7117, 0.7234, -0.6219, -5.6812, 2.6297, 33.3389, -18.3000,
        -62.2500, 52.0781, -3.5000, 0.0016, 1.1477, 0.1062, 0.4659, -0.3296, -0.0876, -0.0329,
    ],
    // 1.950 - 2.800
    [
        -0.6000, -0.3566, -2.5000, 2.3250, 0.2937, 0.0496, -5.6812, 1.8415, 21.0000, -4.7656,
        -21.5906, 7.2492, -3.5000, -0.1554, 1.4062, 0.3988, 0.0032, 0.0766, -0.0656, -0.1294,
    ],
    // 2.800 - 4.500
    [
        -1.0156, -0.3670, 1.0078, 1.4051, 0.2875, -0.5328, -3.8500, 3.3750, 14.0000, -0.9999,
        -7.1406, 7.5469, -3.4000, -0.1078, -1.0750, 1.5702, -0.0672, 0.4016, 0.3017, -0.4844,
    ],
    // 4.500 - 6.200
    [
        -1.0000, 0.0211, 0.5025, -0.5119, -0.3000, 0.1922, 0.7023, -1.6317, 19.0000, -5.0000,
        1.2438, -1.9094, -4.0000, 0.0250, 0.3844, 0.2656, 1.0468, -0.3788, -2.4517, 1.4656,
    ],
    // 6.200 - 12.01
    [
        -1.0500, 0.0289, 0.4260, 0.3590, -0.3250, 0.1156, 0.7781, 0.0025, 31.0625, -14.5000,
        -46.1148, 55.3750, -7.2312, 0.4050, 13.3500, 0.6234, 1.5000, -0.6426, 1.8564, 0.5636,
    ],
];

/// Radiance's `FTINY` (`src/common/fvect.h`), gendaymtx's zero-sky threshold.
const FTINY: f64 = 1e-6;

/// Perez coefficients a, b, c, d, e for a category, clearness, brightness and (clamped) solar
/// zenith angle `z` (radians), with gendaymtx's brightness floor and category-0 forms.
pub fn coefficients(category: usize, epsilon: f64, delta: f64, z: f64) -> [f64; 5] {
    let delta = if epsilon > 1.065 && epsilon < 2.8 {
        delta.max(0.2)
    } else {
        delta
    };
    let x = &PEREZ_1993[category.min(7)];
    let lin = |i: usize| x[4 * i] + x[4 * i + 1] * z + delta * (x[4 * i + 2] + x[4 * i + 3] * z);
    let mut p = [lin(0), lin(1), lin(2), lin(3), lin(4)];
    if category == 0 {
        p[2] = (delta * (x[8] + x[9] * z)).powf(x[10]).exp() - x[11];
        p[3] = -(delta * (x[12] + x[13] * z)).exp() + x[14] + delta * x[15];
    }
    p
}

/// Relative luminance `(1 + a e^{b / cos zeta})(1 + c e^{d gamma} + e cos^2 gamma)` for
/// zenith angle `zeta` and sun angle `gamma` (radians). May be negative; callers clamp.
pub fn relative_luminance(p: &[f64; 5], gamma: f64, zeta: f64) -> f64 {
    relative_luminance_cos(p, gamma, gamma.cos(), zeta.cos())
}

/// [`relative_luminance`] with the cosines of `gamma` and `zeta` already known (the sky
/// matrix evaluates every patch at every step: the trigonometry is most of its cost).
pub fn relative_luminance_cos(p: &[f64; 5], gamma: f64, cos_gamma: f64, cos_zeta: f64) -> f64 {
    (1.0 + p[0] * (p[1] / cos_zeta).exp())
        * (1.0 + p[2] * (p[3] * gamma).exp() + p[4] * cos_gamma * cos_gamma)
}

/// `perezlum.cal`'s `skybright` for a unit direction and gendaylit's 10 arguments
/// (A1 diffuse normalisation, A2 ground brightness, A3..A7 Perez a..e, A8..A10 sun
/// direction): the Perez sky above the horizon (zenith cosine floored at 0.01), blended
/// into the ground brightness around the horizon by `(Dz + 1.01)^10` weights.
pub fn perezlum(dir: [f64; 3], a: &[f64; 10]) -> f64 {
    // rayinit.cal's robust helpers: Acos clamps its argument, Exp is 0 below -100.
    let exp = |x: f64| if -x - 100.0 > 0.0 { 0.0 } else { x.exp() };
    let cosgamma = dir[0] * a[7] + dir[1] * a[8] + dir[2] * a[9];
    let gamma = cosgamma.clamp(-1.0, 1.0).acos();
    let dz = if dir[2] - 0.01 > 0.0 { dir[2] } else { 0.01 };
    let intersky = a[0]
        * (1.0 + a[2] * exp(a[3] / dz))
        * (1.0 + a[4] * exp(a[5] * gamma) + a[6] * cosgamma * cosgamma);
    horizon_blend(dir[2], intersky, a[1])
}

/// The `wmean((Dz+1.01)^10, sky, (Dz+1.01)^-10, ground)` blend shared by `skybright.cal`
/// and `perezlum.cal`.
pub(crate) fn horizon_blend(dz: f64, sky: f64, ground: f64) -> f64 {
    let a = (dz + 1.01).powi(10);
    let b = (dz + 1.01).powi(-10);
    (a * sky + b * ground) / (a + b)
}

/// How the two irradiance/illuminance values of a time step are given (WEA units).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InputUnits {
    /// Direct normal and diffuse horizontal irradiance, W/m^2 (WEA units 1, EPW).
    #[default]
    DirectNormalIrradiance,
    /// Direct horizontal and diffuse horizontal irradiance, W/m^2 (WEA units 2).
    DirectHorizontalIrradiance,
    /// Direct normal and diffuse horizontal illuminance, lx (WEA units 3).
    DirectNormalIlluminance,
}

/// One weather record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeStep {
    pub month: u32,
    pub day: u32,
    /// Day of year used for the solar position (leap-adjusted, see
    /// [`crate::sky::solar::LeapDayTracker`]).
    pub jd: u32,
    /// Local standard time, decimal hours (WEA: mid-interval, e.g. 12.5).
    pub hour: f64,
    /// Direct value (normal or horizontal, see `units`).
    pub direct: f64,
    /// Diffuse horizontal value.
    pub diffuse: f64,
    pub units: InputUnits,
    /// Surface dew point (deg C); [`DEFAULT_DEW_POINT`] for WEA input.
    pub dew_point: f64,
}

impl TimeStep {
    /// A WEA-style record (units 1, default dew point, no leap-day shift).
    pub fn new(month: u32, day: u32, hour: f64, direct: f64, diffuse: f64) -> TimeStep {
        TimeStep {
            month,
            day,
            jd: super::solar::day_of_year(month, day),
            hour,
            direct,
            diffuse,
            units: InputUnits::DirectNormalIrradiance,
            dew_point: DEFAULT_DEW_POINT,
        }
    }
}

/// gendaymtx's options that change one column (colours are applied in
/// [`SkyVector::to_channels`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PerezOptions {
    /// Sky rotation in degrees (gendaymtx `-r`): sun azimuth is reduced by this.
    pub rotation_deg: f64,
    /// `-5 deg`: put the sun in 1 patch with a fixed solid angle `pi (deg pi/360)^2`.
    pub five_phase_sun_deg: Option<f64>,
    /// `-O1`: output total solar radiance (illuminances replaced by irradiance x 179).
    pub solar_radiance: bool,
    /// `-i minutes`: sunrise/sunset interval correction (0 = off).
    pub interval_minutes: f64,
}

impl Default for PerezOptions {
    fn default() -> Self {
        PerezOptions {
            rotation_deg: 0.0,
            five_phase_sun_deg: None,
            solar_radiance: false,
            interval_minutes: 0.0,
        }
    }
}

/// gendaymtx's default sky colour (`-c .960 1.004 1.118`).
pub const GENDAYMTX_SKY_COLOUR: [f64; 3] = [0.960, 1.004, 1.118];
/// gendaymtx's default ground reflectance (`-g .2 .2 .2`).
pub const GENDAYMTX_GROUND_REFLECTANCE: [f64; 3] = [0.2, 0.2, 0.2];

/// One gendaymtx column before colour: scalar radiances (W sr^-1 m^-2).
#[derive(Debug, Clone, PartialEq)]
pub struct SkyVector {
    /// Ground radiance before the ground reflectance: `(E_dif + E_dir sin alt+) / (pi 179)`.
    pub ground: f64,
    /// Diffuse sky radiance per bin (index 0, the ground, is 0), before the sky colour.
    pub sky: Vec<f64>,
    /// Sun radiance added to patches, before the sun colour: (bin, radiance).
    pub sun: Vec<(usize, f64)>,
    /// Solar position used (altitude radians, azimuth west of south, before rotation).
    pub sun_position: SunPosition,
    /// Perez inputs of this step (`None` at night: all zero).
    pub state: Option<SkyState>,
}

impl SkyVector {
    /// True if gendaymtx counts the sun as up (altitude > -0.2665 deg, half the sun's
    /// 0.533 deg); `gendaymtx -u` skips other steps.
    pub fn sun_in_sky(&self) -> bool {
        self.sun_position.altitude > -(0.533f64 / 2.0).to_radians()
    }

    /// Channel values, `ncomp = colours' length` per bin, bin-major: ground x `ground_refl`,
    /// sky x `sky_colour`, sun x `sun_colour`. gendaymtx default: `GENDAYMTX_*` and white sun;
    /// `-d`: zero sky colour and ground; `-s`: zero sun colour.
    pub fn to_channels(
        &self,
        sky_colour: &[f64],
        ground_refl: &[f64],
        sun_colour: &[f64],
    ) -> Vec<f64> {
        let n = sky_colour.len();
        assert!(
            ground_refl.len() == n && sun_colour.len() == n,
            "colours must have the same channel count"
        );
        let mut out = vec![0.0; self.sky.len() * n];
        for c in 0..n {
            out[c] = self.ground * ground_refl[c];
        }
        for (i, &v) in self.sky.iter().enumerate().skip(1) {
            for c in 0..n {
                out[i * n + c] = v * sky_colour[c];
            }
        }
        for &(i, v) in &self.sun {
            for c in 0..n {
                out[i * n + c] += v * sun_colour[c];
            }
        }
        out
    }
}

/// One gendaymtx column (`ComputeSky` + `AddDirect`) for one time step, before colour.
pub fn perez_sky_vector(
    patches: &SkyPatches,
    step: &TimeStep,
    site: &Site,
    options: &PerezOptions,
) -> SkyVector {
    let n = patches.len();
    let decl = super::solar::declination(step.jd);
    let mut st = step.hour + super::solar::solar_time_adjust(step.jd, site);
    if options.interval_minutes > 0.0 {
        let (rise, set) = super::solar::sunrise_sunset(site, step.month, step.day);
        let half = options.interval_minutes / 120.0;
        if (rise - st).abs() <= half {
            st = (st + half + rise) / 2.0;
        } else if (set - st).abs() < half {
            st = (st - half + set) / 2.0;
        }
    }
    let pos = SunPosition::from_declination(site, decl, st);
    let mut out = SkyVector {
        ground: 0.0,
        sky: vec![0.0; n],
        sun: vec![],
        sun_position: pos,
        state: None,
    };
    let alt = pos.altitude;
    let (mut dir, dif) = (step.direct, step.diffuse);
    if dir + dif <= 1e-4 {
        return out; // night
    }
    if step.units == InputUnits::DirectHorizontalIrradiance && alt > FTINY {
        dir /= alt.sin();
    }
    let mut state = match step.units {
        InputUnits::DirectNormalIlluminance => {
            SkyState::from_illuminance(dir, dif, alt, step.jd, step.dew_point)
        }
        _ => SkyState::from_irradiance(dir, dif, alt, step.jd, step.dew_point),
    };
    if options.solar_radiance {
        state.diff_illum = state.diff_irrad * WHITE_EFFICACY;
        state.dir_illum = state.dir_irrad * WHITE_EFFICACY;
    }
    out.state = Some(state);
    let mut ground = state.diff_illum;
    if alt > 0.0 {
        ground += state.dir_illum * alt.sin();
    }
    out.ground = ground / PI / WHITE_EFFICACY;

    // Diffuse sky: relative luminance at each patch centre, normalised to E_dif.
    let azimuth = pos.azimuth_east_of_north(options.rotation_deg);
    let z = state.sun_zenith;
    let p = coefficients(state.category, state.epsilon, state.delta, z);
    let geo = patches.geometry();
    let (cz, sz) = (z.cos(), z.sin());
    let (ca, sa) = (azimuth.cos(), azimuth.sin());
    let mut norm = 0.0;
    for (i, g) in geo.iter().enumerate().skip(1) {
        // cos(azi - azimuth) by the difference formula: no trigonometry per patch.
        let cos_daz = g.cos_azi * ca + g.sin_azi * sa;
        let cos_gamma = (cz * g.cos_zenith + sz * g.sin_zenith * cos_daz).clamp(-1.0, 1.0);
        let lv = relative_luminance_cos(&p, cos_gamma.acos(), cos_gamma, g.cos_zenith).max(0.0);
        out.sky[i] = lv;
        norm += lv * g.sin_alt * g.solid_angle;
    }
    if norm <= FTINY {
        out.sky[1..].iter_mut().for_each(|v| *v = 1.0);
        norm = PI;
    }
    let scale = state.diff_illum / norm / WHITE_EFFICACY;
    out.sky[1..].iter_mut().for_each(|v| *v *= scale);

    // Sun: spread over the nearest patch centres.
    if state.dir_illum > 1e-4 {
        let nsuns = if options.five_phase_sun_deg.is_some() {
            1
        } else {
            4
        };
        let sun = direction(alt, azimuth);
        let mut near: Vec<(f64, usize)> = vec![(-1.0, 0); nsuns];
        for (i, g) in geo.iter().enumerate().skip(1) {
            let c = g.dir;
            let d = c[0] * sun[0] + c[1] * sun[1] + c[2] * sun[2];
            if let Some(k) = near.iter().position(|&(nd, _)| d > nd) {
                near.insert(k, (d, i));
                near.truncate(nsuns);
            }
        }
        let weights: Vec<f64> = near.iter().map(|&(d, _)| 1.0 / (1.002 - d)).collect();
        let wtot: f64 = weights.iter().sum();
        let fixed = options
            .five_phase_sun_deg
            .map(|deg| (PI / 360.0 * deg).powi(2) * PI);
        for (&(_, i), w) in near.iter().zip(&weights) {
            let omega = fixed.unwrap_or(geo[i].solid_angle);
            out.sun
                .push((i, w * state.dir_illum / (WHITE_EFFICACY * wtot) / omega));
        }
    }
    out
}
