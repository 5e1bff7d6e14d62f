//! # The model under calibration: components, sensitivities, observations, prediction
//!
//! [`Model`] holds what every fit needs: the [`Components`] of the model as given, the
//! reflectance records (the sky coefficients and `Vsun` as exact polynomials in the surface
//! classes' reflectances, from one traced run each with path re-weighting records, so any
//! combination of class scales is evaluated from the same paths: [`Refl`]), the room's
//! windows, the skies and the observations.
//! [`Model::predict`] turns a list of effects into simulated illuminances for every
//! observation in a fraction of a millisecond per hundred readings, which is what makes
//! fitting interactive.

use super::effects::{self, Effect};
use super::measurements::Bound;
use super::room::{Room, SurfaceClass};
use super::simulate::{Components, Dcs, ReflRecords, Simulator, StepSky};
use crate::error::Result;
use crate::formats::sensors::Sensor;
use crate::scene::Scene;
use crate::sky::SkyPatches;

/// The reflectance records of a model (see the module documentation): the classes they
/// track, the sky coefficients' and `Vsun`'s records, and the changes already evaluated.
#[derive(Debug, Clone)]
pub struct Refl {
    pub classes: Vec<SurfaceClass>,
    pub sky: ReflRecords,
    pub sun: ReflRecords,
    memo: ReflMemo,
}

/// What a combination of class scales adds to the model's light: `[s][t][p]` sky (lux,
/// before any exterior or window weight) and `[s][t]` inter-reflected sun.
#[derive(Debug)]
pub struct ReflDelta {
    pub sky: Vec<f64>,
    pub sun: Vec<f64>,
}

/// The last few evaluated combinations (a fit varies one effect while the others' scales
/// stay put, so most predictions reuse one). A clone starts empty.
#[derive(Debug, Default)]
struct ReflMemo(std::sync::Mutex<Vec<MemoEntry>>);

/// One memoised combination: (class index, scale's bits) pairs and what they add.
type MemoEntry = (Vec<(usize, u64)>, std::sync::Arc<ReflDelta>);

impl Clone for ReflMemo {
    fn clone(&self) -> Self {
        ReflMemo::default()
    }
}

/// Combinations [`ReflMemo`] keeps.
const MEMO: usize = 16;

impl Refl {
    /// Index of `class` among the tracked classes.
    pub fn index(&self, class: SurfaceClass) -> Option<usize> {
        self.classes.iter().position(|c| *c == class)
    }
}

/// Everything the fits need.
#[derive(Debug, Clone)]
pub struct Model {
    pub comps: Components,
    /// Reflectance records (built with `reflectance`; `None` without, or when the room
    /// has no tracked class).
    pub refl: Option<Refl>,
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
    /// The part of the light that met the exterior ground, computed on first use
    /// ([`Model::ground_part`]).
    pub ground: std::sync::OnceLock<Option<std::sync::Arc<ReflDelta>>>,
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
    /// `[s][p]`: the hidden share of the light that reached sensor `s` by way of the
    /// exterior ground (set with [`Weights::gnd_seen`]; `None`: as `ind`).
    pub gnd: Option<Vec<f64>>,
    /// `[s]`: the hidden share of the sky's ground glow (patch 0) entering the windows,
    /// per sensor (set with [`Weights::glow_ind`]; `None`: as `ind`).
    pub glow: Option<Vec<f64>>,
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
    /// Per patch: share of the patch's light that reaches the windows by way of the
    /// exterior ground still doing so (a skyline shades the ground in front of the room
    /// from other directions than the windows'); `None`: as `win_ind`.
    pub gnd: Option<Vec<f64>>,
    /// Per step: the same for the sun; `None`: as `sun_win_ind`.
    pub sun_gnd: Option<Vec<f64>>,
    /// `[s][p]`: share of that ground light still reaching sensor `s` past what a skyline
    /// hides from the ground (different sensors are lit by different parts of the ground:
    /// [`super::effects::skyline`]); `None`: 1.
    pub gnd_seen: Option<Vec<f64>>,
    /// `[s][t]`: the same for the sun; `None`: 1.
    pub sun_gnd_seen: Option<Vec<f64>>,
    /// `[s]`: share of the sky's ground glow (patch 0) entering the windows still
    /// reaching sensor `s` (a skyline hides the glow from other directions for different
    /// sensors); `None`: as `win_ind`.
    pub glow_ind: Option<Vec<f64>>,
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
    /// (index into [`Refl::classes`], scale - 1).
    pub refl: Vec<(usize, f64)>,
}

impl Model {
    /// Build from coefficients: the reflectance records of every class the room has
    /// come from one re-weighted run each for the sky and the sun (cached).
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
        let mut refl = None;
        if with_reflectance {
            let classes = room.classes();
            if let (Some(sky), Some(sun)) = (
                simulator.dc_records(scene, &room, &classes)?,
                simulator.sun_records(scene, &room, &classes)?,
            ) {
                let expect =
                    |r: &ReflRecords, cols: usize| r.unscaled.len() == comps.nsens * cols * 3;
                if !expect(&sky, comps.npatch) || !expect(&sun, comps.nsteps) {
                    return Err(crate::error::Error::Mismatch(
                        "re-weighting records: unexpected size".into(),
                    ));
                }
                refl = Some(Refl {
                    classes,
                    sky,
                    sun,
                    memo: ReflMemo::default(),
                });
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
            ground: std::sync::OnceLock::new(),
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

    /// The light that met the exterior ground on its way, `[s][t][p]` sky and `[s][t]`
    /// sun in lux (minus what the records give with the ground class black: every path
    /// touching the ground); `None` without records or a ground class.
    pub fn ground_part(&self) -> Option<&ReflDelta> {
        self.ground
            .get_or_init(|| {
                let gi = self.refl.as_ref()?.index(SurfaceClass::Ground)?;
                let d = self.refl_delta(&[(gi, -1.0)])?;
                Some(std::sync::Arc::new(ReflDelta {
                    sky: d.sky.iter().map(|x| (-x).max(0.0)).collect(),
                    sun: d.sun.iter().map(|x| (-x).max(0.0)).collect(),
                }))
            })
            .as_deref()
    }

    /// Per sensor, how the light that met the exterior ground reached it, as shares of
    /// that light (sky coefficients, inter-reflected sun): `[seen directly through a
    /// window, after one bounce in the room, after more]`, from the re-weighting records
    /// evaluated with the room's classes scaled by `t` (the ground part is a polynomial
    /// `g(t) = g0 + g1 t + ...` in it: `g0` and the slope `g1` at 0 are the first two
    /// shares). `None` without records or a ground class.
    pub fn ground_bounces(&self) -> Option<[Vec<[f64; 3]>; 2]> {
        let r = self.refl.as_ref()?;
        r.index(SurfaceClass::Ground)?;
        let ns = self.nsens();
        let shares = |rec: &ReflRecords| -> Option<Vec<[f64; 3]>> {
            let eval = |g: f64, t: f64| {
                let f: Vec<f64> = rec
                    .materials
                    .iter()
                    .map(|(c, _)| if *c == SurfaceClass::Ground { g } else { t })
                    .collect();
                rec.rw.apply(&f).ok()
            };
            // A small step: g(t) is a polynomial of low degree, its next term t g2.
            const EPS: f64 = 1e-4;
            let part = |t: f64| -> Option<Vec<f64>> {
                let (a, b) = (eval(1.0, t)?, eval(0.0, t)?);
                Some(a.iter().zip(&b).map(|(x, y)| x - y).collect())
            };
            let (g0, ge, gall) = (part(0.0)?, part(EPS)?, part(1.0)?);
            let per = g0.len() / ns.max(1);
            Some(
                (0..ns)
                    .map(|s| {
                        let sum = |v: &[f64]| v[s * per..(s + 1) * per].iter().sum::<f64>();
                        let (a, e, all) = (sum(&g0), sum(&ge), sum(&gall));
                        if all <= 0.0 {
                            return [0.0, 0.0, 1.0];
                        }
                        let d = (a / all).clamp(0.0, 1.0);
                        let one = ((e - a) / EPS / all).clamp(0.0, 1.0 - d);
                        [d, one, 1.0 - d - one]
                    })
                    .collect(),
            )
        };
        Some([shares(&r.sky)?, shares(&r.sun)?])
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
            gnd: None,
            sun_gnd: None,
            gnd_seen: None,
            sun_gnd_seen: None,
            glow_ind: None,
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
                if let Some(i) = self.refl.as_ref().and_then(|r| r.index(*class)) {
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
        let delta = self.refl_delta(&w.refl);
        // The ground's part is weighted on its own only when an effect set its weights;
        // it follows the ground class's scale to first order.
        let ground = if w.gnd.is_some() || w.sun_gnd.is_some() {
            self.ground_part()
        } else {
            None
        };
        let kg = self.ground_scale(&w.refl);
        self.obs
            .iter()
            .map(|o| {
                let (s, t) = (o.sensor, o.step);
                let st = s * nt + t;
                let base = st * np;
                let (mut ind, mut dir) = (0.0, 0.0);
                for p in 0..np {
                    let tot = c.sky[base + p] + delta.as_ref().map_or(0.0, |d| d.sky[base + p]);
                    let d = c.sky_direct[base + p];
                    let g = ground.map_or(0.0, |g| (kg * g.sky[base + p]).min(tot - d).max(0.0));
                    let wg = w.gnd.as_ref().map_or(w.win_ind[p], |v| v[p])
                        * w.gnd_seen.as_ref().map_or(1.0, |v| v[s * np + p]);
                    let wd = w.win_dir.as_ref().map_or(1.0, |v| v[s * np + p]);
                    let wi = match (&w.glow_ind, p) {
                        (Some(v), 0) => v[s],
                        _ => w.win_ind[p],
                    };
                    ind += w.patch[p] * (wi * (tot - d - g) + wg * g);
                    dir += w.patch[p] * wd * d;
                    if let Some(f) = &w.fill {
                        let r = f.ratio[t * np + p];
                        let fg = f.gnd.as_ref().map_or(f.ind[p], |v| v[s * np + p]);
                        let fi = match (&f.glow, p) {
                            (Some(v), 0) => v[s],
                            _ => f.ind[p],
                        };
                        ind += w.patch[p] * r * (fi * (tot - d - g) + fg * g);
                        dir += w.patch[p] * f.dir[s * np + p] * r * d;
                    }
                }
                let si = c.sun_indirect[st] + delta.as_ref().map_or(0.0, |d| d.sun[st]);
                let gs = ground.map_or(0.0, |g| (kg * g.sun[st]).min(si).max(0.0));
                let wgs = w.sun_gnd.as_ref().map_or(w.sun_win_ind[t], |v| v[t])
                    * w.sun_gnd_seen.as_ref().map_or(1.0, |v| v[st]);
                let swd = w.sun_win_dir.as_ref().map_or(1.0, |v| v[st]);
                ind += w.sun[t] * (w.sun_win_ind[t] * (si - gs) + wgs * gs);
                dir += w.sun[t] * swd * c.sun_direct[st];
                (ind, dir)
            })
            .collect()
    }

    /// The ground class's scale in `refl` (1 when it is not scaled).
    pub fn ground_scale(&self, refl: &[(usize, f64)]) -> f64 {
        let gi = self
            .refl
            .as_ref()
            .and_then(|r| r.index(SurfaceClass::Ground));
        refl.iter()
            .filter(|x| Some(x.0) == gi)
            .fold(1.0, |k, x| k * (1.0 + x.1))
    }

    /// What the class scales `refl` ((index into [`Refl::classes`], scale - 1)) add to the
    /// sky and the inter-reflected sun, evaluated from the records (memoised); `None` when
    /// nothing is scaled.
    pub fn refl_delta(&self, refl: &[(usize, f64)]) -> Option<std::sync::Arc<ReflDelta>> {
        let r = self.refl.as_ref()?;
        let mut key: Vec<(usize, u64)> = refl
            .iter()
            .filter(|x| x.1 != 0.0)
            .map(|&(i, dk)| (i, (1.0 + dk).to_bits()))
            .collect();
        if key.is_empty() {
            return None;
        }
        key.sort_unstable();
        if let Ok(m) = r.memo.0.lock()
            && let Some((_, d)) = m.iter().find(|x| x.0 == key)
        {
            return Some(d.clone());
        }
        let scales: Vec<(SurfaceClass, f64)> = key
            .iter()
            .filter_map(|&(i, k)| Some((*r.classes.get(i)?, f64::from_bits(k))))
            .collect();
        let (ns, nt, np) = (self.nsens(), self.nsteps(), self.comps.npatch);
        let dsky = r.sky.scaled_difference(&scales).ok()?;
        let dsun = r.sun.scaled_difference(&scales).ok()?;
        let mut sky = vec![0.0; ns * nt * np];
        let mut sun = vec![0.0; ns * nt];
        for s in 0..ns {
            for (t, sk) in self.skies.iter().enumerate() {
                let base = (s * nt + t) * np;
                for p in 0..np {
                    let dc = &dsky[(s * np + p) * 3..][..3];
                    let l = &sk.sky[p * 3..][..3];
                    sky[base + p] = lux_of(&[dc[0] * l[0], dc[1] * l[1], dc[2] * l[2]]);
                }
                sun[s * nt + t] = lux_of(&dsun[(s * nt + t) * 3..][..3]) * sk.sun_radiance;
            }
        }
        let d = std::sync::Arc::new(ReflDelta { sky, sun });
        if let Ok(mut m) = r.memo.0.lock() {
            if m.len() >= MEMO {
                m.remove(0);
            }
            m.push((key, d.clone()));
        }
        Some(d)
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

/// Lux of RGB irradiance (see [`super::simulate::LUX_RGB`]).
fn lux_of(v: &[f64]) -> f64 {
    v.iter()
        .zip(super::simulate::LUX_RGB)
        .map(|(a, b)| a * b)
        .sum()
}

/// Reinhart MF from a patch count (144 MF^2 + 2).
fn dcs_mf(npatch: usize) -> usize {
    (1..=30).find(|mf| 144 * mf * mf + 2 == npatch).unwrap_or(1)
}
