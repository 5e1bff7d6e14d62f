//! # Candidate missing effects
//!
//! Each effect is a physically parameterised change of the model with its own signature in
//! the residuals, expressed through the daylight-coefficient [`Components`] (no re-tracing
//! while fitting; the reflectance variants come from one cached re-weighted run):
//!
//! | effect | parameters | acts on | signature |
//! |---|---|---|---|
//! | [`transmittance`] | scale of the glazing transmittance | everything | uniform bias |
//! | [`obstruction`] | horizon sector: azimuth, half width, altitude | sky patches and suns behind it | low-sky and low-sun hours, sky-view dependent |
//! | [`skyline`] | horizon profile: altitude per 5-degree azimuth sector at a distance (smoothness prior) | the same, with each sensor's parallax | the same, for buildings with ends |
//! | [`reflectance`] | scale per surface class (walls, ceiling, floor, ground) | inter-reflected light (re-weighted coefficients) | grows with depth / with ground-lit ceiling |
//! | [`overhang`] | depth above a window head | high patches and high suns, per sensor | sun hours near the window |
//! | [`local`] | a vertical panel on the floor: plan segment, top height (parallel to a window wall or across the room) | sky cells and sun each sensor sees past it, the room it hides from them | a few neighbouring sensors, varying with the sun and the sky |
//! | [`sensor`] | calibration factor per faulty sensor | one sensor's readings | constant ratio at one sensor |
//! | [`tint`] | glazing level, spectral slope and curvature | the window's light per wavelength | channel ratios (spectral readings only) |
//!
//! Effects compose ([`Model::predict`](super::model::Model::predict)): exterior weights per
//! patch and sun, window weights (overhang), per-sensor direct-light weights (local), then
//! the glazing scale and the sensor factors.

pub mod local;
pub mod obstruction;
pub mod overhang;
pub mod reflectance;
pub mod sensor;
pub mod skyline;
pub mod tint;
pub mod transmittance;

use super::room::SurfaceClass;
use crate::error::{Error, Result};
use serde::Serialize;

/// One effect with its parameters. Angles in degrees, azimuth east of north.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "effect")]
pub enum Effect {
    /// Glazing transmittance times `scale`.
    Transmittance { scale: f64 },
    /// Sky below `altitude` within `half_width` of `azimuth` is blocked.
    Obstruction {
        azimuth: f64,
        half_width: f64,
        altitude: f64,
    },
    /// A skyline profile ([`skyline`]): altitude `alts[k]` (degrees, seen from the
    /// windows' centre) between azimuths `start + k step` and `start + (k + 1) step`, on a cylinder
    /// `distance` metres around the windows' centre. `sd`: the sectors' posterior standard
    /// deviations (empty when not fitted); `edf`: its effective parameters for the BIC;
    /// `reflectance`: its facade's (Lambertian, grey).
    Skyline {
        distance: f64,
        start: f64,
        step: f64,
        alts: Vec<f64>,
        sd: Vec<f64>,
        edf: f64,
        reflectance: f64,
    },
    /// Reflectance of a surface class times `scale`.
    Reflectance { class: SurfaceClass, scale: f64 },
    /// A horizontal overhang `depth` metres deep, `above` metres above the head of window
    /// `window` (index into the room's windows), running `overrun` metres past the
    /// opening's sides.
    Overhang {
        window: usize,
        depth: f64,
        above: f64,
        overrun: f64,
    },
    /// `fraction` of the direct light (sky and sun) blocked at `sensors` (indices): the
    /// earlier form, written as the panel [`crate::apply::local_panel`] builds.
    LocalObstruction { sensors: Vec<usize>, fraction: f64 },
    /// A vertical opaque panel (furniture, a partition) standing on the floor along the
    /// plan segment `a`-`b` (x, y of its centre line), `thick` metres thick, up to height
    /// `top` ([`local`]).
    Furniture {
        a: [f64; 2],
        b: [f64; 2],
        top: f64,
        thick: f64,
    },
    /// Readings of `sensor` are `factor` times the true illuminance.
    SensorFault { factors: Vec<(usize, f64)> },
    /// Glazing transmittance times `scale` with a spectral shape ([`tint`]).
    Tint {
        scale: f64,
        slope: f64,
        curvature: f64,
    },
}

/// Names of the effect families, in the order they are tried.
pub const FAMILIES: [&str; 9] = [
    "transmittance",
    "obstruction",
    "walls",
    "ceiling",
    "floor",
    "ground-albedo",
    "overhang",
    "local-obstruction",
    "sensor-fault",
];

/// Highest an overhang may sit above its window's head (m): above that it shades the
/// window only from beyond 3 m of depth, which the fit does not search.
pub const MAX_ABOVE: f64 = 2.0;

/// Farthest an overhang may run past its window's sides (m).
pub const MAX_OVERRUN: f64 = 5.0;

/// Largest transmittance or reflectance scale `--effect` takes: a material of reflectance
/// 0.095 (the darkest a room has) reaches the 0.95 cap at 10.
pub const MAX_SCALE: f64 = 10.0;

impl Effect {
    /// The family name (`walls` etc. for reflectance classes).
    pub fn family(&self) -> &'static str {
        match self {
            Effect::Transmittance { .. } => "transmittance",
            Effect::Obstruction { .. } | Effect::Skyline { .. } => "obstruction",
            Effect::Reflectance { class, .. } => match class {
                SurfaceClass::Walls => "walls",
                SurfaceClass::Ceiling => "ceiling",
                SurfaceClass::Floor => "floor",
                SurfaceClass::Ground => "ground-albedo",
            },
            Effect::Overhang { .. } => "overhang",
            Effect::LocalObstruction { .. } | Effect::Furniture { .. } => "local-obstruction",
            Effect::SensorFault { .. } => "sensor-fault",
            Effect::Tint { .. } => "tint",
        }
    }

    /// Free parameters (for the BIC penalty): continuous ones plus one per discrete choice
    /// that was searched (sector, window, sensor group); a skyline profile counts its
    /// effective parameters under its smoothness prior plus its distance.
    pub fn n_params(&self) -> f64 {
        match self {
            Effect::Transmittance { .. } | Effect::Reflectance { .. } => 1.0,
            Effect::Obstruction { .. } => 3.0,
            Effect::Skyline { edf, .. } => *edf,
            // Window, depth, height, overrun.
            Effect::Overhang { .. } => 4.0,
            Effect::LocalObstruction { .. } => 3.0,
            // Position, two ends, top, and the wall / orientation searched.
            Effect::Furniture { .. } => 5.0,
            // One per flagged sensor: ln(n) already outweighs what a factor removes at a
            // sensor within the calibration spread (effects::sensor's tests), while a
            // second per sensor would hide a 20 % fault from the significance threshold.
            Effect::SensorFault { factors } => factors.len() as f64,
            Effect::Tint { .. } => 3.0,
        }
    }

    /// The main continuous parameter (its uncertainty is reported).
    pub fn primary(&self) -> (&'static str, f64) {
        match self {
            Effect::Transmittance { scale } => ("scale", *scale),
            Effect::Obstruction { altitude, .. } => ("altitude_deg", *altitude),
            Effect::Skyline { alts, .. } => (
                "peak_altitude_deg",
                alts.iter().copied().fold(0.0, f64::max),
            ),
            Effect::Reflectance { scale, .. } => ("scale", *scale),
            Effect::Overhang { depth, .. } => ("depth_m", *depth),
            Effect::LocalObstruction { fraction, .. } => ("fraction", *fraction),
            Effect::Furniture { top, .. } => ("top_m", *top),
            Effect::SensorFault { factors } => ("factor", factors.first().map_or(1.0, |f| f.1)),
            Effect::Tint { scale, .. } => ("scale", *scale),
        }
    }

    /// The same effect with the main continuous parameter set to `v`.
    pub fn with_primary(&self, v: f64) -> Effect {
        let mut e = self.clone();
        match &mut e {
            Effect::Transmittance { scale }
            | Effect::Reflectance { scale, .. }
            | Effect::Tint { scale, .. } => *scale = v,
            Effect::Obstruction { altitude, .. } => *altitude = v,
            // The profile's height: every sector scaled so that the peak is `v`.
            Effect::Skyline { alts, .. } => {
                let peak = alts.iter().copied().fold(0.0, f64::max);
                if peak > 0.0 {
                    alts.iter_mut().for_each(|a| *a *= v / peak);
                }
            }
            Effect::Overhang { depth, .. } => *depth = v,
            Effect::LocalObstruction { fraction, .. } => *fraction = v,
            Effect::Furniture { top, .. } => *top = v,
            Effect::SensorFault { factors } => {
                if let Some(f) = factors.first_mut() {
                    f.1 = v
                }
            }
        }
        e
    }

    /// `NAME:params` as `rcalib apply --effect` reads it; sensor and window references by id.
    pub fn spec(&self, sensor_ids: &[String], window_ids: &[String]) -> String {
        let sid = |i: &usize| sensor_ids.get(*i).cloned().unwrap_or_else(|| i.to_string());
        match self {
            Effect::Transmittance { scale } => format!("transmittance:{scale:.3}"),
            Effect::Obstruction {
                azimuth,
                half_width,
                altitude,
            } => format!("obstruction:{azimuth:.1},{half_width:.1},{altitude:.1}"),
            Effect::Skyline {
                distance,
                start,
                step,
                alts,
                reflectance,
                ..
            } => skyline::spec(*distance, *start, *step, alts, *reflectance),
            Effect::Reflectance { scale, .. } => format!("{}:{scale:.3}", self.family()),
            Effect::Overhang {
                window,
                depth,
                above,
                overrun,
            } => format!(
                "overhang:{depth:.2},{},{above:.2},{overrun:.2}",
                window_ids.get(*window).cloned().unwrap_or_default()
            ),
            Effect::LocalObstruction { sensors, fraction } => format!(
                "local-obstruction:{fraction:.2},{}",
                sensors.iter().map(sid).collect::<Vec<_>>().join("+")
            ),
            Effect::Furniture { a, b, top, thick } => format!(
                "local-obstruction:{:.2},{:.2},{:.2},{:.2},{top:.2},{thick:.2}",
                a[0], a[1], b[0], b[1]
            ),
            Effect::SensorFault { factors } => format!(
                "sensor-fault:{}",
                factors
                    .iter()
                    .map(|(s, f)| format!("{}={f:.3}", sid(s)))
                    .collect::<Vec<_>>()
                    .join("+")
            ),
            Effect::Tint {
                scale,
                slope,
                curvature,
            } => tint::spec(*scale, *slope, *curvature),
        }
    }

    /// The parameters of [`Effect::spec`] with their names and units, in the spec's order
    /// (the reports print them beside the spec, which carries numbers only).
    pub fn named_params(&self, sensor_ids: &[String], window_ids: &[String]) -> String {
        let sid = |i: &usize| sensor_ids.get(*i).cloned().unwrap_or_else(|| i.to_string());
        match self {
            Effect::Transmittance { scale } => format!("scale = {scale:.3}"),
            Effect::Obstruction {
                azimuth,
                half_width,
                altitude,
            } => format!(
                "azimuth = {azimuth:.1} deg E of N, half width = {half_width:.1} deg, \
                 altitude = {altitude:.1} deg"
            ),
            Effect::Skyline {
                distance,
                start,
                step,
                alts,
                sd,
                edf,
                reflectance,
            } => format!(
                "distance = {distance:.0} m, facade reflectance = {reflectance:.2}, sectors of {step:.0} deg from azimuth {start:.0} E of N, \
                 altitude (deg) by sector centre azimuth: {}; {edf:.1} effective parameters",
                skyline::shown(alts)
                    .map(|i| {
                        let az = (start + step * (i as f64 + 0.5)).rem_euclid(360.0);
                        match sd.get(i) {
                            Some(u) if u.is_finite() => {
                                format!("{az:.0}: {:.1} +- {u:.1}", alts[i])
                            }
                            _ => format!("{az:.0}: {:.1}", alts[i]),
                        }
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            Effect::Reflectance { scale, .. } => format!("scale = {scale:.3}"),
            Effect::Overhang {
                window,
                depth,
                above,
                overrun,
            } => format!(
                "depth = {depth:.2} m, window = {}, above head = {above:.2} m, \
                 past each side = {overrun:.2} m",
                window_ids.get(*window).cloned().unwrap_or_default()
            ),
            Effect::LocalObstruction { sensors, fraction } => format!(
                "fraction blocked = {fraction:.2}, sensors = {}",
                sensors.iter().map(sid).collect::<Vec<_>>().join(", ")
            ),
            Effect::Furniture { a, b, top, thick } => format!(
                "from ({:.2}, {:.2}) to ({:.2}, {:.2}) m, top = {top:.2} m, thickness = {thick:.2} m",
                a[0], a[1], b[0], b[1]
            ),
            Effect::SensorFault { factors } => factors
                .iter()
                .map(|(s, f)| format!("factor({}) = {f:.3}", sid(s)))
                .collect::<Vec<_>>()
                .join(", "),
            Effect::Tint {
                scale,
                slope,
                curvature,
            } => format!("scale = {scale:.3}, slope = {slope:.3}, curvature = {curvature:.3}"),
        }
    }

    /// Parse `NAME:params` (see [`Effect::spec`]); scales at most [`MAX_SCALE`].
    pub fn parse(spec: &str, sensor_ids: &[String], window_ids: &[String]) -> Result<Effect> {
        let (name, params) = spec.split_once(':').unwrap_or((spec, ""));
        let bad = |what: &str| {
            Error::Usage(format!(
                "--effect '{spec}': {what}; expected one of transmittance:SCALE, \
                 obstruction:AZIMUTH,HALF_WIDTH,ALTITUDE, skyline:DISTANCE,START,STEP,ALT,ALT,...[/REFLECTANCE], \
                 walls|ceiling|floor|ground-albedo:SCALE, \
                 overhang:DEPTH[,WINDOW[,ABOVE[,OVERRUN]]], local-obstruction:X0,Y0,X1,Y1,TOP[,THICK] \
                 (or the older FRACTION,ID+ID), sensor-fault:ID=F+ID=F, \
                 tint:SCALE,SLOPE,CURVATURE"
            ))
        };
        let nums = |s: &str| -> Result<Vec<f64>> {
            s.split(',')
                .map(|x| {
                    x.trim()
                        .parse::<f64>()
                        .map_err(|_| bad(&format!("'{x}' is not a number")))
                })
                .collect()
        };
        let sensor = |id: &str| -> Result<usize> {
            sensor_ids
                .iter()
                .position(|s| s == id)
                .ok_or_else(|| bad(&format!("unknown sensor id '{id}'")))
        };
        let one = |s: &str| -> Result<f64> {
            match nums(s)?.as_slice() {
                [v] if *v >= 0.0 => Ok(*v),
                _ => Err(bad("expected one non-negative number")),
            }
        };
        // A scale multiplies reflectances or transmittances that apply caps at 0.95 and 1;
        // beyond MAX_SCALE every material is at its cap and the number means nothing
        // (issue #19: walls:1e300 wrote 0.95 under a comment saying x1e300).
        let scale = |s: &str| -> Result<f64> {
            let v = one(s)?;
            if v > MAX_SCALE {
                return Err(bad(&format!(
                    "scale {} is above {MAX_SCALE} (reflectances are capped at 0.95, \
                     transmittances at 1; explain fits 0.3 .. 4)",
                    s.trim()
                )));
            }
            Ok(v)
        };
        Ok(match name {
            "transmittance" => Effect::Transmittance {
                scale: scale(params)?,
            },
            "walls" | "ceiling" | "floor" | "ground-albedo" => Effect::Reflectance {
                class: match name {
                    "walls" => SurfaceClass::Walls,
                    "ceiling" => SurfaceClass::Ceiling,
                    "floor" => SurfaceClass::Floor,
                    _ => SurfaceClass::Ground,
                },
                scale: scale(params)?,
            },
            "obstruction" => match nums(params)?.as_slice() {
                [a, w, h] if (0.0..=90.0).contains(h) && *w > 0.0 => Effect::Obstruction {
                    azimuth: a.rem_euclid(360.0),
                    half_width: w.min(180.0),
                    altitude: *h,
                },
                _ => return Err(bad("expected AZIMUTH,HALF_WIDTH>0,ALTITUDE 0..90")),
            },
            "skyline" => {
                // The facade's reflectance after a slash (without: apply's default).
                let (alts, rho) = params.split_once('/').unwrap_or((params, ""));
                let rho = if rho.is_empty() {
                    None
                } else {
                    Some(one(rho)?)
                };
                skyline::parse(&nums(alts)?, rho).map_err(|m| bad(&m))?
            }
            "overhang" => {
                let mut parts = params.splitn(4, ',');
                let d = parts.next().unwrap_or_default();
                let w = parts.next().unwrap_or_default();
                let above = match parts.next() {
                    Some(a) => one(a)?,
                    None => 0.0,
                };
                let depth = one(d)?;
                // Without it, as deep as the plate (the earlier form's width).
                let overrun = match parts.next() {
                    Some(o) => one(o)?,
                    None => depth,
                };
                if overrun > MAX_OVERRUN {
                    return Err(bad(&format!(
                        "overrun past the window's sides over {MAX_OVERRUN} m"
                    )));
                }
                if above > MAX_ABOVE {
                    return Err(bad(&format!(
                        "height above the window head over {MAX_ABOVE} m"
                    )));
                }
                let window = if w.is_empty() {
                    0
                } else {
                    window_ids
                        .iter()
                        .position(|x| x == w)
                        .ok_or_else(|| bad(&format!("no window (glass polygon) '{w}'")))?
                };
                Effect::Overhang {
                    window,
                    depth,
                    above,
                    overrun,
                }
            }
            "local-obstruction" if !params.contains('+') && params.split(',').count() >= 5 => {
                match nums(params)?.as_slice() {
                    [x0, y0, x1, y1, top, rest @ ..]
                        if rest.len() <= 1
                            && rest.iter().all(|t| *t > 0.0 && *t <= 5.0)
                            && *top > 0.0
                            && (x1 - x0).hypot(y1 - y0) > 1e-3 =>
                    {
                        Effect::Furniture {
                            a: [*x0, *y0],
                            b: [*x1, *y1],
                            top: *top,
                            thick: rest.first().copied().unwrap_or(local::THICK),
                        }
                    }
                    _ => {
                        return Err(bad(
                            "expected X0,Y0,X1,Y1,TOP[,THICK]: a plan segment of non-zero \
                             length, TOP > 0, 0 < THICK <= 5 (metres)",
                        ));
                    }
                }
            }
            "local-obstruction" => {
                let (f, ids) = params
                    .split_once(',')
                    .ok_or_else(|| bad("expected FRACTION,ID+ID"))?;
                let fraction = one(f)?;
                if fraction > 1.0 {
                    return Err(bad("fraction above 1"));
                }
                let sensors = ids.split('+').map(sensor).collect::<Result<Vec<_>>>()?;
                Effect::LocalObstruction { sensors, fraction }
            }
            "sensor-fault" => {
                let factors = params
                    .split('+')
                    .map(|item| {
                        let (id, f) = item
                            .split_once('=')
                            .ok_or_else(|| bad("expected ID=FACTOR"))?;
                        let f = one(f)?;
                        if f <= 0.0 {
                            return Err(bad("factor must be > 0"));
                        }
                        Ok((sensor(id)?, f))
                    })
                    .collect::<Result<Vec<_>>>()?;
                Effect::SensorFault { factors }
            }
            "tint" => tint::parse(params).map_err(|m| bad(&m))?,
            _ => return Err(bad(&format!("unknown effect '{name}'"))),
        })
    }

    /// One line saying what the effect means physically.
    pub fn describe(&self, sensor_ids: &[String], window_ids: &[String]) -> String {
        let sid = |i: &usize| sensor_ids.get(*i).cloned().unwrap_or_else(|| i.to_string());
        match self {
            Effect::Transmittance { scale } => format!(
                "glazing transmits {:.0} % of the modelled value (dirt, ageing, coating)",
                100.0 * scale
            ),
            Effect::Obstruction {
                azimuth,
                half_width,
                altitude,
            } => format!(
                "exterior obstruction up to {altitude:.1} deg altitude between azimuth {:.0} and \
                 {:.0} deg (east of north)",
                (azimuth - half_width).rem_euclid(360.0),
                (azimuth + half_width).rem_euclid(360.0)
            ),
            Effect::Skyline {
                distance,
                start,
                step,
                alts,
                ..
            } => {
                let r = skyline::shown(alts);
                let peak = alts.iter().copied().fold(0.0, f64::max);
                format!(
                    "exterior skyline {distance:.0} m away, up to {peak:.1} deg altitude between \
                     azimuth {:.0} and {:.0} deg (east of north)",
                    (start + step * r.start as f64).rem_euclid(360.0),
                    (start + step * r.end as f64).rem_euclid(360.0)
                )
            }
            Effect::Reflectance { class, scale } => format!(
                "{} reflectance {:.0} % of the modelled value",
                class.name(),
                100.0 * scale
            ),
            Effect::Overhang {
                window,
                depth,
                above,
                overrun,
            } => format!(
                "overhang {depth:.2} m deep, {above:.2} m above the head of window '{}', \
                 running {overrun:.2} m past each side",
                window_ids.get(*window).cloned().unwrap_or_default()
            ),
            Effect::LocalObstruction { sensors, fraction } => format!(
                "local obstruction blocking {:.0} % of the direct light at sensors {}",
                100.0 * fraction,
                sensors.iter().map(sid).collect::<Vec<_>>().join(", ")
            ),
            Effect::Furniture { a, b, top, .. } => format!(
                "local obstruction (furniture, a partition): a panel {:.1} m long and {top:.2} m \
                 high from ({:.1}, {:.1}) to ({:.1}, {:.1})",
                (b[0] - a[0]).hypot(b[1] - a[1]),
                a[0],
                a[1],
                b[0],
                b[1]
            ),
            Effect::SensorFault { factors } => format!(
                "sensor calibration: {}",
                factors
                    .iter()
                    .map(|(s, f)| format!("{} reads x{f:.2}", sid(s)))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            Effect::Tint {
                scale,
                slope,
                curvature,
            } => tint::describe(*scale, *slope, *curvature),
        }
    }
}

/// Golden-section minimisation of `f` on `[lo, hi]` (a unimodal profile is assumed; the
/// fits call it on one parameter at a time). Returns (argmin, min).
pub fn golden(f: &mut dyn FnMut(f64) -> f64, lo: f64, hi: f64, iters: usize) -> (f64, f64) {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (lo, hi);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..iters {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    if fc < fd { (c, fc) } else { (d, fd) }
}

/// Smooth step from 0 (x << 0) to 1 (x >> 0) over about `width` (logistic): keeps fitted
/// profiles continuous where sky patches or suns cross an edge.
pub fn smooth_step(x: f64, width: f64) -> f64 {
    1.0 / (1.0 + (-x / width.max(1e-12)).exp())
}
