//! # The model under calibration: components, sensitivities, observations, prediction
//!
//! [`Model`] holds what every fit needs: the [`Components`] of the model as given, the
//! reflectance sensitivities (coefficients with each surface class's reflectance scaled by
//! `1 ± DELTA`, from one traced run with path re-weighting records, combined by quadratic
//! interpolation; the inter-reflected sun's from the sky patches around it), the room's windows, the
//! skies and the observations. [`Model::predict`] turns a list of effects into simulated
//! illuminances for every observation in a fraction of a millisecond per hundred readings,
//! which is what makes fitting interactive.
//!

use super::effects::{self, Effect};
use super::measurements::Bound;
use super::room::{Room, SurfaceClass};
use super::simulate::{Components, Dcs, StepSky, Tracer};
use crate::error::Result;
use crate::formats::sensors::Sensor;
use crate::scene::Scene;
use crate::sky::SkyPatches;

/// Relative reflectance step of the re-weighted sensitivities.
pub const DELTA: f64 = 0.5;

/// First and second derivatives (per unit of the scale factor) of the sky and
/// inter-reflected-sun components with respect to one class's reflectance scale.
#[derive(Debug, Clone, PartialEq)]
pub struct ReflSens {
    pub class: SurfaceClass,
    pub d1_sky: Vec<f64>,
    pub d2_sky: Vec<f64>,
    pub d1_sun: Vec<f64>,
    pub d2_sun: Vec<f64>,
}

/// Everything the fits need.
#[derive(Debug, Clone)]
pub struct Model {
    pub comps: Components,
    pub refl: Vec<ReflSens>,
    pub room: Room,
    pub sensors: Vec<Sensor>,
    pub skies: Vec<StepSky>,
    pub patches: SkyPatches,
    pub obs: Vec<Bound>,
}

/// Multipliers the effects set (see [`super::effects`]); all 1 for the model as given.
#[derive(Debug, Clone)]
pub struct Weights {
    /// Per sky patch: exterior (obstruction, ground albedo on the ground patch).
    pub patch: Vec<f64>,
    /// Per step: the sun (exterior obstruction).
    pub sun: Vec<f64>,
    /// Per patch: share of a patch's light still entering the windows (overhang).
    pub win_ind: Vec<f64>,
    /// `[s][p]` direct sky seen past an overhang.
    pub win_dir: Option<Vec<f64>>,
    /// Per step: share of the sun entering the windows (overhang).
    pub sun_win_ind: Vec<f64>,
    /// `[s][t]` direct sun past an overhang.
    pub sun_win_dir: Option<Vec<f64>>,
    /// Per sensor: direct light left by a local obstruction.
    pub local: Vec<f64>,
    pub tau: f64,
    /// Per sensor: reading / true illuminance.
    pub cal: Vec<f64>,
    /// (index into [`Model::refl`], scale - 1).
    pub refl: Vec<(usize, f64)>,
}

impl Model {
    /// Build from coefficients: the reflectance sensitivities of every class the room has
    /// come from one re-weighted run (cached).
    #[allow(clippy::too_many_arguments)]
    pub fn build(
        tracer: &Tracer,
        scene: &Scene,
        room: Room,
        sensors: Vec<Sensor>,
        skies: Vec<StepSky>,
        dcs: &Dcs,
        obs: Vec<Bound>,
        with_reflectance: bool,
    ) -> Result<Model> {
        let comps = Components::new(dcs, &skies);
        let patches = SkyPatches::new(dcs_mf(dcs.npatch));
        let mut refl = Vec::new();
        if with_reflectance {
            let classes = room.classes();
            // The middle variant is the re-weighted run's own (unscaled) coefficients: the
            // differences then come from one set of paths even where the cached `total`
            // was traced by another version of the tracer.
            let (scaled, none) =
                tracer.dc_scaled(scene, &room, &classes, &[1.0 - DELTA, 1.0, 1.0 + DELTA])?;
            let c_none = Components::new(
                &Dcs {
                    total: none,
                    ..dcs.clone()
                },
                &skies,
            );
            for (&class, v) in classes.iter().zip(scaled) {
                let [lo, mid, hi]: [Vec<f64>; 3] = v.try_into().map_err(|_| {
                    crate::error::Error::Mismatch("re-weighting: three variants expected".into())
                })?;
                let c_lo = Components::new(
                    &Dcs {
                        total: lo,
                        ..dcs.clone()
                    },
                    &skies,
                );
                let c_mid = Components::new(
                    &Dcs {
                        total: mid,
                        ..dcs.clone()
                    },
                    &skies,
                );
                let c_hi = Components::new(
                    &Dcs {
                        total: hi,
                        ..dcs.clone()
                    },
                    &skies,
                );
                refl.push(sensitivity(
                    class, &comps, &c_none, &c_mid, &c_lo, &c_hi, &skies, &patches,
                ));
            }
        }
        Ok(Model {
            comps,
            refl,
            room,
            sensors,
            skies,
            patches,
            obs,
        })
    }

    pub fn nsens(&self) -> usize {
        self.comps.nsens
    }
    pub fn nsteps(&self) -> usize {
        self.comps.nsteps
    }

    /// Weights of the model as given.
    pub fn unit_weights(&self) -> Weights {
        let (ns, nt, np) = (self.nsens(), self.nsteps(), self.comps.npatch);
        Weights {
            patch: vec![1.0; np],
            sun: vec![1.0; nt],
            win_ind: vec![1.0; np],
            win_dir: None,
            sun_win_ind: vec![1.0; nt],
            sun_win_dir: None,
            local: vec![1.0; ns],
            tau: 1.0,
            cal: vec![1.0; ns],
            refl: Vec::new(),
        }
    }

    /// Weights with `effects` applied in order.
    pub fn weights(&self, effects: &[Effect]) -> Weights {
        let mut w = self.unit_weights();
        for e in effects {
            match e {
                Effect::Transmittance { .. } => effects::transmittance::apply(e, self, &mut w),
                Effect::Tint { .. } => effects::tint::apply(e, self, &mut w),
                Effect::Obstruction { .. } => effects::obstruction::apply(e, self, &mut w),
                Effect::Reflectance { class, scale } => {
                    if let Some(i) = self.refl.iter().position(|r| r.class == *class) {
                        w.refl.push((i, scale - 1.0));
                    }
                    if *class == SurfaceClass::Ground {
                        // gendaymtx's ground patch is the ground reflectance times the
                        // horizontal illuminance: it scales with the albedo.
                        w.patch[0] *= scale;
                    }
                }
                Effect::Overhang { .. } => effects::overhang::apply(e, self, &mut w),
                Effect::LocalObstruction { sensors, fraction } => {
                    for &s in sensors {
                        if let Some(l) = w.local.get_mut(s) {
                            *l *= 1.0 - fraction;
                        }
                    }
                }
                Effect::SensorFault { factors } => {
                    for &(s, f) in factors {
                        if let Some(c) = w.cal.get_mut(s) {
                            *c *= f;
                        }
                    }
                }
            }
        }
        w
    }

    /// Per observation: (indirect, direct) light before the glazing scale, the local
    /// obstruction and the sensor factors.
    pub fn parts(&self, w: &Weights) -> Vec<(f64, f64)> {
        let c = &self.comps;
        let (nt, np) = (c.nsteps, c.npatch);
        self.obs
            .iter()
            .map(|o| {
                let (s, t) = (o.sensor, o.step);
                let st = s * nt + t;
                let base = st * np;
                let (mut ind, mut dir) = (0.0, 0.0);
                for p in 0..np {
                    let mut tot = c.sky[base + p];
                    for &(i, dk) in &w.refl {
                        let r = &self.refl[i];
                        tot += r.d1_sky[base + p] * dk + r.d2_sky[base + p] * dk * dk;
                    }
                    let d = c.sky_direct[base + p];
                    let wd = w.win_dir.as_ref().map_or(1.0, |v| v[s * np + p]);
                    ind += w.patch[p] * w.win_ind[p] * (tot - d);
                    dir += w.patch[p] * wd * d;
                }
                let mut si = c.sun_indirect[st];
                for &(i, dk) in &w.refl {
                    let r = &self.refl[i];
                    si += r.d1_sun[st] * dk + r.d2_sun[st] * dk * dk;
                }
                let swd = w.sun_win_dir.as_ref().map_or(1.0, |v| v[st]);
                ind += w.sun[t] * w.sun_win_ind[t] * si;
                dir += w.sun[t] * swd * c.sun_direct[st];
                (ind, dir)
            })
            .collect()
    }

    /// Simulated readings from parts and the per-sensor weights.
    pub fn finish(&self, parts: &[(f64, f64)], w: &Weights) -> Vec<f64> {
        self.obs
            .iter()
            .zip(parts)
            .map(|(o, &(ind, dir))| {
                w.cal[o.sensor] * w.tau * (ind + w.local[o.sensor] * dir).max(0.0)
            })
            .collect()
    }

    /// Simulated readings with `effects` applied.
    pub fn predict(&self, effects: &[Effect]) -> Vec<f64> {
        let w = self.weights(effects);
        self.finish(&self.parts(&w), &w)
    }

    /// Measured values in observation order.
    pub fn measured(&self) -> Vec<f64> {
        self.obs.iter().map(|o| o.value).collect()
    }

    /// Horizontal distance between two sensors.
    pub fn sensor_distance(&self, a: usize, b: usize) -> f64 {
        let (p, q) = (self.sensors[a].ray.org, self.sensors[b].ray.org);
        ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
    }
}

/// Angular width (standard deviation, degrees) of the kernel that pools the sky patches
/// around the sun into its relative sensitivity: about one Tregenza patch (12 degrees wide),
/// so that a few patches' worth of paths share the estimate.
const SUN_KERNEL_DEG: f64 = 8.0;

/// Sensitivities from components at `1 - DELTA` and `1 + DELTA`.
///
/// The inter-reflected sun is not re-traced (one run per step, class and scale would
/// dominate the cost). Its *relative* sensitivity is taken from the sky patches around the
/// sun's position: light of sky patch `p` that reaches the sensor only after reflection
/// first lands where the window's projection along `p` falls, which is where the sun
/// inside `p` lands too (the last vertex of a sensor path leaving through the window
/// towards `p` is a first-bounce point of that patch's light). So per sensor
/// `dVsun/dk / Vsun_ind = sum_p w_p dDC_p/dk / sum_p w_p DC_ind,p`, with `w_p` a Gaussian in
/// the angle between patch `p`'s centre and the sun. Averaging over the whole sky instead
/// (the sensor's total inter-reflected sky light) mixes in the ground patch, whose light
/// goes up to the ceiling, while the sun lands on the floor or walls: the walls' and the
/// ground's sensitivities of the sun were then wrong by factors of several.
#[allow(clippy::too_many_arguments)]
fn sensitivity(
    class: SurfaceClass,
    c0: &Components,
    none: &Components,
    mid: &Components,
    lo: &Components,
    hi: &Components,
    skies: &[StepSky],
    patches: &SkyPatches,
) -> ReflSens {
    let d1 = |a: &[f64], b: &[f64]| -> Vec<f64> {
        a.iter()
            .zip(b)
            .map(|(l, h)| (h - l) / (2.0 * DELTA))
            .collect()
    };
    let d2 = |a: &[f64], m: &[f64], b: &[f64]| -> Vec<f64> {
        a.iter()
            .zip(m)
            .zip(b)
            .map(|((l, m), h)| (h - 2.0 * m + l) / (2.0 * DELTA * DELTA))
            .collect()
    };
    let d1_sky = d1(&lo.sky, &hi.sky);
    let d2_sky = d2(&lo.sky, &mid.sky, &hi.sky);
    let (ns, nt, np) = (c0.nsens, c0.nsteps, c0.npatch);
    // Per step: kernel weights of the patches near the sun (none while it is down).
    let kernels: Vec<Vec<(usize, f64)>> = skies
        .iter()
        .map(|sk| {
            if sk.sun_radiance <= 0.0 || sk.sun_altitude_deg <= 0.0 || np != patches.len() {
                return Vec::new();
            }
            let sigma = SUN_KERNEL_DEG.to_radians();
            (1..np)
                .filter_map(|p| {
                    let c = patches.centre(p);
                    let cos = (c[0] * sk.sun_dir[0] + c[1] * sk.sun_dir[1] + c[2] * sk.sun_dir[2])
                        .clamp(-1.0, 1.0);
                    let a = cos.acos();
                    (a < 3.0 * sigma).then(|| (p, (-0.5 * (a / sigma).powi(2)).exp()))
                })
                .collect()
        })
        .collect();
    let mut d1_sun = vec![0.0; ns * nt];
    let mut d2_sun = vec![0.0; ns * nt];
    for s in 0..ns {
        // Per patch, summed over the steps: inter-reflected sky light and its derivatives
        // (the ratio of a patch's derivative to its light does not depend on the sky).
        let (mut ind, mut a1, mut a2) = (vec![0.0; np], vec![0.0; np], vec![0.0; np]);
        for t in 0..nt {
            let base = (s * nt + t) * np;
            for p in 0..np {
                // Light that met a tracked surface, from the same paths as the derivatives
                // (mid minus direct-only coefficients of another run is a small
                // difference of noisy numbers where the sensor sees the patch).
                ind[p] += mid.sky[base + p] - none.sky[base + p];
                a1[p] += d1_sky[base + p];
                a2[p] += d2_sky[base + p];
            }
        }
        let all: f64 = ind.iter().sum();
        if all <= 0.0 {
            continue;
        }
        // The whole sky's ratio: the fallback where the patches around the sun carry no
        // inter-reflected light.
        let g1 = a1.iter().sum::<f64>() / all;
        let g2 = a2.iter().sum::<f64>() / all;
        for t in 0..nt {
            let (mut wi, mut w1, mut w2) = (0.0, 0.0, 0.0);
            for &(p, w) in &kernels[t] {
                wi += w * ind[p];
                w1 += w * a1[p];
                w2 += w * a2[p];
            }
            // Below a thousandth of the sensor's inter-reflected sky light the patches'
            // few paths say nothing reliable.
            let (r1, r2) = if wi > 1e-3 * all {
                (w1 / wi, w2 / wi)
            } else {
                (g1, g2)
            };
            d1_sun[s * nt + t] = c0.sun_indirect[s * nt + t] * r1;
            d2_sun[s * nt + t] = c0.sun_indirect[s * nt + t] * r2;
        }
    }
    ReflSens {
        class,
        d1_sky,
        d2_sky,
        d1_sun,
        d2_sun,
    }
}

/// Reinhart MF from a patch count (144 MF^2 + 2).
fn dcs_mf(npatch: usize) -> usize {
    (1..=30).find(|mf| 144 * mf * mf + 2 == npatch).unwrap_or(1)
}
