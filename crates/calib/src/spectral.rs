//! # Spectral calibration (issue 8): spectral sensors, the seed's chapter-6 workflow, tint
//!
//! Measurements from a multi-channel spectral sensor (e.g. 18 channels) are compared with
//! an N-band simulation of the model (`rdc -cs N`) at the measured steps:
//!
//! | module | concept |
//! |---|---|
//! | [`readings`] | the spectral readings CSV (`month,day,hour,sensor,410nm,...`) and its checks |
//! | [`channels`] | simulated bands -> sensor channels (band convention or response curves) |
//! | [`simulate`] | N-band irradiance at the measured steps through `rdc -cs N` coefficients |
//! | [`scan`] | the seed's chapter-6 workflow: transmittance options by 18-channel MAE at the control sensor (Eq. 6.1), then Table 6.4 (Ev, m-EDI, M/P per sensor) and the spectral-shape Pearson r |
//! | [`explain`] | `rcalib explain` with spectral readings: the photopic effects plus the glazing [`tint`](crate::effects::tint) fitted to the wavelength-dependent residuals |
//! | [`case`] | hidden-effect spectral test cases (tinted or scaled glazing) |
//!
//! [`SpectralModel`] binds the readings to the simulation; every window option or tint is a
//! per-band factor on the model's simulated bands (all daylight enters through the glazing
//! once, and Radiance's glass multiplies only its transmission by a pattern), so the scan
//! and the fits re-simulate nothing.

pub mod case;
pub mod channels;
pub mod explain;
pub mod readings;
pub mod scan;
pub mod simulate;

use self::channels::ChannelMap;
use self::simulate::{SpectralSim, simulate};
use super::measurements::Bound;
use super::session::Options;
use super::simulate::{Simulator, StepSky, step_skies, subset_wea};
use crate::error::{Error, Result};
use crate::formats::sensors::Sensor;
use crate::formats::weather::Weather;
use crate::material::spectrum::Sampled;
use crate::metrics::melanopic::{BandWeights, Melanopic};
use crate::radiometry::Channels;
use crate::scene::{Primitive, Scene};

/// The seed's channel layout: 18 bands over 380-780 nm (`-cs 18 -cw 380 780`).
pub fn seed_channels() -> Channels {
    Channels {
        ncomp: 18,
        splits: [780.0, 588.0, 480.0, 380.0],
    }
}

/// Centre wavelengths of the bands of `ch`, in the simulation's order (longest first).
pub fn band_centres(ch: &Channels) -> Vec<f64> {
    (0..ch.ncomp)
        .map(|b| {
            let (u, l) = ch.band(b);
            0.5 * (u + l)
        })
        .collect()
}

/// Spectral readings bound to an N-band simulation of the model.
#[derive(Debug, Clone)]
pub struct SpectralModel {
    pub sim: SpectralSim,
    /// Observations: sensor, step (index into the measured steps), value = measured
    /// photopic illuminance (ratio estimator, see [`channels`]) on Radiance's photopic scale
    /// (what the photopic model predicts).
    pub obs: Vec<Bound>,
    /// Channel readings of each observation.
    pub meas: Vec<Vec<f64>>,
    pub map: ChannelMap,
    pub sensors: Vec<Sensor>,
    pub skies: Vec<StepSky>,
    /// Normal-incidence transmittance of the model's glass per band (with its patterns).
    pub base_tau: Vec<f64>,
    bw: BandWeights,
    w_y: Vec<f64>,
    w_m: Vec<f64>,
}

/// Photopic and melanopic quantities of one reading, simulated and measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quantities {
    pub sim: Melanopic,
    pub ev_meas: f64,
    pub medi_meas: f64,
}

impl Quantities {
    pub fn mp_meas(&self) -> f64 {
        if self.ev_meas > 0.0 {
            self.medi_meas / self.ev_meas
        } else {
            0.0
        }
    }
}

/// The distinct weather steps of `readings` (sorted) and the readings re-indexed to them.
pub fn measured_steps(readings: &[Bound]) -> (Vec<usize>, Vec<Bound>) {
    let mut idx: Vec<usize> = readings.iter().map(|b| b.step).collect();
    idx.sort_unstable();
    idx.dedup();
    let obs = readings
        .iter()
        .map(|b| Bound {
            step: idx.binary_search(&b.step).unwrap_or(0),
            ..*b
        })
        .collect();
    (idx, obs)
}

/// Simulate `scene` spectrally at the steps of `readings` (weather step indices).
pub fn simulate_scene(
    scene: &Scene,
    sensors: &[Sensor],
    weather: &Weather,
    readings: &[Bound],
    opts: &Options,
    ch: &Channels,
) -> Result<(SpectralSim, Vec<StepSky>)> {
    if sensors.is_empty() {
        return Err(Error::Usage("no sensors".into()));
    }
    let (idx, _) = measured_steps(readings);
    let skies = step_skies(weather, &idx, opts.settings.mf);
    let simulator = Simulator::new(
        opts.settings.clone(),
        opts.cache.clone(),
        sensors,
        subset_wea(weather, &idx),
    )?
    .with_progress(opts.progress.clone());
    let sim = simulate(&simulator, scene, &skies, sensors.len(), ch)?;
    Ok((sim, skies))
}

/// Normal-incidence transmittance per band of the first `glass` in `scene`, times the
/// `spectrum`/`specfile` patterns in its modifier chain (1 where there is no glass).
pub fn glass_transmittance(scene: &Scene, ch: &Channels) -> Vec<f64> {
    let mut tau = vec![1.0; ch.ncomp];
    let Some(gi) = scene
        .objects
        .iter()
        .position(|o| matches!(o.kind, Primitive::Glass { .. }))
    else {
        return tau;
    };
    if let Primitive::Glass {
        transmissivity,
        index,
    } = &scene.objects[gi].kind
    {
        // One level for every band (a neutral stand-in for the glass, which the scan's
        // options and the VLT column scale): the glass's luminous normal transmittance, as
        // glazing transmittances are quoted (was the mean of the channels; identical for
        // the neutral glass of every tested case).
        let t0 = crate::effects::transmittance::normal_transmittance(
            transmissivity,
            *index,
            crate::effects::transmittance::Summary::Luminous,
        );
        tau.iter_mut().for_each(|t| *t = t0);
    }
    for m in scene.modifier_chain(gi) {
        let s = match &scene.objects[m].kind {
            Primitive::Spectrum { nm_a, nm_b, values } => {
                Sampled::new(*nm_a, *nm_b, values.clone())
            }
            Primitive::SpecFile { data: Some(d), .. } => Sampled::from_data(d),
            _ => continue,
        };
        for (t, v) in tau.iter_mut().zip(s.to_channels(ch).as_slice()) {
            *t *= f64::from(*v);
        }
    }
    tau
}

impl SpectralModel {
    /// Bind readings (`bound` with weather step indices, `values` their channel readings)
    /// to the model `scene` simulated at `opts`.
    pub fn build(
        scene: &Scene,
        sensors: Vec<Sensor>,
        weather: &Weather,
        bound: &[Bound],
        values: Vec<Vec<f64>>,
        map: ChannelMap,
        opts: &Options,
    ) -> Result<SpectralModel> {
        let ch = map.ch;
        let (sim, skies) = simulate_scene(scene, &sensors, weather, bound, opts, &ch)?;
        let (_, obs) = measured_steps(bound);
        let mut m = SpectralModel {
            sim,
            obs,
            meas: values,
            bw: BandWeights::new(&ch)?,
            w_y: map.weights(false),
            w_m: map.weights(true),
            map,
            sensors,
            skies,
            base_tau: glass_transmittance(scene, &ch),
        };
        // The photopic model works on Radiance's photopic scale (179 lm/W x its RGB or band
        // weights, `179 sum v_b A_b`); CIE illuminance (683 lm/W x ybar) of the same bands is
        // larger by 683 x int ybar / (400 x 179) (1.93 % over 380-780 nm) for any spectrum.
        let full = Channels::spectral(3, 380.0, 780.0)
            .map(|c| {
                crate::colour::bands::band_integrals(&crate::colour::cie::tables().cmf[1], &c)
                    .iter()
                    .sum::<f64>()
            })
            .unwrap_or(106.857);
        let to_radiance = crate::radiometry::WHITE_EFFICACY
            * crate::metrics::melanopic::RADIANCE_SPAN_NM
            / (crate::colour::melanopic::KM * full);
        for i in 0..m.obs.len() {
            m.obs[i].value = m.quantities(i, None).ev_meas * to_radiance;
        }
        Ok(m)
    }

    pub fn ch(&self) -> Channels {
        self.map.ch
    }

    /// Simulated bands of observation `i` times per-band `factors`.
    pub fn bands(&self, i: usize, factors: Option<&[f64]>) -> Vec<f64> {
        let o = &self.obs[i];
        let v = self.sim.at(o.sensor, o.step);
        match factors {
            Some(f) => v.iter().zip(f).map(|(a, b)| a * b).collect(),
            None => v.to_vec(),
        }
    }

    /// Simulated channel readings of observation `i`.
    pub fn channels(&self, i: usize, factors: Option<&[f64]>) -> Vec<f64> {
        self.map.apply(&self.bands(i, factors))
    }

    /// Ev, m-EDI (simulated and measured) of observation `i` under `factors`; measured ones
    /// by the ratio estimator of [`channels`] against the model as given.
    pub fn quantities(&self, i: usize, factors: Option<&[f64]>) -> Quantities {
        let sim = self.bw.eval(&self.bands(i, factors));
        let base = self.bw.eval(&self.bands(i, None));
        let sc = self.channels(i, None);
        let m = &self.meas[i];
        let ratio = |w: &[f64]| {
            let num: f64 = w.iter().zip(m).map(|(a, b)| a * b).sum();
            let den: f64 = w.iter().zip(&sc).map(|(a, b)| a * b).sum();
            if den > 0.0 { num / den } else { 0.0 }
        };
        Quantities {
            sim,
            ev_meas: base.ev * ratio(&self.w_y),
            medi_meas: base.medi * ratio(&self.w_m),
        }
    }

    /// Sensor ids.
    pub fn ids(&self) -> Vec<String> {
        self.sensors.iter().map(|s| s.id.clone()).collect()
    }
}

/// The photopic companion of spectral model `sm` (its readings' photopic values at
/// `bound`): the photopic effects fitted on the same readings. The spectral simulation's
/// skies are gendaymtx's (per band, as rspecsky makes them), so this model sees the same
/// sky, whatever `opts.sky` says.
pub fn photopic_model(
    scene: &Scene,
    sensors: &[Sensor],
    weather: &Weather,
    bound: &[Bound],
    sm: &SpectralModel,
    opts: &Options,
) -> Result<super::model::Model> {
    let readings: Vec<Bound> = bound
        .iter()
        .zip(&sm.obs)
        .map(|(b, o)| Bound {
            value: o.value,
            ..*b
        })
        .collect();
    let opts = Options {
        sky: super::simulate::StepSkyModel::Gendaymtx,
        ..opts.clone()
    };
    super::session::build(scene, sensors.to_vec(), weather, &readings, &opts)
}

/// Everything `rcalib spectral` reads from files.
pub struct SpectralInputs {
    pub scene: Scene,
    pub sensors: Vec<Sensor>,
    pub weather: Weather,
    pub readings: readings::SpectralReadings,
    /// Readings bound to sensors and weather steps, and their channel values.
    pub bound: Vec<Bound>,
    pub values: Vec<Vec<f64>>,
    pub map: ChannelMap,
}

/// Read scene, sensors, weather, spectral readings and (optionally) response curves, bind
/// the readings and map the channels onto the bands of `ch`.
pub fn load(
    scene_files: &[String],
    sensors: &str,
    weather: &str,
    measured: &str,
    response: Option<&str>,
    ch: &Channels,
) -> Result<SpectralInputs> {
    let scene = crate::scene::load(scene_files, &crate::scene::LoadOptions::from_env())?;
    let sensors_v = super::inputs::load_sensors(sensors)?;
    let w = Weather::read_path(weather)?;
    let r = readings::SpectralReadings::read_path(measured)?;
    let map = match response {
        Some(p) => ChannelMap::with_responses(&r, &channels::Responses::read_path(p)?, ch)?,
        None => ChannelMap::bands(&r, ch)?,
    };
    let ids: Vec<String> = sensors_v.iter().map(|s| s.id.clone()).collect();
    let steps: Vec<(u32, u32, f64)> = w
        .steps
        .iter()
        .map(|s| (u32::from(s.month), u32::from(s.day), s.hour))
        .collect();
    let (bound, values) = r.bind(&ids, &steps, weather)?;
    Ok(SpectralInputs {
        scene,
        sensors: sensors_v,
        weather: w,
        readings: r,
        bound,
        values,
        map,
    })
}

impl SpectralInputs {
    /// The spectral model of the scene.
    pub fn model(&self, opts: &Options) -> Result<SpectralModel> {
        SpectralModel::build(
            &self.scene,
            self.sensors.clone(),
            &self.weather,
            &self.bound,
            self.values.clone(),
            self.map.clone(),
            opts,
        )
    }

    /// The photopic model on the readings' photopic values (from `sm`).
    pub fn photopic(&self, sm: &SpectralModel, opts: &Options) -> Result<super::model::Model> {
        photopic_model(
            &self.scene,
            &self.sensors,
            &self.weather,
            &self.bound,
            sm,
            opts,
        )
    }

    /// Index of the control sensor `id` (default: the sensor nearest a window among those
    /// with spectral readings). A control without readings has nothing to compare: every
    /// window option would score MAE 0 and the "best" would be arbitrary (issue 22), so it
    /// is refused, naming the sensors that have readings.
    pub fn control(&self, id: Option<&str>) -> Result<usize> {
        let mut with: Vec<usize> = self.bound.iter().map(|b| b.sensor).collect();
        with.sort_unstable();
        with.dedup();
        let names = || {
            with.iter()
                .map(|&i| self.sensors[i].id.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        match id {
            Some(id) => {
                let i = self
                    .sensors
                    .iter()
                    .position(|s| s.id == id)
                    .ok_or_else(|| {
                        Error::Usage(format!(
                            "--control '{id}': no such sensor id in the sensor file"
                        ))
                    })?;
                if with.binary_search(&i).is_err() {
                    return Err(Error::Usage(format!(
                        "--control '{id}': that sensor has no spectral readings; give one \
                         that has: {}",
                        names()
                    )));
                }
                Ok(i)
            }
            None => {
                let room = super::room::Room::new(
                    &self.scene,
                    super::room::sensor_centroid(&self.sensors),
                    &[],
                );
                with.iter()
                    .copied()
                    .min_by(|a, b| self.depth(&room, *a).total_cmp(&self.depth(&room, *b)))
                    .ok_or_else(|| {
                        Error::Usage("no sensor has spectral readings to compare".into())
                    })
            }
        }
    }

    /// Distance of sensor `s` from the nearest window plane (m; 0 without windows).
    pub fn depth(&self, room: &super::room::Room, s: usize) -> f64 {
        let p = self.sensors[s].ray.org;
        room.windows
            .iter()
            .map(|w| {
                let d = [p[0] - w.centroid[0], p[1] - w.centroid[1], 0.0];
                -super::room::dot(d, w.outward)
            })
            .fold(f64::INFINITY, f64::min)
            .clamp(0.0, f64::MAX)
    }
}
