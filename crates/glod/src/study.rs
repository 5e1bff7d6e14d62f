//! # The chapter-2 experiment for the user's room: TAI error and trace time per level
//!
//! The seed (section 2.3, Table 2.4, Fig. 2.8) simulated each GLoD of six rooms with the
//! two-phase method and compared Total Annual Illumination (TAI, Eq. 2.2) per sensor with
//! GLoD4 by Percentage Error, MAPE and RMSE (Appendix A, Eq. A.1-A.3). Here each level's
//! scene ([`crate::filter`]) is traced once with the typed tracer API (sky coefficients over
//! the Reinhart MF patches, `rdaylight_trace::rdc::Tracer`), with the same seed for every
//! level, and multiplied by a gendaymtx sky matrix of the user's weather.
//!
//! TAI is linear in the coefficients, so the year collapses before the product:
//! `TAI_s = (h/1000) sum_t occ_t 179 w . (C_s s_t) = (h/1000) sum_p 179 w . (C_sp o S_p)` with
//! `S_p = sum_{t occupied} s_pt` (per channel) and `w` the rounded photopic weights of
//! `rmtx -c 47.4 119.9 11.6`, which the main job uses: the same numbers as `rmtx` +
//! `rmetrics` up to summation order.

use crate::filter::filter;
use crate::objects::Analysis;
use rdaylight_base::progress::{Progress, Stage};
use rdaylight_base::radiometry::luminance_rounded;
use rdaylight_base::{Error, Result};
use rdaylight_formats::scene::Scene;
use rdaylight_formats::sensors::SensorRay;
use rdaylight_formats::weather::Weather;
use rdaylight_metrics::compare::{percentage_error, rmse};
use rdaylight_metrics::schedule::{Schedule, stamps_from_weather};
use rdaylight_physics::sky::SkyPatches;
use rdaylight_physics::sky::matrix::{Colours, MatrixOptions, sky_matrix, time_steps};
use rdaylight_physics::sky::perez::PerezOptions;
use rdaylight_trace::rdc::{Config, Sampling, Tracer};

/// What the study traces and how it counts occupancy.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyConfig {
    /// Sampling of every level's trace (same seed for all levels).
    pub sampling: Sampling,
    /// Reinhart subdivision of the sky (1 = Tregenza, 146 columns).
    pub mf: usize,
    pub seed: u64,
    /// Occupied `start <= hour < end`, every day (rmetrics' default 8-18).
    pub occupied: (f64, f64),
    /// Worker threads (all cores when `None`).
    pub threads: Option<usize>,
}

impl Default for StudyConfig {
    /// The main job's settings: `-ab 5 -ad 10000 -lw 1e-5 -m 1`, occupied 8-18 h.
    fn default() -> Self {
        StudyConfig {
            sampling: Sampling::main_job(),
            mf: 1,
            seed: 1,
            occupied: (8.0, 18.0),
            threads: None,
        }
    }
}

/// One level's figures.
#[derive(Debug, Clone, PartialEq)]
pub struct LevelResult {
    pub level: u8,
    /// Non-permanent objects kept at this level.
    pub objects: usize,
    /// Primitives of the level's scene (materials included).
    pub primitives: usize,
    /// TAI per sensor (klx h).
    pub tai: Vec<f64>,
    /// Room TAI: the mean over sensors (Eq. 2.2).
    pub room_tai: f64,
    /// Eq. A.1 of the room TAI against GLoD4 (%).
    pub pe: f64,
    /// Mean absolute per-sensor percentage error against GLoD4 (%), over the sensors GLoD4
    /// gives light (a sensor inside furniture has no percentage error).
    pub mape: f64,
    /// Root mean squared per-sensor difference against GLoD4 (klx h; Eq. A.3's term).
    pub rmse: f64,
    /// Wall-clock seconds of the level's trace (compile included).
    pub trace_seconds: f64,
}

/// The per-level study of `scene` (analysed as `analysis`) for `sensors` under `weather`.
pub fn study(
    scene: &Scene,
    analysis: &Analysis,
    weather: &Weather,
    sensors: &[SensorRay],
    cfg: &StudyConfig,
    progress: &dyn Progress,
) -> Result<Vec<LevelResult>> {
    if sensors.is_empty() {
        return Err(Error::Usage(
            "no sensors: give at least one sensor ray".into(),
        ));
    }
    let sky = OccupiedSky::new(weather, cfg.mf, cfg.occupied)?;
    let mut out: Vec<LevelResult> = Vec::new();
    for level in 0..=crate::MAX_LEVEL {
        let stage = Stage::new(
            progress,
            &format!("tracing GLoD{level}"),
            Some(sensors.len() as u64),
            "sensors",
        );
        let sub = filter(scene, analysis, level)?;
        let t0 = std::time::Instant::now();
        let tai = sky.traced_tai(&sub, sensors, cfg, stage.progress())?;
        drop(stage);
        let trace_seconds = t0.elapsed().as_secs_f64();
        let room_tai = tai.iter().sum::<f64>() / tai.len() as f64;
        out.push(LevelResult {
            level,
            objects: analysis.objects.iter().filter(|o| o.level <= level).count(),
            primitives: sub.objects.len(),
            tai,
            room_tai,
            pe: f64::NAN,
            mape: f64::NAN,
            rmse: f64::NAN,
            trace_seconds,
        });
    }
    let reference = out.last().map(|r| (r.tai.clone(), r.room_tai));
    if let Some((tai4, room4)) = reference {
        for r in &mut out {
            r.pe = percentage_error(r.room_tai, room4);
            // Sensors that GLoD4 leaves in the dark (inside or under furniture) have no
            // percentage error; they count in the RMSE only.
            let pes: Vec<f64> = r
                .tai
                .iter()
                .zip(&tai4)
                .filter(|&(_, &b)| b > 0.0)
                .map(|(&a, &b)| percentage_error(a, b).abs())
                .collect();
            r.mape = pes.iter().sum::<f64>() / pes.len() as f64;
            r.rmse = rmse(&r.tai, &tai4);
        }
    }
    Ok(out)
}

/// The occupied part of a year's sky matrix (gendaymtx's defaults: sun in the patches,
/// gendaymtx colours) for everything that multiplies coefficients by it: the per-hour
/// values (hour-based metrics) and their sums over the occupied hours (TAI).
#[derive(Debug, Clone)]
pub struct OccupiedSky {
    /// Sky columns (patches, ground first).
    pub npatches: usize,
    /// Occupied weather steps, in file order.
    pub hours: usize,
    /// `values[(p * 3 + c) * hours + h]`: patch `p`, channel `c`, occupied step `h`
    /// (W sr-1 m-2), f32 as in a Radiance matrix file.
    pub values: Vec<f32>,
    /// `S_p` per channel: the occupied columns summed, `[p * 3 + c]`.
    pub sums: Vec<f64>,
    /// Length of one step (h).
    pub step_hours: f64,
}

impl OccupiedSky {
    /// The sky of `weather` over Reinhart `mf` patches, occupied `start <= hour < end`.
    pub fn new(weather: &Weather, mf: usize, occupied: (f64, f64)) -> Result<OccupiedSky> {
        let (start, end) = occupied;
        let stamps = stamps_from_weather(weather);
        let schedule = Schedule::from_range(&stamps, start, end, None);
        if schedule.count() == 0 {
            return Err(Error::Usage(format!(
                "occupied {start}-{end} h: no weather step falls in it"
            )));
        }
        let patches = SkyPatches::new(mf);
        let opts = MatrixOptions {
            perez: PerezOptions::default(),
            colours: Colours::gendaymtx(),
            skip_night: false,
        };
        let m = sky_matrix(
            &patches,
            &time_steps(weather),
            &weather.site,
            &opts,
            &|_, _| {},
        );
        let hours = schedule.count();
        let np = m.nrows();
        let mut values = vec![0f32; np * 3 * hours];
        let mut sums = vec![0.0; np * 3];
        let mut row = Vec::new();
        for p in 0..np {
            m.row(p, &mut row);
            let mut h = 0;
            for (k, &col) in m.columns().iter().enumerate() {
                if schedule.occupied.get(col).copied().unwrap_or(false) {
                    for c in 0..3 {
                        let v = row[k * 3 + c];
                        sums[p * 3 + c] += v;
                        values[(p * 3 + c) * hours + h] = v as f32;
                    }
                    h += 1;
                }
            }
        }
        Ok(OccupiedSky {
            npatches: np,
            hours,
            values,
            sums,
            step_hours: schedule.step_hours,
        })
    }

    /// TAI (klx h) per sensor of `scene`, traced for sky coefficients (irradiance) with
    /// `cfg`'s sampling, seed and threads: one level of the study, or one re-simulation.
    /// Each traced sensor advances `progress` by one.
    pub fn traced_tai(
        &self,
        scene: &Scene,
        sensors: &[SensorRay],
        cfg: &StudyConfig,
        progress: &dyn Progress,
    ) -> Result<Vec<f64>> {
        let config = Config {
            seed: cfg.seed,
            threads: cfg.threads,
            ..Config::sky_coefficients(cfg.mf, cfg.sampling)
        };
        let rows = Tracer::new(&config, scene)?.compute_reporting(sensors, progress)?;
        Ok(rows.iter().map(|r| self.tai_of_row(&r.values)).collect())
    }

    /// TAI (klx h) of one sensor's coefficient row (`npatches * 3`), seed Eq. 4.1 / 1000.
    pub fn tai_of_row(&self, dc: &[f64]) -> f64 {
        tai_of_row(dc, &self.sums, self.step_hours)
    }
}

/// TAI (klx h) of one sensor's coefficient row (`ncols * 3`) against the occupied sky sums.
fn tai_of_row(dc: &[f64], sky: &[f64], step_hours: f64) -> f64 {
    let lux_hours: f64 = dc
        .chunks_exact(3)
        .zip(sky.chunks_exact(3))
        .map(|(d, s)| luminance_rounded([d[0] * s[0], d[1] * s[1], d[2] * s[2]]))
        .sum();
    lux_hours * step_hours / 1000.0
}

/// The study as the seed's Table 2.4 lays it out (TSV).
pub fn table(results: &[LevelResult]) -> String {
    let mut s = String::from(
        "level\tobjects\tprimitives\troom_TAI_klxh\tPE_%\tMAPE_%\tRMSE_klxh\ttrace_s\n",
    );
    for r in results {
        s += &format!(
            "GLoD{}\t{}\t{}\t{:.3}\t{:+.2}\t{:.2}\t{:.3}\t{:.2}\n",
            r.level, r.objects, r.primitives, r.room_tai, r.pe, r.mape, r.rmse, r.trace_seconds
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tai_of_a_row_is_the_luminance_of_the_weighted_sky() {
        // Two patches, one sensor: 0.5 of patch 0 and 0.25 of patch 1 (grey), skies of
        // 100 and 200 W/sr/m2 summed over occupied hours: 179 (0.5 100 + 0.25 200) lx h.
        let dc = [0.5, 0.5, 0.5, 0.25, 0.25, 0.25];
        let sky = [100.0, 100.0, 100.0, 200.0, 200.0, 200.0];
        let want = 179.0 * (0.265 + 0.670 + 0.065) * 100.0 / 1000.0;
        assert!((tai_of_row(&dc, &sky, 1.0) - want).abs() < 1e-9);
        assert!((tai_of_row(&dc, &sky, 0.5) - want / 2.0).abs() < 1e-9);
    }
}
