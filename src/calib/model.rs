//! # The model under calibration: components, sensitivities, observations, prediction
//!
//! [`Model`] holds what every fit needs: the [`Components`] of the model as given, the
//! reflectance sensitivities (coefficients re-traced with each surface class's reflectance
//! scaled by `1 ± DELTA`, combined by quadratic interpolation), the room's windows, the
//! skies and the observations. [`Model::predict`] turns a list of effects into simulated
//! illuminances for every observation in a fraction of a millisecond per hundred readings,
//! which is what makes fitting interactive.
//!
//! Where path re-weighting (rdc recording per-path reflection records) becomes available,
//! it replaces the re-traces in [`Model::build`]: the sensitivities are the same arrays.

use super::effects::{self, Effect};
use super::measurements::Bound;
use super::room::{Room, SurfaceClass};
use super::simulate::{Components, Dcs, StepSky, Tracer};
use crate::error::Result;
use crate::formats::sensors::Sensor;
use crate::scene::Scene;
use crate::sky::SkyPatches;

/// Relative reflectance step of the re-traced sensitivities.
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
    /// Build from coefficients: re-traces the reflectance sensitivities of every class the
    /// room has (two cached runs per class).
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
        let mut refl = Vec::new();
        if with_reflectance {
            for class in room.classes() {
                let lo = tracer.dc_scaled(scene, &room, class, 1.0 - DELTA)?;
                let hi = tracer.dc_scaled(scene, &room, class, 1.0 + DELTA)?;
                let c_lo = Components::new(
                    &Dcs {
                        total: lo,
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
                refl.push(sensitivity(class, &comps, &c_lo, &c_hi));
            }
        }
        let patches = SkyPatches::new(dcs_mf(dcs.npatch));
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

/// Sensitivities from components at `1 - DELTA` and `1 + DELTA`. The inter-reflected sun is
/// not re-traced (one run per step and class would dominate the cost): its relative
/// sensitivity is taken as that of the sensor's inter-reflected sky light, i.e. the sun's
/// first bounce is assumed to land where the sky's does (near the window). Where rdc's path
/// re-weighting records become available they give the sun's own sensitivity for free.
fn sensitivity(class: SurfaceClass, c0: &Components, lo: &Components, hi: &Components) -> ReflSens {
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
    let d2_sky = d2(&lo.sky, &c0.sky, &hi.sky);
    let (ns, nt, np) = (c0.nsens, c0.nsteps, c0.npatch);
    let mut d1_sun = vec![0.0; ns * nt];
    let mut d2_sun = vec![0.0; ns * nt];
    for s in 0..ns {
        let r = s * nt * np..(s + 1) * nt * np;
        let ind: f64 = c0.sky[r.clone()]
            .iter()
            .zip(&c0.sky_direct[r.clone()])
            .map(|(a, b)| a - b)
            .sum();
        if ind <= 0.0 {
            continue;
        }
        let r1 = d1_sky[r.clone()].iter().sum::<f64>() / ind;
        let r2 = d2_sky[r].iter().sum::<f64>() / ind;
        for t in 0..nt {
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
