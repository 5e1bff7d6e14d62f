//! # Simulating the measured time steps through daylight coefficients
//!
//! Illuminance at sensor `s` and time step `t` is computed the way Radiance's five-phase
//! method does (Subramaniam, *Daylighting simulations with Radiance using matrix-based
//! methods*, LBNL 2017, ch. 5; radiance-notes 6.6), with `rdc` standing in for rcontrib:
//!
//! ```text
//! E(s,t) = DC(s)·sky(t)  +  [Vsun(s,t) - Cds(s,t)] L_sun(t)  +  Cds(s,t) L_sun(t)
//! ```
//!
//! - `DC`: sky coefficients (`rdc -I -m MF`), all bounces; `DCd`: direct-only ones
//!   (`--direct`, used by the effects that block direct light); `Cds`: the sun of each
//!   measured step as a disc (`--suns steps.wea`, direct only, deterministic).
//! - `Vsun`: the light of unit-radiance sun discs at the steps' positions with all bounces
//!   (`rdc --suns steps.wea --suns-ab`: every surface a sensor's path meets looks at every
//!   step's sun), the five-phase method's sun coefficients with inter-reflection. Spreading
//!   the sun over sky patches and subtracting direct-only from total coefficients instead
//!   (the DDS shortcut) leaves the Monte Carlo noise of a few samples per patch in the sun
//!   term: tens of percent.
//! - `sky(t)`: the gendaymtx Perez sky without the sun (ground patch with reflectance 0.2);
//!   `L_sun`: the radiance of a 0.533 degree disc (gendaymtx -5).
//! - RGB irradiance to lux: 179 x (0.265 R + 0.670 G + 0.065 B) (`rmtxop -c 47.4 119.9 11.6`).
//!
//! The per-patch terms are kept apart ([`Components`]) because the effects of
//! [`super::effects`] act on them: an exterior obstruction blocks sky patches and suns, an
//! overhang blocks the direct part per sensor, a reflectance change alters `DC` and `Vsun`.
//! Sampling ([`Settings::model`]): each sensor is sampled until its row (the sensor under a
//! uniform sky; all suns together) is known to 1 % (`rdc --target-se 0.01 --se-row`), so
//! the back of a deep room gets the samples it needs and the window sensors do not waste
//! them; bounces end by Russian roulette rather than at a small `-ab`. Against converged
//! runs the model's values are within 1-2 % RMS (10 m deep room), below the 3-4 % of
//! real sensors. Reflectance variants of both the sky coefficients and `Vsun` come from one
//! re-weighted run each, whose records make them exact polynomials in the classes'
//! reflectances ([`Simulator::dc_records`], [`Simulator::sun_records`]).
//!
//! Coefficients are cached on disk ([`super::cache`]): a re-run traces nothing.

use super::cache;
#[allow(unused_imports)] // named in the documentation
use super::room::scaled_scene;
use super::room::{Room, SurfaceClass};
use crate::error::{Error, Result};
use crate::formats::sensors::Sensor;
use crate::formats::weather::Weather;
use crate::progress::{Reporter, Stage};
use crate::radiometry::Channels;
use crate::radiometry::{RGB_PHOTOPIC_ROUNDED, WHITE_EFFICACY};
use crate::rdc::config::SUN_ANGLE_DEG;
use crate::rdc::{Adaptive, Config, RecordResult, Reweight, Sampling, SunSource, Target};
use crate::scene::Scene;
use crate::scene::{LoadOptions, Primitive};
use crate::sky::gendaylit::{GendaylitInput, GendaylitOptions, GendaylitSky};
use crate::sky::matrix::time_steps;
use crate::sky::perez::{
    GENDAYMTX_GROUND_REFLECTANCE, GENDAYMTX_SKY_COLOUR, InputUnits, PerezOptions, TimeStep,
    perez_sky_vector,
};
use crate::sky::solar::sunrise_sunset;
use crate::sky::{SkyPatches, solar::SunPosition};
use crate::trace::reweight::Reweighting;
use std::path::{Path, PathBuf};

/// Lux per unit RGB irradiance (W/m2 per channel).
pub const LUX_RGB: [f64; 3] = [
    WHITE_EFFICACY * RGB_PHOTOPIC_ROUNDED[0],
    WHITE_EFFICACY * RGB_PHOTOPIC_ROUNDED[1],
    WHITE_EFFICACY * RGB_PHOTOPIC_ROUNDED[2],
];

/// Sampling settings of the coefficient runs (Radiance's letters; `target_se` and
/// `max_samples` are rdc's `--target-se --se-row` and `--max-samples`).
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    pub ab: u32,
    pub ad: usize,
    pub lw: f64,
    /// Reinhart subdivision of the sky patches (1 = Tregenza, 146 columns).
    pub mf: usize,
    pub seed: u64,
    /// Relative standard error each sensor's row is sampled to (batches of `ad`): the
    /// sensor under a uniform sky for sky coefficients, its value for `Vsun`.
    pub target_se: Option<f64>,
    /// Cap on samples per sensor with `target_se`.
    pub max_samples: usize,
}

impl Settings {
    /// The model under calibration: `-ab 10 -ad 1024 -lw 5e-5`, each sensor sampled until
    /// its relative standard error is 1 % (at most 64 batches).
    ///
    /// Why these: the calibration can be no better than the simulation, and the readings
    /// carry ~3.6 % sensor noise, so the simulation's own error must stay well below that
    /// at every sensor. A fixed `-ad` leaves the back of a deep room (which sees the
    /// window through a few percent of its hemisphere) at 10-20 % noise, and `-ab 5`
    /// leaves it 5-11 % low (measured in the 10 m deep test room against -ab 12 with
    /// 131072 samples); the per-sensor target spends the samples where they are needed,
    /// and `-lw` at 5 % of the starting weight 1/`-ad` ends paths by roulette (unbiased)
    /// instead of at a fixed bounce count. With `-lw` above 1/`-ad` (Radiance's meaning:
    /// ambient samples start at weight 1/`-ad`) every path is rouletted at its first
    /// bounce and more samples stop helping.
    pub fn model() -> Settings {
        Settings {
            ab: 10,
            ad: 1024,
            lw: 5e-5,
            mf: 1,
            seed: 1,
            target_se: Some(0.01),
            max_samples: 64 * 1024,
        }
    }
    /// Settings for synthetic "truth" measurements: converged (0.5 % per sensor, more
    /// bounces, another seed), so that the readings' error is the sensor noise alone.
    /// Against 0.3 % and `-ab 14` the deep test room's values differ by 0.2 % RMS.
    pub fn truth() -> Settings {
        Settings {
            ab: 12,
            ad: 1024,
            lw: 2e-5,
            mf: 1,
            seed: 7,
            target_se: Some(0.005),
            max_samples: 256 * 1024,
        }
    }
    /// The tracer's configuration for these settings (sensors measure irradiance).
    fn config(&self, target: Target, channels: Channels, reweight: Option<Reweight>) -> Config {
        Config {
            sampling: Sampling {
                ab: self.ab,
                ad: self.ad,
                lw: self.lw,
                ..Sampling::default()
            },
            channels,
            target,
            irradiance: true,
            adaptive: self.target_se.map(|target_se| Adaptive {
                target_se,
                per_row: true,
                max_samples: Some(self.max_samples),
            }),
            seed: self.seed,
            reweight,
            ..Config::default()
        }
    }
}

/// The sky of one measured time step.
#[derive(Debug, Clone, PartialEq)]
pub struct StepSky {
    pub month: u32,
    pub day: u32,
    pub hour: f64,
    /// Sky and ground radiance per patch, `npatch * 3` (no sun).
    pub sky: Vec<f64>,
    /// Radiance of the sun disc (gendaymtx -5 0.533), 0 when down.
    pub sun_radiance: f64,
    pub sun_altitude_deg: f64,
    /// Degrees east of north.
    pub sun_azimuth_deg: f64,
    /// Unit vector to the sun.
    pub sun_dir: [f64; 3],
    /// Perez sky clearness epsilon (1 overcast .. 11.9 clear; 0 at night).
    pub clearness: f64,
    pub dni: f64,
    pub dhi: f64,
}

/// Which Radiance program's Perez sky a measured step gets. The two apply the same
/// published models (Perez 1990 efficacy, Perez 1993 luminance) but build the sky
/// differently, by up to several percent of a room's illuminance (measured:
/// `radiance-fixtures/calib/README.md`, issue 22). rcalib uses gendaymtx's (the default),
/// which its own synthetic readings (`rcalib synth`) are made with; against readings of
/// gendaylit skies (`gendaylit | rtrace -I` truths) use gendaylit's as the scene sees it,
/// [`step_skies_seen`] (per step within 0.3 % of real Radiance,
/// `crates/calib/tests/forward.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StepSkyModel {
    /// gendaylit `-W dni dhi` (or `-G`/`-L` by the weather file's units), as a point-in-time
    /// reference run (`gendaylit ... | oconv | rtrace -I`) sees it: `perezlum.cal` averaged
    /// over each bin, which includes its horizon blend into the ground and its ground
    /// brightness A2 (gensky's intermediate-sky normalisation for any clearness above 1,
    /// i.e. for the faintest sun), the sun disc of gendaylit's radiance, white sky.
    Gendaylit,
    /// gendaymtx's column (`gendaymtx -m MF`, sun `-5 0.533`): the Perez sky at each patch
    /// centre normalised over the patches, ground `rho (E_dif + E_dir sin alt) / pi`,
    /// gendaymtx's sky colour. Annual pipelines (`rspecsky`, `dctimestep`) use this.
    #[default]
    Gendaymtx,
}

/// Skies of the weather steps `idx` at Reinhart subdivision `mf` ([`StepSkyModel`]'s
/// default, gendaymtx's).
pub fn step_skies(w: &Weather, idx: &[usize], mf: usize) -> Vec<StepSky> {
    step_skies_with(w, idx, mf, StepSkyModel::default())
}

/// Directions per bin side when averaging gendaylit's sky over a bin (64 per bin): the
/// horizon row's mean changes by less than 1e-3 relative from 8 x 8 to 32 x 32.
const BIN_SAMPLES: usize = 8;
/// Directions per side for the ground bin (the whole lower hemisphere, uniform in solid
/// angle: its brightness changes only in the horizon blend, within 10 deg below).
const GROUND_SAMPLES: usize = 32;

/// Skies of the weather steps `idx` with the chosen program's sky. A step for which
/// gendaylit writes its "error sky" (sun below the horizon for the date, Perez b > 0) gets
/// gendaymtx's sky instead: gendaylit's is black, which no reading can be compared with.
pub fn step_skies_with(w: &Weather, idx: &[usize], mf: usize, model: StepSkyModel) -> Vec<StepSky> {
    build_step_skies(w, idx, mf, model, None)
}

/// gendaylit's skies ([`StepSkyModel::Gendaylit`]) with each bin averaged over the
/// directions the scene's paths take into it ([`SeenSky`]) rather than uniformly: the
/// sky that reproduces a point-in-time `gendaylit | rtrace -I` run of the scene.
pub fn step_skies_seen(w: &Weather, idx: &[usize], mf: usize, seen: &SeenSky) -> Vec<StepSky> {
    build_step_skies(w, idx, mf, StepSkyModel::Gendaylit, Some(seen))
}

fn build_step_skies(
    w: &Weather,
    idx: &[usize],
    mf: usize,
    model: StepSkyModel,
    seen: Option<&SeenSky>,
) -> Vec<StepSky> {
    let patches = SkyPatches::new(mf);
    let steps = time_steps(w);
    let site = &w.site;
    let smear = PerezOptions::default();
    let disc = PerezOptions {
        five_phase_sun_deg: Some(0.533),
        ..PerezOptions::default()
    };
    let zero = [0.0; 3];
    idx.iter()
        .filter_map(|&i| steps.get(i))
        .map(|st| {
            let pos = SunPosition::at(site, st.jd, st.hour);
            let mut sky = StepSky {
                month: st.month,
                day: st.day,
                hour: st.hour,
                sky: Vec::new(),
                sun_radiance: 0.0,
                sun_altitude_deg: pos.altitude.to_degrees(),
                sun_azimuth_deg: pos
                    .azimuth_east_of_north(0.0)
                    .to_degrees()
                    .rem_euclid(360.0),
                sun_dir: pos.direction(),
                clearness: 0.0,
                dni: st.direct,
                dhi: st.diffuse,
            };
            if let Some(g) = (model == StepSkyModel::Gendaylit)
                .then(|| gendaylit_step(site, st))
                .flatten()
            {
                let uniform = |i: usize| {
                    let n = if i == 0 { GROUND_SAMPLES } else { BIN_SAMPLES };
                    g.bin_radiance(&patches, i, n)
                };
                let bins = match seen {
                    Some(seen) => seen.bin_radiances(&patches, |d| g.radiance(d), uniform),
                    None => (0..patches.len()).map(uniform).collect(),
                };
                sky.sky = bins.into_iter().flat_map(|x| [x, x, x]).collect();
                sky.sun_radiance = g.solar.unwrap_or(0.0);
                sky.clearness = g.epsilon;
                return sky;
            }
            let v = perez_sky_vector(&patches, st, site, &smear);
            let v5 = perez_sky_vector(&patches, st, site, &disc);
            sky.sky = v.to_channels(&GENDAYMTX_SKY_COLOUR, &GENDAYMTX_GROUND_REFLECTANCE, &zero);
            sky.sun_radiance = v5.sun.first().map_or(0.0, |s| s.1);
            sky.clearness = v.state.map_or(0.0, |s| s.epsilon);
            sky
        })
        .collect()
}

/// gendaylit's sky for a weather step: `gendaylit M D H -a -o -m -W|-G|-L dir dif` with
/// its defaults (ground reflectance 0.2, dew point 10.97 C), the position from the step's
/// own (leap-adjusted) day number. `None` where gendaylit writes its error sky: the sun
/// below the horizon or outside sunrise..sunset for the date, Perez b > 0.
fn gendaylit_step(site: &crate::formats::weather::Site, st: &TimeStep) -> Option<GendaylitSky> {
    let (direct, diffuse) = (st.direct, st.diffuse);
    let input = match st.units {
        InputUnits::DirectNormalIrradiance => {
            GendaylitInput::DirectNormalIrradiance { direct, diffuse }
        }
        InputUnits::DirectHorizontalIrradiance => {
            GendaylitInput::DirectHorizontalIrradiance { direct, diffuse }
        }
        InputUnits::DirectNormalIlluminance => {
            GendaylitInput::DirectNormalIlluminance { direct, diffuse }
        }
    };
    let opts = GendaylitOptions::new(input);
    let pos = SunPosition::at(site, st.jd, st.hour);
    let (rise, set) = sunrise_sunset(site, st.month, st.day);
    if pos.solar_time < rise || pos.solar_time > set || pos.altitude <= 0.0 {
        return None;
    }
    Some(GendaylitSky::new(
        pos.altitude,
        pos.azimuth,
        f64::from(st.jd),
        &opts,
    ))
    .filter(|g| !g.error)
}

/// Reinhart subdivision at which [`SeenSky`] resolves where paths escape: rows of 3.2 deg,
/// fine against `perezlum.cal`'s horizon blend, whose ground share falls from 45 % at the
/// horizon to 10 % at 6 deg (`(Dz + 1.01)^10` weights) and whose sky share below the
/// horizon is gone by -17 deg.
pub const SEEN_MF: usize = 4;
/// Directions per side when averaging a sky over one [`SEEN_MF`] patch.
const SEEN_SAMPLES: usize = 4;

/// Where a scene's sensor paths escape to the sky and ground, per [`SEEN_MF`] patch (columns
/// `0..n` above the horizon, `n..2n` below it as the mirror images of the patches): each
/// sensor's escapes as fractions of its own total, summed over the sensors.
///
/// Why: a daylight coefficient is the light of its bin per unit radiance of the bin, so
/// the radiance to give a bin is the mean over the directions the paths actually take into
/// it, not over its solid angle. That matters where the sky varies inside a bin: the one
/// ground bin under gendaylit (`perezlum.cal` blends sky into ground below the horizon: 1.5
/// to 2 x the ground brightness A2 just below it, A2 further down), and the lowest sky row
/// (45 % ground at the horizon, 10 % at 6 deg). A room with an exterior ground polygon
/// sends its downward paths past the polygon's edge only, 0 to -5 deg in the example
/// office, so the solid-angle mean of the lower hemisphere (mostly A2) made its sensors
/// 0.7-4.3 % low against `gendaylit | rtrace -I` (issue 22, `radiance-fixtures/calib`).
#[derive(Debug, Clone, PartialEq)]
pub struct SeenSky {
    pub weights: Vec<f64>,
}

impl SeenSky {
    /// From the values of a [`What::Seen`] run, `[s][p][c]` with `2 n` columns.
    pub fn from_run(values: &[f64], nsens: usize) -> SeenSky {
        let ncol = 2 * SkyPatches::new(SEEN_MF).len();
        let mut weights = vec![0.0; ncol];
        for s in 0..nsens {
            let row: Vec<f64> = (0..ncol)
                .map(|p| lux(&values[(s * ncol + p) * 3..][..3]))
                .collect();
            let total: f64 = row.iter().sum();
            if total > 0.0 {
                for (w, v) in weights.iter_mut().zip(&row) {
                    *w += v / total;
                }
            }
        }
        SeenSky { weights }
    }

    /// The radiance of every bin of `patches` under the sky `radiance(dir)`: the mean over
    /// the escape directions of [`SeenSky::weights`] that fall into the bin (each fine
    /// patch sampled evenly); `uniform(bin)` where no path escapes into a bin.
    pub fn bin_radiances(
        &self,
        patches: &SkyPatches,
        radiance: impl Fn([f64; 3]) -> f64,
        uniform: impl Fn(usize) -> f64,
    ) -> Vec<f64> {
        let fine = SkyPatches::new(SEEN_MF);
        let n = fine.len();
        let mut num = vec![0.0; patches.len()];
        let mut den = vec![0.0; patches.len()];
        let k = 1.0 / SEEN_SAMPLES as f64;
        for (p, &w) in self.weights.iter().enumerate() {
            // Column 0 (the ground of the upper half) and n (its mirror) stay empty.
            if w <= 0.0 || p % n == 0 {
                continue;
            }
            let ws = w * k * k;
            for a in 0..SEEN_SAMPLES {
                for b in 0..SEEN_SAMPLES {
                    let mut d = fine.sample(p % n, (a as f64 + 0.5) * k, (b as f64 + 0.5) * k);
                    if p >= n {
                        d[2] = -d[2];
                    }
                    let bin = patches.bin_of(d);
                    num[bin] += ws * radiance(d);
                    den[bin] += ws;
                }
            }
        }
        // A bin that only a sliver of the escapes reach keeps its solid-angle mean: its
        // coefficient is as small, and its seen mean as noisy.
        let total: f64 = den.iter().sum();
        (0..patches.len())
            .map(|i| {
                if den[i] > 1e-6 * total {
                    num[i] / den[i]
                } else {
                    uniform(i)
                }
            })
            .collect()
    }
}

/// A `.wea` holding only the steps `idx` of `w` (for `rdc --suns`).
pub fn subset_wea(w: &Weather, idx: &[usize]) -> String {
    let sub = Weather {
        site: w.site.clone(),
        units: w.units,
        steps: idx
            .iter()
            .filter_map(|&i| w.steps.get(i).cloned())
            .collect(),
        epw_text: None,
    };
    sub.to_wea(false)
}

/// Daylight coefficients of one scene for the sensors and measured steps.
#[derive(Debug, Clone, PartialEq)]
pub struct Dcs {
    pub nsens: usize,
    pub npatch: usize,
    pub nsteps: usize,
    /// `[s][p][c]` all bounces.
    pub total: Vec<f64>,
    /// `[s][p][c]` direct only.
    pub direct: Vec<f64>,
    /// `[s][t][c]` sun discs of the measured steps (direct).
    pub sun: Vec<f64>,
    /// `[s][t][c]` the same suns with all bounces.
    pub sun_total: Vec<f64>,
}

/// What one traced run computes for every sensor.
#[derive(Debug, Clone, PartialEq)]
pub struct Kind {
    pub what: What,
    /// RGB, or the bands of a spectral model.
    pub channels: Channels,
}

/// The coefficient sets rcalib traces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum What {
    /// Sky coefficients over the settings' Reinhart patches (`direct_only`: C_dcd).
    Sky { direct_only: bool },
    /// The measured steps' suns (`bounces`: with inter-reflection, `Vsun`).
    Suns { bounces: bool },
    /// Where the paths escape, at [`SEEN_MF`]: sky coefficients with the lower hemisphere
    /// resolved too (`Target::Sky { below_horizon }`), for [`SeenSky`].
    Seen,
}

impl Kind {
    /// RGB coefficients of `what`.
    pub fn rgb(what: What) -> Kind {
        Kind {
            what,
            channels: Channels::rgb(),
        }
    }

    /// The text that identifies the run in cache keys.
    fn key(&self, mf: usize) -> String {
        let mut k = match self.what {
            What::Sky { direct_only } => {
                format!("-m {mf}{}", if direct_only { " --direct" } else { "" })
            }
            What::Suns { bounces } => {
                format!("--suns SUNS{}", if bounces { " --suns-ab" } else { "" })
            }
            What::Seen => format!("-m {SEEN_MF} --below-horizon"),
        };
        if self.channels != Channels::rgb() {
            let c = &self.channels;
            k += &format!(" -cs {} -cw {} {}", c.ncomp, c.splits[3], c.splits[0]);
        }
        k
    }

    fn uses_suns(&self) -> bool {
        matches!(self.what, What::Suns { .. })
    }
}

/// Simulates the measured steps: runs the tracer (in memory, through [`crate::rdc::Tracer`])
/// with a disk cache. (Named apart from `rdc::Tracer`, which it drives.)
pub struct Simulator {
    pub settings: Settings,
    pub cache: Option<PathBuf>,
    sensors_text: String,
    rays: Vec<crate::formats::sensors::SensorRay>,
    /// `.wea` of the measured steps (part of the cache keys) and the same steps parsed once
    /// (the suns of every sun-coefficient run).
    suns_wea: String,
    suns: Weather,
    nsteps: usize,
    /// Where each traced run (a cache miss) reports, as a stage of its own.
    progress: Reporter,
}

impl Simulator {
    pub fn new(
        settings: Settings,
        cache: Option<PathBuf>,
        sensors: &[Sensor],
        suns_wea: String,
    ) -> Result<Simulator> {
        let suns = Weather::parse(&suns_wea, "steps.wea")?;
        let nsteps = suns.steps.len();
        let sensors_text: String = sensors
            .iter()
            .map(|s| format!("{:?} {:?}\n", s.ray.org, s.ray.dir))
            .collect();
        Ok(Simulator {
            settings,
            cache,
            sensors_text,
            rays: sensors.iter().map(|s| s.ray).collect(),
            suns_wea,
            suns,
            nsteps,
            progress: Reporter::quiet(),
        })
    }

    /// Report every traced run to `progress` (a stage per run, a unit per sensor).
    pub fn with_progress(mut self, progress: Reporter) -> Simulator {
        self.progress = progress;
        self
    }

    /// One cached traced run of `scene_text`: the flat values of every sensor row.
    pub fn run(&self, scene_text: &str, kind: &Kind) -> Result<Vec<f64>> {
        self.run_with(&self.settings, scene_text, kind)
    }

    /// [`Simulator::run`] with other sampling settings.
    fn run_with(&self, settings: &Settings, scene_text: &str, kind: &Kind) -> Result<Vec<f64>> {
        let settings_key = format!("{settings:?}");
        let kinds = kind.key(settings.mf);
        let suns = if kind.uses_suns() {
            self.suns_wea.as_str()
        } else {
            ""
        };
        let key = cache::key(&[
            scene_text.as_bytes(),
            self.sensors_text.as_bytes(),
            settings_key.as_bytes(),
            kinds.as_bytes(),
            suns.as_bytes(),
        ]);
        if let Some(c) = &self.cache {
            if let Some(v) = cache::load(c, key) {
                return Ok(v);
            }
        }
        let values: Vec<f64> = self
            .trace_with(settings, scene_text, kind, None, key)?
            .into_iter()
            .flat_map(|r| r.values)
            .collect();
        if let Some(c) = &self.cache {
            cache::store(c, key, &values);
        }
        Ok(values)
    }

    /// One traced run; `key` names the scene in error messages.
    fn trace(
        &self,
        scene_text: &str,
        kind: &Kind,
        reweight: Option<Reweight>,
        key: u64,
    ) -> Result<Vec<RecordResult>> {
        self.trace_with(&self.settings, scene_text, kind, reweight, key)
    }

    fn trace_with(
        &self,
        settings: &Settings,
        scene_text: &str,
        kind: &Kind,
        reweight: Option<Reweight>,
        key: u64,
    ) -> Result<Vec<RecordResult>> {
        let name = format!("scene-{key:016x}.rad");
        let scene =
            crate::scene::parse_str(scene_text, &name, Path::new(""), &LoadOptions::from_env())?;
        let target = match kind.what {
            What::Sky { direct_only } => Target::Sky {
                mf: settings.mf,
                direct_only,
                below_horizon: false,
            },
            What::Seen => Target::Sky {
                mf: SEEN_MF,
                direct_only: false,
                below_horizon: true,
            },
            What::Suns { bounces } => Target::Suns {
                suns: SunSource::Steps(self.suns.clone()),
                angle_deg: SUN_ANGLE_DEG,
                bounces,
            },
        };
        let config = settings.config(target, kind.channels, reweight);
        let mut what = match kind.what {
            What::Sky { direct_only: false } => "sky coefficients".to_string(),
            What::Sky { direct_only: true } => "direct sky coefficients".to_string(),
            What::Seen => "escape directions".to_string(),
            What::Suns { bounces: false } => "sun coefficients".to_string(),
            What::Suns { bounces: true } => "sun coefficients with inter-reflection".to_string(),
        };
        if kind.channels.ncomp != 3 {
            what += &format!(" ({} bands)", kind.channels.ncomp);
        }
        if config.reweight.is_some() {
            what += " with re-weighting records";
        }
        let p = self.progress.get();
        let stage = Stage::new(p, &what, Some(self.rays.len() as u64), "sensors");
        crate::rdc::Tracer::new(&config, &scene)?.compute_reporting(&self.rays, stage.progress())
    }

    /// All three coefficient sets of a scene.
    pub fn dcs(&self, scene: &Scene) -> Result<Dcs> {
        let text = scene.to_string();
        let total = self.run(&text, &Kind::rgb(What::Sky { direct_only: false }))?;
        let direct = self.run(&text, &Kind::rgb(What::Sky { direct_only: true }))?;
        let sun = self.run(&text, &Kind::rgb(What::Suns { bounces: false }))?;
        let sun_total = self.sun_total(&text)?;
        let nsens = self.rays.len();
        let npatch = SkyPatches::new(self.settings.mf).len();
        if total.len() != nsens * npatch * 3 || sun.len() != nsens * self.nsteps * 3 {
            return Err(Error::Mismatch(format!(
                "rdc returned {} sky and {} sun values for {nsens} sensors, {npatch} patches \
                 and {} steps",
                total.len(),
                sun.len(),
                self.nsteps
            )));
        }
        Ok(Dcs {
            nsens,
            npatch,
            nsteps: self.nsteps,
            total,
            direct,
            sun,
            sun_total,
        })
    }

    /// Where the sensors' paths escape in `scene` ([`SeenSky`]): one sky-coefficient run
    /// at [`SEEN_MF`] with the lower hemisphere resolved (cached like the others).
    pub fn seen_sky(&self, scene: &Scene) -> Result<SeenSky> {
        let v = self.run(&scene.to_string(), &Kind::rgb(What::Seen))?;
        let n = self.rays.len() * 2 * SkyPatches::new(SEEN_MF).len() * 3;
        if v.len() != n {
            return Err(Error::Mismatch(format!(
                "rdc returned {} values for the escape directions, expected {n}",
                v.len()
            )));
        }
        Ok(SeenSky::from_run(&v, self.rays.len()))
    }

    /// `Vsun` of a scene (see [`Simulator::sun_total`]), `[s][t][c]`.
    pub fn sun_total_of(&self, scene: &Scene) -> Result<Vec<f64>> {
        self.sun_total(&scene.to_string())
    }

    /// `Vsun`: the measured steps' suns as unit-radiance discs with every bounce
    /// (`rdc --suns steps.wea --suns-ab`: at each surface a path meets, next-event
    /// estimation towards every step's sun), `[s][t][c]`. One set of paths serves every
    /// step, so each sensor is sampled to the run's target once for all of them; the
    /// earlier per-step point-in-time runs (a `source` per step) cost three times as much
    /// for the same error and could not be re-weighted.
    fn sun_total(&self, text: &str) -> Result<Vec<f64>> {
        let v = self.run(text, &Kind::rgb(What::Suns { bounces: true }))?;
        let n = self.rays.len() * self.nsteps * 3;
        if v.len() != n {
            return Err(Error::Mismatch(format!(
                "rdc returned {} sun values, expected {n}",
                v.len()
            )));
        }
        Ok(v)
    }

    /// The path re-weighting records ([`crate::trace::reweight`]) of the sky coefficients
    /// (all bounces) of `scene`, every material of `classes` tracked: the coefficients as
    /// exact polynomials in those materials' reflectances, from ONE traced run (same seed
    /// and settings as the model's). Any combination of class scales is then evaluated
    /// from the same paths ([`ReflRecords::scaled`]): exact for diffuse reflection, and
    /// the differences between variants are free of the Monte Carlo noise that separate
    /// re-traces carry (their paths diverge at the first roulette decision). `None` when
    /// no material of `classes` can be tracked. Cached.
    pub fn dc_records(
        &self,
        scene: &Scene,
        room: &Room,
        classes: &[SurfaceClass],
    ) -> Result<Option<ReflRecords>> {
        let kind = Kind::rgb(What::Sky { direct_only: false });
        self.records(scene, room, classes, &kind)
    }

    /// `Vsun` ([`Simulator::sun_total`]) as re-weighting records, as
    /// [`Simulator::dc_records`] for the sky.
    pub fn sun_records(
        &self,
        scene: &Scene,
        room: &Room,
        classes: &[SurfaceClass],
    ) -> Result<Option<ReflRecords>> {
        self.records(
            scene,
            room,
            classes,
            &Kind::rgb(What::Suns { bounces: true }),
        )
    }

    /// One re-weighted run of kind `kind` and its records (cached as the records' file).
    fn records(
        &self,
        scene: &Scene,
        room: &Room,
        classes: &[SurfaceClass],
        kind: &Kind,
    ) -> Result<Option<ReflRecords>> {
        let text = scene.to_string();
        let kinds = kind.key(self.settings.mf);
        let suns = if kind.uses_suns() {
            self.suns_wea.as_str()
        } else {
            ""
        };
        // Every plastic/metal/trans of a class is tracked, with its class and colour (the
        // colour decides where a scaled reflectance is capped).
        let mut names: Vec<String> = Vec::new();
        let mut materials: Vec<(SurfaceClass, [f64; 3])> = Vec::new();
        for o in &scene.objects {
            let Some(&(_, class)) = room.materials.iter().find(|m| m.0 == o.id) else {
                continue;
            };
            if !classes.contains(&class) || names.contains(&o.id) {
                continue;
            }
            if let Primitive::Plastic { color, .. }
            | Primitive::Metal { color, .. }
            | Primitive::Trans { color, .. } = &o.kind
            {
                names.push(o.id.clone());
                let c = |i: usize| color.get(i).copied().unwrap_or(0.0);
                materials.push((class, [c(0), c(1), c(2)]));
            }
        }
        if names.is_empty() {
            return Ok(None);
        }
        let key = cache::key(&[
            text.as_bytes(),
            self.sensors_text.as_bytes(),
            format!("{:?} {kinds} records of {}", self.settings, names.join(",")).as_bytes(),
            suns.as_bytes(),
        ]);
        let name = format!("records-{key:016x}");
        if let Some(dir) = &self.cache
            && let Some(bytes) = cache::load_bytes(dir, key)
            && let Ok(rw) = Reweighting::parse(&bytes, &name)
            && rw.materials == names
        {
            return Ok(Some(ReflRecords::new(rw, materials)?));
        }
        let trace_key = cache::key(&[
            text.as_bytes(),
            names.join(",").as_bytes(),
            kinds.as_bytes(),
        ]);
        // The terms come back in memory with the rows (no file).
        let reweight = Reweight {
            path: None,
            materials: Some(names.clone()),
        };
        let rows = self.trace(&text, kind, Some(reweight), trace_key)?;
        let ncols = rows.first().map_or(0, |r| r.values.len() / 3);
        let mut rw = Reweighting::new(names, ncols, 3);
        for r in &rows {
            rw.push_row(&r.terms);
        }
        if let Some(dir) = &self.cache {
            let mut bytes = Vec::new();
            if rw.write(&mut bytes, &name).is_ok() {
                cache::store_bytes(dir, key, &bytes);
            }
        }
        Ok(Some(ReflRecords::new(rw, materials)?))
    }
}

/// Coefficients as polynomials in the reflectances of the room's surface classes (see
/// [`Simulator::dc_records`]): the records, each tracked material's class and colour, and
/// the coefficients of the scene as given (all factors 1).
#[derive(Debug, Clone)]
pub struct ReflRecords {
    pub rw: Reweighting,
    /// Per tracked material (in the records' order): class and RGB colour.
    pub materials: Vec<(SurfaceClass, [f64; 3])>,
    /// The coefficients with every factor 1, `nrows x ncols x 3`.
    pub unscaled: Vec<f64>,
}

impl ReflRecords {
    fn new(rw: Reweighting, materials: Vec<(SurfaceClass, [f64; 3])>) -> Result<ReflRecords> {
        let unscaled = rw.apply(&vec![1.0; rw.materials.len()])?;
        Ok(ReflRecords {
            rw,
            materials,
            unscaled,
        })
    }

    /// The coefficients with each class of `scales` (class, factor) scaled as
    /// [`scaled_scene`] writes it (every channel of every material of the class times the
    /// factor, capped at 0.95), minus the unscaled ones: what the change adds.
    pub fn scaled_difference(&self, scales: &[(SurfaceClass, f64)]) -> Result<Vec<f64>> {
        let factors: Vec<f64> = self
            .materials
            .iter()
            .flat_map(|(class, colour)| {
                let k = scales.iter().find(|x| x.0 == *class).map(|x| x.1);
                colour.map(|c| match k {
                    Some(k) if c > 0.0 => (c * k).clamp(0.0, 0.95) / c,
                    _ => 1.0,
                })
            })
            .collect();
        let v = self.rw.apply_channels(&factors)?;
        Ok(v.iter().zip(&self.unscaled).map(|(a, b)| a - b).collect())
    }
}

fn lux(v: &[f64]) -> f64 {
    v.iter().zip(LUX_RGB).map(|(a, b)| a * b).sum()
}

/// The light at every (sensor, step), split into what the effects act on; all in lux.
#[derive(Debug, Clone, PartialEq)]
pub struct Components {
    pub nsens: usize,
    pub nsteps: usize,
    pub npatch: usize,
    /// `[s][t][p]` sky patch p through all bounces.
    pub sky: Vec<f64>,
    /// `[s][t][p]` sky patch p seen directly.
    pub sky_direct: Vec<f64>,
    /// `[s][t]` inter-reflected sun.
    pub sun_indirect: Vec<f64>,
    /// `[s][t]` direct sun.
    pub sun_direct: Vec<f64>,
}

impl Components {
    /// Combine coefficients and skies.
    pub fn new(d: &Dcs, skies: &[StepSky]) -> Components {
        let (ns, nt, np) = (d.nsens, skies.len(), d.npatch);
        let mut c = Components {
            nsens: ns,
            nsteps: nt,
            npatch: np,
            sky: vec![0.0; ns * nt * np],
            sky_direct: vec![0.0; ns * nt * np],
            sun_indirect: vec![0.0; ns * nt],
            sun_direct: vec![0.0; ns * nt],
        };
        for s in 0..ns {
            for (t, sk) in skies.iter().enumerate() {
                let base = (s * nt + t) * np;
                for p in 0..np {
                    let dc = &d.total[(s * np + p) * 3..][..3];
                    let dd = &d.direct[(s * np + p) * 3..][..3];
                    let sky = &sk.sky[p * 3..][..3];
                    c.sky[base + p] = lux(&[dc[0] * sky[0], dc[1] * sky[1], dc[2] * sky[2]]);
                    c.sky_direct[base + p] = lux(&[dd[0] * sky[0], dd[1] * sky[1], dd[2] * sky[2]]);
                }
                let cs = lux(&d.sun[(s * nt + t) * 3..][..3]);
                let vs = lux(&d.sun_total[(s * nt + t) * 3..][..3]);
                c.sun_indirect[s * nt + t] = (vs - cs).max(0.0) * sk.sun_radiance;
                c.sun_direct[s * nt + t] = cs * sk.sun_radiance;
            }
        }
        c
    }

    /// Illuminance of every (sensor, step) with nothing changed.
    pub fn total(&self) -> Vec<f64> {
        let np = self.npatch;
        (0..self.nsens * self.nsteps)
            .map(|i| {
                self.sky[i * np..(i + 1) * np].iter().sum::<f64>()
                    + self.sun_indirect[i]
                    + self.sun_direct[i]
            })
            .collect()
    }
}
