//! # Re-weighting against brute-force re-simulation
//!
//! For `draws` draws of every sigma class, the TAI per sensor from the re-weighted paths of
//! one trace ([`LevelModel::tai`]) is compared with a fresh trace of the scene rebuilt with
//! the drawn materials (colours scaled; a glass pane rebuilt from its drawn normal
//! transmittance by Radiance's law, [`transmissivity_for_index`]), each re-simulation with
//! its own seed. The two differ by the Monte Carlo noise of both runs, plus, for glass, the
//! angle binning of re-weighting (`rdaylight_trace::trace::reweight::GLASS_BINS`: 0.03 %
//! of diffuse transmittance for a pane redrawn from 88 % to 50 %).
//!
//! **The noise** is measured, not assumed: `noise_runs` traces of the error-free scene with
//! different seeds give each sensor's TAI standard deviation `sd_i` and the room's
//! `sd_room`, taken as relative to the value and scaled to each draw. Two independent runs
//! differ with standard deviation `sqrt 2 sd`, so **the criterion** is
//! (1) every draw's room TAI: `|rw - rs| <= 3 sqrt 2 sd_room`;
//! (2) per sensor: the root mean square of `z = (rw - rs) / (sqrt 2 sd_i)` over all sensors
//!     and draws, divided by its expectation `sqrt(nu / (nu - 2))` when `sd_i` comes from
//!     `nu = noise_runs - 1` degrees of freedom (z is then Student-t distributed), is at
//!     most 1.25 (1 if the noise model is exact; the margin: re-weighted estimates of a
//!     much brighter or darker draw carry a little more noise than a fresh trace, being
//!     importance sampling with the traced model's density);
//! (3) the spread the study reports: the standard deviation of room TAI across draws from
//!     re-weighting is within 10 % of the re-simulated one.

use crate::classes::{self, Kind, Mcop};
use crate::engine::LevelModel;
use crate::stats::mean_sd;
use crate::study::StudyConfig;
use rdaylight_base::progress::{Progress, QUIET, Stage};
use rdaylight_base::{Error, Result};
use rdaylight_formats::scene::{Primitive, Scene};
use rdaylight_formats::sensors::SensorRay;
use rdaylight_formats::weather::Weather;
use rdaylight_glod::study::OccupiedSky;
use rdaylight_physics::material::glass::{
    transmissivity_for_index, transmittance_from_transmissivity,
};
use serde::Serialize;

/// Figures of one sigma class.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClassCheck {
    pub sigma: f64,
    pub draws: usize,
    /// Largest `|rw - rs| / (sqrt 2 sd_room)` over the draws (criterion 1: <= 3).
    pub max_room_z: f64,
    /// Largest room difference relative to the re-simulation (%).
    pub max_room_diff_pct: f64,
    /// Mean room difference (%): the bias of re-weighting (its own trace's noise included).
    pub mean_room_diff_pct: f64,
    /// RMS of the per-sensor z over its Student-t expectation (criterion 2: <= 1.25).
    pub rms_sensor_z: f64,
    /// Share of sensor z beyond 3 (normal: 0.27 %).
    pub share_beyond_3: f64,
    /// sd of room TAI across draws, re-weighted / re-simulated (criterion 3: 0.9-1.1).
    pub spread_ratio: f64,
    pub passed: bool,
}

/// The whole validation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Validation {
    /// Relative TAI noise of one re-simulation: room and median over sensors (%).
    pub room_noise_pct: f64,
    pub sensor_noise_pct: f64,
    pub noise_runs: usize,
    pub classes: Vec<ClassCheck>,
    /// Seconds: one re-simulation (mean) and one re-weighted draw (mean).
    pub resimulation_seconds: f64,
    pub reweight_seconds: f64,
}

/// `scene` with each named material's property replaced by its drawn value.
pub fn rebuilt(scene: &Scene, props: &[classes::Property], drawn: &[f64]) -> Scene {
    let mut out = scene.clone();
    for (p, &v) in props.iter().zip(drawn) {
        let s = p.scale(v);
        for o in out.objects.iter_mut().filter(|o| o.id == p.name) {
            match &mut o.kind {
                Primitive::Plastic { color, .. }
                | Primitive::Metal { color, .. }
                | Primitive::Trans { color, .. }
                | Primitive::Mirror { color, .. } => {
                    for c in color.iter_mut() {
                        *c *= s;
                    }
                }
                Primitive::Glass {
                    transmissivity,
                    index,
                } => {
                    let n = index.unwrap_or(rdaylight_physics::material::glass::DEFAULT_INDEX);
                    for t in transmissivity.iter_mut() {
                        let tn = transmittance_from_transmissivity(*t, n);
                        *t = transmissivity_for_index(s * tn, n);
                    }
                }
                _ => {}
            }
        }
    }
    out
}

/// The TAI of one trace of `scene` with another seed (a noise run or a re-simulation).
fn tai_of(
    scene: &Scene,
    sensors: &[SensorRay],
    cfg: &StudyConfig,
    seed: u64,
    sky: &OccupiedSky,
) -> Result<Vec<f64>> {
    let trace = rdaylight_glod::study::StudyConfig {
        seed,
        ..cfg.trace.clone()
    };
    // One unit of the caller's stage (a noise run, a re-simulation), not a stage of its own.
    sky.traced_tai(scene, sensors, &trace, &QUIET)
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Validate re-weighting on `scene` (see the module documentation).
pub fn validate(
    scene: &Scene,
    weather: &Weather,
    sensors: &[SensorRay],
    cfg: &StudyConfig,
    draws: usize,
    noise_runs: usize,
    progress: &dyn Progress,
) -> Result<Validation> {
    if !(4..=1000).contains(&noise_runs) {
        return Err(Error::Usage(format!(
            "--noise-runs {noise_runs}: give 4 to 1000 (the noise's degrees of freedom must exceed 2)"
        )));
    }
    let nu = (noise_runs - 1) as f64;
    let t_rms = (nu / (nu - 2.0)).sqrt();
    let sky = OccupiedSky::new(weather, cfg.trace.mf, cfg.trace.occupied)?;
    let stage = Stage::new(
        progress,
        "tracing with re-weighting records",
        Some(sensors.len() as u64),
        "sensors",
    );
    let model = LevelModel::trace(scene, sensors, cfg, &sky, stage.progress())?;
    drop(stage);
    let props = model
        .materials
        .iter()
        .map(|m| classes::property(scene, m))
        .collect::<Result<Vec<_>>>()?;
    // Seeds of the noise runs and re-simulations: far from the study's.
    let mut noise = Vec::new();
    let t0 = std::time::Instant::now();
    let stage = Stage::new(progress, "noise runs", Some(noise_runs as u64), "runs");
    for j in 0..noise_runs {
        noise.push(tai_of(
            scene,
            sensors,
            cfg,
            cfg.trace.seed + 1_000_000 + j as u64,
            &sky,
        )?);
        stage.advance(1);
    }
    drop(stage);
    let mut resim_time = t0.elapsed().as_secs_f64();
    let n = sensors.len();
    let sd_rel: Vec<f64> = (0..n)
        .map(|i| {
            let v: Vec<f64> = noise.iter().map(|r| r[i]).collect();
            let (m, sd) = mean_sd(&v);
            if m > 0.0 { sd / m } else { f64::NAN }
        })
        .collect();
    let rooms: Vec<f64> = noise.iter().map(|r| mean(r)).collect();
    let (room_mean, room_sd) = mean_sd(&rooms);
    let room_rel = room_sd / room_mean;
    let mut resims = noise_runs;
    let mut rw_time = 0.0;
    let mut rw_count = 0usize;
    let mut out = Vec::new();
    let stage = Stage::new(
        progress,
        "re-simulations",
        Some((cfg.sigmas.len() * draws) as u64),
        "draws",
    );
    for (k, &sigma) in cfg.sigmas.iter().enumerate() {
        let mcop = Mcop {
            sigma,
            truncation: cfg.truncation,
            grouping: cfg.grouping,
        };
        let (mut room_z, mut room_diff, mut zs) = (Vec::new(), Vec::new(), Vec::new());
        let (mut rw_rooms, mut rs_rooms) = (Vec::new(), Vec::new());
        for d in 0..draws {
            let drawn = mcop.draw(&props, cfg.trace.seed, k, d);
            let scales: Vec<f64> = props.iter().zip(&drawn).map(|(p, &v)| p.scale(v)).collect();
            let t1 = std::time::Instant::now();
            let rw = model.tai(&scales);
            rw_time += t1.elapsed().as_secs_f64();
            rw_count += 1;
            let t2 = std::time::Instant::now();
            let seed = cfg.trace.seed + 2_000_000 + (k * draws + d) as u64;
            let rs = tai_of(&rebuilt(scene, &props, &drawn), sensors, cfg, seed, &sky)?;
            resim_time += t2.elapsed().as_secs_f64();
            resims += 1;
            stage.advance(1);
            let (a, b) = (mean(&rw), mean(&rs));
            rw_rooms.push(a);
            rs_rooms.push(b);
            room_z.push((a - b) / (std::f64::consts::SQRT_2 * room_rel * b));
            room_diff.push(100.0 * (a - b) / b);
            for i in 0..n {
                if sd_rel[i] > 0.0 && rs[i] > 0.0 {
                    zs.push((rw[i] - rs[i]) / (std::f64::consts::SQRT_2 * sd_rel[i] * rs[i]));
                }
            }
        }
        let max_room_z = room_z.iter().fold(0.0f64, |m, z| m.max(z.abs()));
        let rms = (zs.iter().map(|z| z * z).sum::<f64>() / zs.len().max(1) as f64).sqrt() / t_rms;
        let spread_ratio = mean_sd(&rw_rooms).1 / mean_sd(&rs_rooms).1;
        out.push(ClassCheck {
            sigma,
            draws,
            max_room_z,
            max_room_diff_pct: room_diff.iter().fold(0.0f64, |m, z| m.max(z.abs())),
            mean_room_diff_pct: mean(&room_diff),
            rms_sensor_z: rms,
            share_beyond_3: zs.iter().filter(|z| z.abs() > 3.0).count() as f64
                / zs.len().max(1) as f64,
            spread_ratio,
            passed: max_room_z <= 3.0 && rms <= 1.25 && (0.9..=1.1).contains(&spread_ratio),
        });
    }
    let mut sorted = sd_rel
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .collect::<Vec<_>>();
    sorted.sort_by(f64::total_cmp);
    Ok(Validation {
        room_noise_pct: 100.0 * room_rel,
        sensor_noise_pct: 100.0 * sorted.get(sorted.len() / 2).copied().unwrap_or(f64::NAN),
        noise_runs,
        classes: out,
        resimulation_seconds: resim_time / resims as f64,
        reweight_seconds: rw_time / rw_count.max(1) as f64,
    })
}

/// The validation as a table (TSV).
pub fn table(v: &Validation) -> String {
    let mut s = format!(
        "# noise of one re-simulation ({} seeds): room {:.3} %, median sensor {:.3} %; one re-simulation {:.3} s, one re-weighted draw {:.2e} s (ratio {:.0})\n",
        v.noise_runs,
        v.room_noise_pct,
        v.sensor_noise_pct,
        v.resimulation_seconds,
        v.reweight_seconds,
        v.resimulation_seconds / v.reweight_seconds.max(1e-12)
    );
    s += "sigma\tdraws\tmax_room_z\tmax_room_diff_%\tmean_room_diff_%\trms_sensor_z\tshare_|z|>3\tspread_ratio\tpassed\n";
    for c in &v.classes {
        s += &format!(
            "{:.2}\t{}\t{:.2}\t{:.3}\t{:+.3}\t{:.3}\t{:.4}\t{:.4}\t{}\n",
            c.sigma,
            c.draws,
            c.max_room_z,
            c.max_room_diff_pct,
            c.mean_room_diff_pct,
            c.rms_sensor_z,
            c.share_beyond_3,
            c.spread_ratio,
            if c.passed { "yes" } else { "no" }
        );
    }
    s
}

/// Whether any class uses glass, for the note on the angle law.
pub fn has_glass(props: &[classes::Property]) -> bool {
    props
        .iter()
        .any(|p| p.kind == Kind::Transmittance && p.index.is_some())
}
