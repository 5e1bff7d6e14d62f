//! # Hidden-effect spectral test cases
//!
//! As [`crate::cases`] with a spectral sensor: the truth room is the model with the
//! hidden effects written by [`crate::apply`] (a tinted glazing is a `spectrum`
//! pattern on the glass, a level change a scaled transmissivity), simulated with `rdc -cs N`
//! at the truth settings; the sensor has one channel per simulated band (named by its
//! centre wavelength, e.g. `391.1nm`) reading the band's spectral irradiance in W m-2 nm-1.
//! Noise, seeded: the issue-7 model (a fixed calibration factor per sensor
//! `exp(N(0, 0.03))` and a per-reading factor `exp(N(0, 0.02))`, both common to the
//! channels) plus an independent per-channel factor `exp(N(0, 0.01))` (a spectral sensor's
//! channel noise).

use super::channels::ChannelMap;
use super::readings::{SpectralReading, SpectralReadings};
use super::{SpectralModel, band_centres, simulate_scene};
use crate::cases::{Noise, RoomKind, Truth, room};
use crate::effects::Effect;
use crate::error::Result;
use crate::formats::sensors::Sensor;
use crate::formats::weather::Weather;
use crate::measurements::Bound;
use crate::radiometry::Channels;
use crate::session::Options;

/// Independent per-channel noise (relative, log-normal).
pub const CHANNEL_SIGMA: f64 = 0.01;

/// A generated spectral case.
pub struct SpectralCase {
    pub name: String,
    pub model_text: String,
    pub truth_text: String,
    pub sensors: Vec<Sensor>,
    pub weather: Weather,
    pub ch: Channels,
    /// Readings (weather step indices) and their channel values.
    pub bound: Vec<Bound>,
    pub values: Vec<Vec<f64>>,
    pub names: Vec<String>,
    pub hidden: Vec<Effect>,
}

pub use crate::cases::scene_of;

/// A control sensor as the seed's: inside the first window, 0.25 m from the glass at the
/// window's mid height (at most 1.65 m), facing out (vertical illuminance, mostly the sky
/// seen through the glass). `None` without windows.
pub fn window_control(room: &crate::room::Room) -> Option<Sensor> {
    let w = room.windows.first()?;
    let o = w.outward;
    let z = (0.5 * (w.sill + w.head)).min(1.65);
    Some(Sensor {
        id: "control".into(),
        ray: crate::formats::sensors::SensorRay::new(
            [w.centroid[0] - 0.25 * o[0], w.centroid[1] - 0.25 * o[1], z],
            [o[0], o[1], 0.0],
        ),
    })
}

/// Channel names of the band centres of `ch`, shortest wavelength first.
pub fn channel_names(ch: &Channels) -> Vec<(usize, String)> {
    let mut v: Vec<(usize, String)> = band_centres(ch)
        .into_iter()
        .enumerate()
        .map(|(b, c)| (b, format!("{c:.1}nm")))
        .collect();
    v.reverse();
    v
}

/// Build a case in room `kind` (its scene) with `sensors` (e.g. some of the room's
/// [`room`] sensors and a control sensor at the window).
#[allow(clippy::too_many_arguments)]
pub fn generate(
    name: &str,
    kind: RoomKind,
    sensors: Vec<Sensor>,
    weather: Weather,
    hidden: Vec<Effect>,
    nsteps: usize,
    seed: u64,
    truth: &Options,
    ch: &Channels,
) -> Result<SpectralCase> {
    let (model_text, _) = room(kind);
    let t = Truth::new(
        &model_text,
        &sensors,
        &weather,
        &hidden,
        nsteps,
        seed,
        truth,
    )?;
    let bound = t.bound(sensors.len(), 0.0);
    let (sim, _) = simulate_scene(&t.truth_scene, &sensors, &weather, &bound, &t.opts, ch)?;
    let names = channel_names(ch);
    // Sensor faults do not reach spectral readings (they never did; kept so that existing
    // spectral cases reproduce: the photopic builder applies them).
    let mut noise = Noise::new(seed, sensors.len());
    let (_, local) = super::measured_steps(&bound);
    let values = local
        .iter()
        .map(|b| {
            let v = sim.at(b.sensor, b.step);
            let (cal, reading) = noise.reading(b.sensor);
            let k = cal * reading;
            names
                .iter()
                .map(|(band, _)| {
                    v.get(*band).copied().unwrap_or(0.0)
                        / crate::metrics::melanopic::RADIANCE_SPAN_NM
                        * k
                        * noise.factor(CHANNEL_SIGMA)
                })
                .collect()
        })
        .collect();
    let model_text = t.model_text;
    let truth_text = t.truth_text;
    Ok(SpectralCase {
        name: name.to_string(),
        model_text,
        truth_text,
        sensors,
        weather,
        ch: *ch,
        bound,
        values,
        names: names.into_iter().map(|n| n.1).collect(),
        hidden,
    })
}

impl SpectralCase {
    /// The readings as the CSV parser returns them.
    pub fn readings(&self) -> SpectralReadings {
        SpectralReadings {
            file: format!("<{}>", self.name),
            centres: self
                .names
                .iter()
                .map(|n| super::readings::wavelength_of(n).unwrap_or(0.0))
                .collect(),
            names: self.names.clone(),
            header_line: 1,
            readings: self
                .bound
                .iter()
                .zip(&self.values)
                .map(|(b, v)| {
                    let s = &self.weather.steps[b.step];
                    SpectralReading {
                        month: s.month.into(),
                        day: s.day.into(),
                        hour: s.hour,
                        sensor: self.sensors[b.sensor].id.clone(),
                        values: v.clone(),
                        line: 0,
                    }
                })
                .collect(),
        }
    }

    /// The spectral model of scene `text` against this case's readings.
    pub fn model(&self, text: &str, opts: &Options) -> Result<SpectralModel> {
        let map = ChannelMap::bands(&self.readings(), &self.ch)?;
        SpectralModel::build(
            &scene_of(text)?,
            self.sensors.clone(),
            &self.weather,
            &self.bound,
            self.values.clone(),
            map,
            opts,
        )
    }

    /// The photopic model of scene `text` on the readings' photopic values (from `sm`, the
    /// spectral model of the same scene).
    pub fn photopic(
        &self,
        text: &str,
        sm: &SpectralModel,
        opts: &Options,
    ) -> Result<crate::model::Model> {
        super::photopic_model(
            &scene_of(text)?,
            &self.sensors,
            &self.weather,
            &self.bound,
            sm,
            opts,
        )
    }
}
