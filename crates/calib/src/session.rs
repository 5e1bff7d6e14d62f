//! # From files to a [`Model`]: the steps every `rcalib` command shares
//!
//! Load the scene, sensors, weather and readings; bind readings to sensors and weather steps;
//! compute the skies of the measured steps only; trace (or fetch from the cache) the
//! coefficients; find the windows and surface classes; build the model with its
//! reflectance sensitivities.

use super::inputs::load_sensors;
use super::measurements::{Bound, Columns, Measurements};
use super::model::Model;
use super::room::{Room, SurfaceClass, sensor_centroid};
use super::simulate::{
    Settings, Simulator, StepSkyModel, step_skies_seen, step_skies_with, subset_wea,
};
use crate::error::{Error, Result};
use crate::formats::sensors::Sensor;
use crate::formats::weather::Weather;
use crate::progress::Reporter;
use crate::scene::{self, LoadOptions, Scene};
use std::path::PathBuf;

/// How to simulate.
#[derive(Debug, Clone)]
pub struct Options {
    pub settings: Settings,
    pub cache: Option<PathBuf>,
    pub classes: Vec<(String, SurfaceClass)>,
    /// Re-trace reflectance sensitivities (explain needs them; compare does not).
    pub reflectance: bool,
    /// The measured steps' skies ([`StepSkyModel`]). `Gendaylit` (the default) is
    /// gendaylit's sky as the scene sees it ([`step_skies_seen`]: one more traced run,
    /// cached), the sky of a point-in-time `gendaylit | rtrace -I` reference, within 0.3 %
    /// of it per step; `Gendaymtx` is the annual pipelines' sky (gendaymtx), 0.5-2.2 % high
    /// against it (`radiance-fixtures/calib/README.md`).
    pub sky: StepSkyModel,
    /// Where traced runs report (quiet by default; the tool draws bars).
    pub progress: Reporter,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            settings: Settings::model(),
            cache: None,
            classes: Vec::new(),
            reflectance: false,
            sky: StepSkyModel::Gendaylit,
            progress: Reporter::quiet(),
        }
    }
}

/// Build a model from in-memory inputs. `readings` hold weather step indices.
pub fn build(
    scene: &Scene,
    sensors: Vec<Sensor>,
    weather: &Weather,
    readings: &[Bound],
    opts: &Options,
) -> Result<Model> {
    if sensors.is_empty() {
        return Err(Error::Usage("no sensors".into()));
    }
    let mut idx: Vec<usize> = readings.iter().map(|b| b.step).collect();
    idx.sort_unstable();
    idx.dedup();
    let obs: Vec<Bound> = readings
        .iter()
        .map(|b| Bound {
            step: idx.binary_search(&b.step).unwrap_or(0),
            ..*b
        })
        .collect();
    let simulator = Simulator::new(
        opts.settings.clone(),
        opts.cache.clone(),
        &sensors,
        subset_wea(weather, &idx),
    )?
    .with_progress(opts.progress.clone());
    let mf = opts.settings.mf;
    let skies = match opts.sky {
        StepSkyModel::Gendaylit => step_skies_seen(weather, &idx, mf, &simulator.seen_sky(scene)?),
        StepSkyModel::Gendaymtx => step_skies_with(weather, &idx, mf, StepSkyModel::Gendaymtx),
    };
    let dcs = simulator.dcs(scene)?;
    let room = Room::new(scene, sensor_centroid(&sensors), &opts.classes);
    Model::build(
        &simulator,
        scene,
        room,
        sensors,
        skies,
        &dcs,
        obs,
        opts.reflectance,
    )
}

/// Everything read from files.
pub struct Loaded {
    pub scene: Scene,
    pub sensors: Vec<Sensor>,
    pub weather: Weather,
    pub readings: Vec<Bound>,
}

/// Read the inputs (scene files, sensors, weather, measurements with their `--columns`)
/// and bind the readings.
pub fn load(
    scene_files: &[String],
    sensors: &str,
    weather: &str,
    measured: &str,
    columns: &Columns,
) -> Result<Loaded> {
    let scene = scene::load(scene_files, &LoadOptions::from_env())?;
    let sensors = load_sensors(sensors)?;
    let w = Weather::read_path(weather)?;
    let m = Measurements::read_path_with(measured, columns)?;
    let ids: Vec<String> = sensors.iter().map(|s| s.id.clone()).collect();
    let steps: Vec<(u32, u32, f64)> = w
        .steps
        .iter()
        .map(|s| (u32::from(s.month), u32::from(s.day), s.hour))
        .collect();
    let readings = m.bind(&ids, &steps, weather)?;
    Ok(Loaded {
        scene,
        sensors,
        weather: w,
        readings,
    })
}
