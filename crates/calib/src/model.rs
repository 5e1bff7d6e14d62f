//! # The model under calibration: components, sensitivities, observations, prediction
//!
//! [`Model`] holds what every fit needs: the [`Components`] of the model as given, the
//! reflectance sensitivities (the light with each surface class's reflectance scaled by
//! `1 ± DELTA`, combined by quadratic interpolation: the sky's from one traced run with path
//! re-weighting records, the inter-reflected sun's from `Vsun` re-traced on the scaled
//! scene with the same seeds), the room's windows, the skies and the observations.
//! [`Model::predict`] turns a list of effects into simulated illuminances for every
//! observation in a fraction of a millisecond per hundred readings, which is what makes
//! fitting interactive.

use super::effects::{self, Effect};
use super::measurements::Bound;
use super::room::{Room, SurfaceClass};
use super::simulate::{Components, Dcs, Simulator, StepSky};
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
    /// The sky cells the exterior obstruction blocks, computed on first use.
    pub horizon: std::sync::OnceLock<effects::obstruction::Horizon>,
    /// The same cells listed per sensor for the furniture panel, computed on first use.
    pub sight: std::sync::OnceLock<effects::local::Sight>,
    /// The skyline profile's geometry and facade luminance, computed on first use.
    pub skyline: std::sync::OnceLock<effects::skyline::Cache>,
}

/// The light an exterior obstruction's facade sends towards the room in place of the sky
/// it hides (see [`super::effects::obstruction`]): per patch the hidden share of the light
/// entering the windows, per sensor and patch the hidden share of its direct view, and per
/// step and patch the facade's luminance over the patch's.
#[derive(Debug, Clone)]
pub struct Fill {
    pub ind: Vec<f64>,
    /// `[s][p]`
    pub dir: Vec<f64>,
    /// `[t][p]`
    pub ratio: Vec<f64>,
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
    /// Per sensor: inter-reflected light left by a local obstruction (the part of the
    /// room it hides from the sensor, less what its own face sends back).
    pub local_ind: Vec<f64>,
    /// What an exterior obstruction sends back in place of the sky it hides.
    pub fill: Option<Fill>,
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
        simulator: &Simulator,
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
            // Sky: one traced run with path re-weighting records. The middle variant is
            // that run's own (unscaled) coefficients, so the differences come from one set
            // of paths even where the cached `total` was traced by another tracer version.
            let (scaled, _none) =
                simulator.dc_scaled(scene, &room, &classes, &[1.0 - DELTA, 1.0, 1.0 + DELTA])?;
            // The inter-reflected sun: the sun paths re-weighted the same way (one run for
            // every class), so its sensitivities are as free of Monte Carlo noise as the
            // sky's.
            let (sun_scaled, _) =
                simulator.sun_scaled(scene, &room, &classes, &[1.0 - DELTA, 1.0, 1.0 + DELTA])?;
            for ((&class, v), vs) in classes.iter().zip(scaled).zip(sun_scaled) {
                let [lo, mid, hi]: [Vec<f64>; 3] = v.try_into().map_err(|_| {
                    crate::error::Error::Mismatch("re-weighting: three variants expected".into())
                })?;
                let sky = |total: Vec<f64>| {
                    Components::new(
                        &Dcs {
                            total,
                            ..dcs.clone()
                        },
                        &skies,
                    )
                    .sky
                };
                let [vs_lo, vs_mid, vs_hi]: [Vec<f64>; 3] = vs.try_into().map_err(|_| {
                    crate::error::Error::Mismatch("re-weighting: three variants expected".into())
                })?;
                let sun_ind = |sun_total: Vec<f64>| {
                    Components::new(
                        &Dcs {
                            sun_total,
                            ..dcs.clone()
                        },
                        &skies,
                    )
                    .sun_indirect
                };
                refl.push(sensitivity(
                    class,
                    (&sky(lo), &sky(mid), &sky(hi)),
                    (&sun_ind(vs_lo), &sun_ind(vs_mid), &sun_ind(vs_hi)),
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
            horizon: std::sync::OnceLock::new(),
            sight: std::sync::OnceLock::new(),
            skyline: std::sync::OnceLock::new(),
        })
    }

    /// Per sensor, the sky cells it sees through a window (built on first use).
    pub fn sight(&self) -> &effects::local::Sight {
        self.sight.get_or_init(|| effects::local::Sight::new(self))
    }

    /// The sky cells of [`effects::obstruction::Horizon`] (built on first use).
    pub fn horizon(&self) -> &effects::obstruction::Horizon {
        self.horizon
            .get_or_init(|| effects::obstruction::Horizon::new(self))
    }

    /// The skyline profile's cache of [`effects::skyline::Cache`] (built on first use).
    pub fn skyline(&self) -> &effects::skyline::Cache {
        self.skyline
            .get_or_init(|| effects::skyline::Cache::new(self))
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
            local_ind: vec![1.0; ns],
            fill: None,
            tau: 1.0,
            cal: vec![1.0; ns],
            refl: Vec::new(),
        }
    }

    /// Weights with `effects` applied in order.
    pub fn weights(&self, effects: &[Effect]) -> Weights {
        let mut w = self.unit_weights();
        for e in effects {
            self.add_effect(e, &mut w);
        }
        w
    }

    /// Apply one more effect to weights (every effect multiplies its own factors, so the
    /// order does not matter): lets a fit compute the other effects' weights once.
    pub fn add_effect(&self, e: &Effect, w: &mut Weights) {
        match e {
            Effect::Transmittance { .. } => effects::transmittance::apply(e, self, w),
            Effect::Tint { .. } => effects::tint::apply(e, self, w),
            Effect::Obstruction { .. } => effects::obstruction::apply(e, self, w),
            Effect::Skyline { .. } => effects::skyline::apply(e, self, w),
            Effect::Reflectance { class, scale } => {
                if let Some(i) = self.refl.iter().position(|r| r.class == *class) {
                    w.refl.push((i, scale - 1.0));
                }
                // The sky's ground patch (gendaymtx: reflectance 0.2 times the
                // horizontal illuminance, beyond the modelled ground) is not scaled:
                // rcalib's skies always use 0.2, and `apply` can only change the
                // ground's material, so the fitted model must not scale it either.
            }
            Effect::Overhang { .. } => effects::overhang::apply(e, self, w),
            Effect::LocalObstruction { .. } | Effect::Furniture { .. } => {
                effects::local::apply(e, self, w)
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
                    if let Some(f) = &w.fill {
                        let r = f.ratio[t * np + p];
                        ind += w.patch[p] * f.ind[p] * r * (tot - d);
                        dir += w.patch[p] * f.dir[s * np + p] * r * d;
                    }
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
                w.cal[o.sensor]
                    * w.tau
                    * (ind * w.local_ind[o.sensor] + w.local[o.sensor] * dir).max(0.0)
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

/// First and second derivatives from values at `1 - DELTA`, 1 and `1 + DELTA` (quadratic
/// interpolation), for the sky (per patch) and the inter-reflected sun.
fn sensitivity(
    class: SurfaceClass,
    sky: (&[f64], &[f64], &[f64]),
    sun: (&[f64], &[f64], &[f64]),
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
    ReflSens {
        class,
        d1_sky: d1(sky.0, sky.2),
        d2_sky: d2(sky.0, sky.1, sky.2),
        d1_sun: d1(sun.0, sun.2),
        d2_sun: d2(sun.0, sun.1, sun.2),
    }
}

/// Reinhart MF from a patch count (144 MF^2 + 2).
fn dcs_mf(npatch: usize) -> usize {
    (1..=30).find(|mf| 144 * mf * mf + 2 == npatch).unwrap_or(1)
}
