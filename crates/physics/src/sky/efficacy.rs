//! # Perez 1990 irradiance-to-illuminance model (sky clearness, brightness, efficacy)
//!
//! Perez, R., P. Ineichen, R. Seals, J. Michalsky, R. Stewart (1990), "Modeling Daylight
//! Availability and Irradiance Components from Direct and Global Irradiance", Solar Energy
//! 44(5):271-289, as Radiance's `gendaymtx` applies it (`LBNL-ETA/Radiance:
//! src/gen/gendaymtx.c`, Ian Ashdown's rewrite of gendaylit):
//!
//! ```text
//! Z       = solar zenith angle (rad), clamped: 90 deg if altitude <= 0, 3 deg if alt >= 87
//! m       = 1 / (cos Z + 0.15 (93.885 - Z_deg)^-1.253)           air mass (Kasten 1966)
//! E0      = 1.00011 + 0.034221 cos G + 0.00128 sin G + 0.000719 cos 2G + 0.000077 sin 2G,
//!           G = 2 pi (jd - 1) / 365                  eccentricity (Sen 2008, p. 72)
//! delta   = DHI m / (1367 E0)                         sky brightness (eq. 2), in [0.01, 0.6]
//! epsilon = ((DHI + DNI) / DHI + 1.041 Z^3) / (1 + 1.041 Z^3)
//!                                                     sky clearness (eq. 1), in [1, 11.9]
//! W       = exp(0.07 Td - 0.075)                      precipitable water, cm (eq. 3),
//!                                                     Td = surface dew point (deg C)
//! diffuse illuminance = DHI (a + b W + c cos Z + d ln delta)               (eq. 7)
//! direct illuminance  = DNI max(0, a + b W + c exp(5.73 Z - 5) + d delta)  (eq. 8)
//! ```
//!
//! One model, two Radiance programs: gendaymtx (annual matrices) and gendaylit (one sky)
//! apply it with the same formulas and tables but clamp its inputs differently; [`Flavour`]
//! is that switch (clearness and dew point limits) and every formula above has one home
//! here, used by both [`SkyState`] (gendaymtx) and `super::gendaylit`. (gendaylit writes
//! the air mass as `exp(-1.253 ln(93.885 - Z))` and the day angle as `2 pi (jd - 1)/365`:
//! the same numbers to rounding.)
//!
//! with `a..d` from Table 4 per clearness category (the 8 bins of Table 1, edges
//! `1, 1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2, 12.01`). Photometric input (WEA units 3) is
//! converted back to irradiance by gendaymtx's fixed-point iteration
//! ([`SkyState::from_illuminance`]).

/// Solar constant used for sky brightness (W/m^2), gendaymtx `DC_SolarConstantE`.
pub const SOLAR_CONSTANT: f64 = 1367.0;
/// Solar constant in klx used to convert illuminance input, gendaymtx `DC_SolarConstantL`.
pub const SOLAR_CONSTANT_KLUX: f64 = 127.5;

/// Lower edges of the 8 sky clearness categories plus the upper bound (Perez 1990, Table 1;
/// gendaymtx's last bin ends at 12.01).
pub const CLEARNESS_EDGES: [f64; 9] = [1.0, 1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2, 12.01];

/// Diffuse luminous efficacy coefficients a, b, c, d (lm/W) per clearness category:
/// Perez et al. 1990, Solar Energy 44(5), Table 4 (eq. 7).
pub const DIFFUSE_EFFICACY: [[f64; 4]; 8] = [
    [97.24, -0.46, 12.00, -8.91],
    [107.22, 1.15, 0.59, -3.95],
    [104.97, 2.96, -5.53, -8.77],
    [102.39, 5.59, -13.95, -13.90],
    [100.71, 5.94, -22.75, -23.74],
    [106.42, 3.83, -36.15, -28.83],
    [141.88, 1.90, -53.24, -14.03],
    [152.23, 0.35, -45.27, -7.98],
];

/// Direct luminous efficacy coefficients a, b, c, d (lm/W) per clearness category:
/// Perez et al. 1990, Solar Energy 44(5), Table 4 (eq. 8).
pub const DIRECT_EFFICACY: [[f64; 4]; 8] = [
    [57.20, -4.55, -2.98, 117.12],
    [98.99, -3.46, -1.21, 12.38],
    [109.83, -4.90, -1.71, -8.81],
    [110.34, -5.84, -1.99, -4.56],
    [106.36, -3.97, -1.75, -6.16],
    [107.19, -1.25, -1.51, -26.73],
    [105.75, 0.77, -1.26, -34.44],
    [101.18, 1.58, -1.10, -8.29],
];

/// gendaymtx's default surface dew point (deg C) when the input carries none (WEA files).
pub const DEFAULT_DEW_POINT: f64 = 11.0;

/// Solar zenith angle as the Perez models see it: 90 deg when the sun is at or below the
/// horizon, 3 deg when it is within 3 deg of the zenith ("keep circumsolar off zenith").
pub fn perez_zenith(altitude: f64) -> f64 {
    if altitude <= 0.0 {
        90f64.to_radians()
    } else if altitude >= 87f64.to_radians() {
        3f64.to_radians()
    } else {
        90f64.to_radians() - altitude
    }
}

/// Relative optical air mass (Kasten 1966) for zenith angle `z` (radians).
pub fn air_mass(z: f64) -> f64 {
    1.0 / (z.cos() + 0.15 * (93.885 - z.to_degrees()).powf(-1.253))
}

/// Earth orbit eccentricity correction for day of year `jd` (gendaylit's day numbers may be
/// fractional).
pub fn eccentricity(jd: f64) -> f64 {
    let g = (jd - 1.0) * (2.0 * std::f64::consts::PI / 365.0);
    1.00011
        + 0.034221 * g.cos()
        + 0.00128 * g.sin()
        + 0.000719 * (2.0 * g).cos()
        + 0.000077 * (2.0 * g).sin()
}

/// Atmospheric precipitable water (cm) from the surface dew point (deg C).
pub fn precipitable_water(dew_point: f64) -> f64 {
    (0.07 * dew_point - 0.075).exp()
}

/// Clearness category 0..=7 (first bin with `lower <= epsilon < upper`); 8 if outside.
pub fn category(epsilon: f64) -> usize {
    (0..8)
        .find(|&i| epsilon >= CLEARNESS_EDGES[i] && epsilon < CLEARNESS_EDGES[i + 1])
        .unwrap_or(8)
}

/// Everything the Perez models need for one time step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyState {
    /// Clamped solar zenith angle ([`perez_zenith`], radians).
    pub sun_zenith: f64,
    /// Sky clearness epsilon (clamped).
    pub epsilon: f64,
    /// Sky brightness delta (clamped).
    pub delta: f64,
    /// Clearness category 0..=7.
    pub category: usize,
    /// Precipitable water (cm).
    pub precip_water: f64,
    /// Direct normal irradiance (W/m^2).
    pub dir_irrad: f64,
    /// Diffuse horizontal irradiance (W/m^2).
    pub diff_irrad: f64,
    /// Direct normal illuminance (lx).
    pub dir_illum: f64,
    /// Diffuse horizontal illuminance (lx).
    pub diff_illum: f64,
}

/// Sky brightness delta (eq. 2), unclamped; `jd` the day of the year.
pub fn brightness(diff_irrad: f64, z: f64, jd: f64) -> f64 {
    diff_irrad * air_mass(z) / (SOLAR_CONSTANT * eccentricity(jd))
}

/// Sky clearness epsilon (eq. 1), unclamped (infinite for a zero diffuse value).
pub fn clearness(diff_irrad: f64, dir_irrad: f64, z: f64) -> f64 {
    let z3 = z * z * z;
    ((diff_irrad + dir_irrad) / diff_irrad + 1.041 * z3) / (1.0 + 1.041 * z3)
}

/// Diffuse luminous efficacy (lm/W, eq. 7) of category `cat` (0..=7).
pub fn diffuse_efficacy(cat: usize, w: f64, z: f64, delta: f64) -> f64 {
    let [a, b, c, d] = DIFFUSE_EFFICACY[cat.min(7)];
    a + b * w + c * z.cos() + d * delta.ln()
}

/// Direct luminous efficacy (lm/W, eq. 8, never negative) of category `cat` (0..=7).
pub fn direct_efficacy(cat: usize, w: f64, z: f64, delta: f64) -> f64 {
    let [a, b, c, d] = DIRECT_EFFICACY[cat.min(7)];
    (a + b * w + c * (5.73 * z - 5.0).exp() + d * delta).max(0.0)
}

/// Which Radiance program's input limits the model runs with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flavour {
    /// gendaymtx (`ComputeSky`, `CalcSkyParamFromIllum`): epsilon clamped to [1, 11.9]
    /// (12 while inverting photometric input), dew point used as given.
    Gendaymtx,
    /// gendaylit (`check_parametrization`): epsilon below 1 raised to 1, above 12.01 set to
    /// 12.009; a dew point outside -40..40 deg C replaced by [`GENDAYLIT_DEW_POINT`].
    Gendaylit,
}

/// gendaylit's default surface dew point (deg C), used when the given one is out of range.
pub const GENDAYLIT_DEW_POINT: f64 = 10.97353115;

impl Flavour {
    /// Epsilon as the program clamps it before looking up the category.
    pub fn clamp_clearness(self, eps: f64) -> f64 {
        match self {
            Flavour::Gendaymtx if eps.is_nan() => 1.0,
            Flavour::Gendaymtx => eps.clamp(1.0, 11.9),
            Flavour::Gendaylit if eps < CLEARNESS_EDGES[0] => CLEARNESS_EDGES[0],
            Flavour::Gendaylit if eps > CLEARNESS_EDGES[8] => CLEARNESS_EDGES[8] - 0.001,
            Flavour::Gendaylit => eps,
        }
    }

    /// Precipitable water (cm) from the dew point the program accepts.
    pub fn precipitable_water(self, dew_point: f64) -> f64 {
        let td = match self {
            Flavour::Gendaylit if !(-40.0..=40.0).contains(&dew_point) => GENDAYLIT_DEW_POINT,
            _ => dew_point,
        };
        precipitable_water(td)
    }
}

impl SkyState {
    /// From direct normal and diffuse horizontal irradiance (W/m^2), gendaymtx's
    /// `input == 1` path: epsilon clamped to [1, 11.9], delta to [0.01, 0.6].
    pub fn from_irradiance(
        dir_irrad: f64,
        diff_irrad: f64,
        sun_altitude: f64,
        jd: u32,
        dew_point: f64,
    ) -> SkyState {
        let z = perez_zenith(sun_altitude);
        let w = Flavour::Gendaymtx.precipitable_water(dew_point);
        let delta = brightness(diff_irrad, z, f64::from(jd)).clamp(0.01, 0.6);
        // A zero diffuse value makes epsilon infinite (as in C), which the clamp catches.
        let eps = Flavour::Gendaymtx.clamp_clearness(clearness(diff_irrad, dir_irrad, z));
        let cat = category(eps);
        SkyState {
            sun_zenith: z,
            epsilon: eps,
            delta,
            category: cat,
            precip_water: w,
            dir_irrad,
            diff_irrad,
            diff_illum: diff_irrad * diffuse_efficacy(cat, w, z, delta),
            dir_illum: dir_irrad * direct_efficacy(cat, w, z, delta),
        }
    }

    /// From direct normal and diffuse horizontal illuminance (lx), gendaymtx's
    /// `CalcSkyParamFromIllum`: start from irradiance = illuminance x 1367 / 127500, then at
    /// most 5 rounds of inverting the efficacy model until both irradiances move less than
    /// 10 W/m^2 (epsilon clamped to [1, 12], delta to [0.01, 0.6]).
    pub fn from_illuminance(
        dir_illum: f64,
        diff_illum: f64,
        sun_altitude: f64,
        jd: u32,
        dew_point: f64,
    ) -> SkyState {
        let z = perez_zenith(sun_altitude);
        let w = Flavour::Gendaymtx.precipitable_water(dew_point);
        let k = SOLAR_CONSTANT / (SOLAR_CONSTANT_KLUX * 1000.0);
        let (mut diff_irrad, mut dir_irrad) = (diff_illum * k, dir_illum * k);
        let clamp_eps = |e: f64| if e.is_nan() { 1.0 } else { e.clamp(1.0, 12.0) };
        let mut delta = brightness(diff_irrad, z, f64::from(jd)).clamp(0.01, 0.6);
        let mut eps = clamp_eps(clearness(diff_irrad, dir_irrad, z));
        let (mut test1, mut test2) = (0.1, 0.1);
        let mut rounds = 0;
        while ((diff_irrad - test1).abs() > 10.0 || (dir_irrad - test2).abs() > 10.0) && rounds != 5
        {
            test1 = diff_irrad;
            test2 = dir_irrad;
            rounds += 1;
            let cat = category(eps);
            diff_irrad = diff_illum / diffuse_efficacy(cat, w, z, delta);
            // gendaymtx keeps the ratio itself when it is tiny (a quirk kept for equality).
            dir_irrad = direct_efficacy(cat, w, z, delta);
            if dir_irrad > 0.1 {
                dir_irrad = dir_illum / dir_irrad;
            }
            delta = brightness(diff_irrad, z, f64::from(jd)).clamp(0.01, 0.6);
            eps = clamp_eps(clearness(diff_irrad, dir_irrad, z));
        }
        SkyState {
            sun_zenith: z,
            epsilon: eps,
            delta,
            category: category(eps),
            precip_water: w,
            dir_irrad,
            diff_irrad,
            dir_illum,
            diff_illum,
        }
    }
}

/// gendaymtx's 3-hour running mean of the dew point for EPW input: the first record fills
/// the history with its own value; a record without dew point resets the history and the
/// previous mean stays in use (WEA files: always [`DEFAULT_DEW_POINT`]).
#[derive(Debug, Clone, Copy)]
pub struct DewPointMean {
    hist: Option<[f32; 2]>,
    current: f64,
}

impl Default for DewPointMean {
    fn default() -> Self {
        DewPointMean {
            hist: None,
            current: DEFAULT_DEW_POINT,
        }
    }
}

impl DewPointMean {
    pub fn new() -> Self {
        Self::default()
    }

    /// Feed the next record's dew point (`None` if missing) and get the value to use.
    /// gendaymtx stores the history in C `float`s; reproduced.
    pub fn next(&mut self, dew_point: Option<f64>) -> f64 {
        match dew_point {
            Some(t) => {
                let t = t as f32;
                let h = self.hist.unwrap_or([t, t]);
                // C adds the three floats in float precision before scaling in double.
                self.current = (1.0 / 3.0) * f64::from(h[0] + h[1] + t);
                self.hist = Some([h[1], t]);
            }
            None => self.hist = None,
        }
        self.current
    }
}
