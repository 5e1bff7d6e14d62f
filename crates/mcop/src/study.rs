//! # The chapter-3 experiment: GLoD x MCoP cells of material draws
//!
//! [`prepare`] traces each requested GLoD once ([`LevelModel`]) and finds its materials'
//! properties; [`draws`] evaluates the draws of every (level, sigma) cell, or of one shard's
//! block of draw indices; [`reduce`] turns the per-draw records into the cell and sensor
//! statistics. A sharded run keeps its records ([`ShardFile`]) and `rmcop merge` reduces
//! them once: the statistics are computed from every draw, never averaged from shards, and
//! the reduction sees the same records in the same order, so a merge gives the same bytes
//! as one run.

use crate::classes::{self, Grouping, Mcop, Property, Truncation};
use crate::engine::{LevelModel, WeightedSky};
use crate::stats::{KsFit, Normality, Summary, dagostino_pearson, ks_curve, ks_normal};
use rayon::prelude::*;
use rdaylight_base::progress::{Progress, Stage};
use rdaylight_base::{Error, Result};
use rdaylight_formats::scene::Scene;
use rdaylight_formats::sensors::SensorRay;
use rdaylight_formats::shard::{Manifest, Shard};
use rdaylight_formats::weather::Weather;
use rdaylight_glod::study::{OccupiedSky, StudyConfig as TraceConfig};
use rdaylight_glod::{Analysis, filter::filter};
use rdaylight_metrics::annual::{Thresholds, room_means, sensor_metrics};
use rdaylight_metrics::compare::percentage_error;
use serde::{Deserialize, Serialize};

/// Most draws per cell a user may ask for (the seed used 500): every draw's per-sensor
/// results are kept until the reduction, 100,000 draws x 20 cells x 165 sensors is 2.6 GB;
/// past that, shard the draws.
pub const MAX_DRAWS: usize = 100_000;

/// Everything a study needs besides its inputs.
#[derive(Debug, Clone, PartialEq)]
pub struct StudyConfig {
    /// How every level is traced and the year counted: rglod's study settings (sampling,
    /// Reinhart MF, seed, occupied hours, threads); the seed also seeds the draws.
    pub trace: TraceConfig,
    /// The MCoP sigmas (absolute reflectance/transmittance errors).
    pub sigmas: Vec<f64>,
    /// Draws per cell.
    pub draws: usize,
    /// GLoDs to study (0-4); the seed's benchmark is the highest.
    pub levels: Vec<u8>,
    pub truncation: Truncation,
    pub grouping: Grouping,
    /// `(class, glob)` rules naming surface classes by material name (`--class`).
    pub class_rules: Vec<(String, String)>,
    /// Materials that vary (all reflecting and transmitting ones when `None`).
    pub materials: Option<Vec<String>>,
    /// Also the hour-based metrics (UDI, DA, sDA, Eq. A.3 RMSE) per draw.
    pub hourly: bool,
    pub thresholds: Thresholds,
    /// This run's block of draw indices (`None`: all).
    pub shard: Option<Shard>,
}

impl Default for StudyConfig {
    /// The seed's experiment: sigma 0.05-0.20, 500 draws, GLoD0-4, per material, occupied
    /// 8-18 h, the main job's `-ab 5 -ad 10000 -lw 1e-5`.
    fn default() -> Self {
        StudyConfig {
            trace: TraceConfig::default(),
            sigmas: vec![0.05, 0.10, 0.15, 0.20],
            draws: 500,
            levels: vec![0, 1, 2, 3, 4],
            truncation: Truncation::Redraw,
            grouping: Grouping::Material,
            class_rules: Vec::new(),
            materials: None,
            hourly: false,
            thresholds: Thresholds::default(),
            shard: None,
        }
    }
}

impl StudyConfig {
    pub fn validate(&self) -> Result<()> {
        if self.draws == 0 || self.draws > MAX_DRAWS {
            return Err(Error::Usage(format!(
                "--draws {}: expected 1 to {MAX_DRAWS} draws per cell",
                self.draws
            )));
        }
        if self.sigmas.is_empty() {
            return Err(Error::Usage("--sigmas: give at least one sigma".into()));
        }
        if self.levels.is_empty() || self.levels.iter().any(|&l| l > rdaylight_glod::MAX_LEVEL) {
            return Err(Error::Usage(format!(
                "--levels {:?}: expected levels 0 to {}",
                self.levels,
                rdaylight_glod::MAX_LEVEL
            )));
        }
        if let Some(s) = self.shard {
            s.validate()?;
        }
        self.thresholds.check()
    }
}

/// One traced level and the error-free model's results.
#[derive(Debug, Clone)]
pub struct PreparedLevel {
    pub level: u8,
    pub model: LevelModel,
    /// The properties of `model.materials`, in that order.
    pub props: Vec<Property>,
    /// TAI per sensor of the error-free model (all scales 1).
    pub free_tai: Vec<f64>,
    /// Its hourly illuminance (with `hourly`).
    pub free_lux: Option<Vec<f32>>,
}

/// The traced levels and the year's occupied sky.
#[derive(Debug, Clone)]
pub struct Prepared {
    pub sky: OccupiedSky,
    pub weighted: Option<WeightedSky>,
    pub levels: Vec<PreparedLevel>,
    /// Sensor plan positions (x, y), for maps.
    pub positions: Vec<[f64; 2]>,
}

/// Trace every level of `cfg.levels` (the same seed for all) and the error-free model.
pub fn prepare(
    scene: &Scene,
    analysis: &Analysis,
    weather: &Weather,
    sensors: &[SensorRay],
    cfg: &StudyConfig,
    progress: &dyn Progress,
) -> Result<Prepared> {
    cfg.validate()?;
    if sensors.is_empty() {
        return Err(Error::Usage(
            "no sensors: give at least one sensor ray".into(),
        ));
    }
    if let Some(names) = &cfg.materials {
        for n in names {
            classes::property(scene, n).map_err(|e| Error::Usage(format!("--materials: {e}")))?;
        }
    }
    let sky = OccupiedSky::new(weather, cfg.trace.mf, cfg.trace.occupied)?;
    let weighted = cfg.hourly.then(|| WeightedSky::new(&sky));
    let mut levels = Vec::new();
    let mut wanted = cfg.levels.clone();
    wanted.sort_unstable();
    wanted.dedup();
    for &level in &wanted {
        let stage = Stage::new(
            progress,
            &format!("tracing GLoD{level}"),
            Some(sensors.len() as u64),
            "sensors",
        );
        let sub = filter(scene, analysis, level)?;
        let model = LevelModel::trace(&sub, sensors, cfg, &sky, stage.progress())?;
        drop(stage);
        let mut props = model
            .materials
            .iter()
            .map(|m| classes::property(&sub, m))
            .collect::<Result<Vec<_>>>()?;
        classes::assign_classes(&mut props, scene, analysis, &cfg.class_rules);
        let ones = vec![1.0; props.len()];
        let free_tai = model.tai(&ones);
        let free_lux = weighted.as_ref().map(|w| model.hourly(&ones, w).lux);
        levels.push(PreparedLevel {
            level,
            model,
            props,
            free_tai,
            free_lux,
        });
    }
    Ok(Prepared {
        sky,
        weighted,
        levels,
        positions: sensors.iter().map(|s| [s.org[0], s.org[1]]).collect(),
    })
}

/// Hour-based results of one draw.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DrawHourly {
    /// Per sensor UDI-a and DA (% of occupied hours).
    pub udi_a: Vec<f64>,
    pub da: Vec<f64>,
    /// Room means: UDI-n, UDI-s, UDI-a, UDI-e, DA, sDA (%).
    pub room: Vec<f64>,
    /// Seed Eq. A.3's inner term for this draw: RMS over sensors and occupied hours of the
    /// difference to the error-free model (lx).
    pub rmse_lux: f64,
}

/// One draw of one cell.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DrawRecord {
    pub level: u8,
    pub sigma_index: usize,
    pub draw: usize,
    /// TAI per sensor (klx h).
    pub tai: Vec<f64>,
    pub hourly: Option<DrawHourly>,
}

fn hourly_metrics(
    lux: &[f32],
    free: &[f32],
    hours: usize,
    step_hours: f64,
    t: &Thresholds,
) -> DrawHourly {
    let occupied = vec![true; hours];
    let mut row = vec![0.0; hours];
    let sensors: Vec<_> = lux
        .chunks_exact(hours.max(1))
        .map(|r| {
            for (o, &x) in row.iter_mut().zip(r) {
                *o = f64::from(x);
            }
            sensor_metrics(&row, None, &occupied, step_hours, t)
        })
        .collect();
    let room = room_means(&sensors)[1..7].to_vec();
    let ss: f64 = lux
        .iter()
        .zip(free)
        .map(|(&a, &b)| (f64::from(a) - f64::from(b)).powi(2))
        .sum();
    DrawHourly {
        udi_a: sensors.iter().map(|s| s.udi_a).collect(),
        da: sensors.iter().map(|s| s.da).collect(),
        room,
        rmse_lux: (ss / lux.len().max(1) as f64).sqrt(),
    }
}

/// The scale factors of draw `draw` of sigma class `k` for a level.
pub fn draw_scales(p: &PreparedLevel, cfg: &StudyConfig, k: usize, draw: usize) -> Vec<f64> {
    let mcop = Mcop {
        sigma: cfg.sigmas[k],
        truncation: cfg.truncation,
        grouping: cfg.grouping,
    };
    let values = mcop.draw(&p.props, cfg.trace.seed, k, draw);
    p.props
        .iter()
        .zip(values)
        .map(|(pr, v)| pr.scale(v))
        .collect()
}

/// Every record of this run's draws (all, or the shard's block of draw indices), ordered
/// by level, sigma, draw. Parallel over draws; each record depends only on its indices.
/// The draws are a stage of `progress`.
pub fn draws(prep: &Prepared, cfg: &StudyConfig, progress: &dyn Progress) -> Vec<DrawRecord> {
    let range = match cfg.shard {
        Some(s) => s.rows(cfg.draws),
        None => 0..cfg.draws,
    };
    let mut jobs = Vec::new();
    for (li, _) in prep.levels.iter().enumerate() {
        for k in 0..cfg.sigmas.len() {
            for d in range.clone() {
                jobs.push((li, k, d));
            }
        }
    }
    let stage = Stage::new(progress, "draws", Some(jobs.len() as u64), "draws");
    let one = |&(li, k, d): &(usize, usize, usize)| {
        stage.advance(1);
        let p = &prep.levels[li];
        let scales = draw_scales(p, cfg, k, d);
        let hourly = match (&prep.weighted, &p.free_lux) {
            (Some(w), Some(free)) => {
                let h = p.model.hourly(&scales, w);
                Some(hourly_metrics(
                    &h.lux,
                    free,
                    h.hours,
                    prep.sky.step_hours,
                    &cfg.thresholds,
                ))
            }
            _ => None,
        };
        DrawRecord {
            level: p.level,
            sigma_index: k,
            draw: d,
            tai: p.model.tai(&scales),
            hourly,
        }
    };
    let run = || jobs.par_iter().map(one).collect::<Vec<_>>();
    match cfg.trace.threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_or_else(|_| run(), |pool| pool.install(run)),
        None => run(),
    }
}

/// What a cell's hour-based metrics did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CellHourly {
    pub udi_a: Summary,
    pub da: Summary,
    pub sda: Summary,
    /// Seed Eq. A.3: the mean over draws of each draw's RMS difference (lx).
    pub rmse_a3_lux: f64,
}

/// One (GLoD, MCoP) cell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cell {
    pub level: u8,
    pub sigma: f64,
    /// Room TAI (klx h) over the draws.
    pub room_tai: Summary,
    /// The error-free model's room TAI at this level.
    pub free_room_tai: f64,
    /// Eq. A.1 of each draw's room TAI against the error-free model at this level (%).
    pub pe: Summary,
    /// Eq. A.2: mean absolute PE against the same level's error-free model (%).
    pub mape: f64,
    /// Eq. A.2 against the highest studied level's error-free model (the seed's Fig. 3.9
    /// benchmark: geometry and material error together).
    pub mape_vs_top: f64,
    /// D'Agostino-Pearson on the PEs (`None` below 20 draws).
    pub normality: Option<Normality>,
    /// KS distance of the PEs to their fitted normal, all draws.
    pub ks: Option<KsFit>,
    /// The convergence curve (Fig. 3.5).
    pub ks_curve: Vec<KsFit>,
    pub hourly: Option<CellHourly>,
}

/// One sensor in one cell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorCell {
    pub level: u8,
    pub sigma: f64,
    pub sensor: usize,
    pub free_tai: f64,
    pub tai: Summary,
    /// Mean absolute PE of the sensor's TAI against its error-free value (%); NaN for a
    /// sensor the error-free model leaves dark.
    pub mape: f64,
    /// Per-sensor UDI-a and DA medians and 5/95 percentiles (with hourly metrics).
    pub udi_a: Option<Summary>,
    pub da: Option<Summary>,
}

/// A property of one level, with the range its draws covered.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MaterialRow {
    pub level: u8,
    pub property: Property,
}

/// The reduced study.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Results {
    pub cells: Vec<Cell>,
    pub sensors: Vec<SensorCell>,
    pub materials: Vec<MaterialRow>,
    pub draws: usize,
    pub sigmas: Vec<f64>,
    pub levels: Vec<u8>,
    /// Sensor positions (x, y).
    pub positions: Vec<[f64; 2]>,
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// Reduce all records (every draw of every cell, in any order) to the statistics.
pub fn reduce(prep: &Prepared, cfg: &StudyConfig, records: &[DrawRecord]) -> Result<Results> {
    let mut by_cell: std::collections::BTreeMap<(u8, usize), Vec<&DrawRecord>> = Default::default();
    for r in records {
        by_cell.entry((r.level, r.sigma_index)).or_default().push(r);
    }
    let top = prep
        .levels
        .last()
        .ok_or_else(|| Error::Usage("no level traced".into()))?;
    let top_room = mean(&top.free_tai);
    let (mut cells, mut sensors) = (Vec::new(), Vec::new());
    for p in &prep.levels {
        let free_room = mean(&p.free_tai);
        for (k, &sigma) in cfg.sigmas.iter().enumerate() {
            let mut recs = by_cell.remove(&(p.level, k)).unwrap_or_default();
            recs.sort_by_key(|r| r.draw);
            let complete =
                recs.len() == cfg.draws && recs.iter().enumerate().all(|(i, r)| r.draw == i);
            if !complete {
                return Err(Error::Mismatch(format!(
                    "GLoD{} sigma {sigma}: {} distinct draws of {}; a shard is missing or duplicated",
                    p.level,
                    recs.len(),
                    cfg.draws
                )));
            }
            let rooms: Vec<f64> = recs.iter().map(|r| mean(&r.tai)).collect();
            let pes: Vec<f64> = rooms
                .iter()
                .map(|&x| percentage_error(x, free_room))
                .collect();
            let hourly = recs[0].hourly.as_ref().map(|_| {
                let col = |i: usize| -> Vec<f64> {
                    recs.iter()
                        .filter_map(|r| r.hourly.as_ref().map(|h| h.room[i]))
                        .collect()
                };
                CellHourly {
                    udi_a: Summary::of(&col(2)),
                    da: Summary::of(&col(4)),
                    sda: Summary::of(&col(5)),
                    rmse_a3_lux: mean(
                        &recs
                            .iter()
                            .filter_map(|r| r.hourly.as_ref().map(|h| h.rmse_lux))
                            .collect::<Vec<_>>(),
                    ),
                }
            });
            cells.push(Cell {
                level: p.level,
                sigma,
                room_tai: Summary::of(&rooms),
                free_room_tai: free_room,
                mape: mean(&pes.iter().map(|x| x.abs()).collect::<Vec<_>>()),
                mape_vs_top: mean(
                    &rooms
                        .iter()
                        .map(|&x| percentage_error(x, top_room).abs())
                        .collect::<Vec<_>>(),
                ),
                pe: Summary::of(&pes),
                normality: dagostino_pearson(&pes),
                ks: ks_normal(&pes),
                ks_curve: ks_curve(&pes),
                hourly,
            });
            for (i, &free) in p.free_tai.iter().enumerate() {
                let t: Vec<f64> = recs.iter().map(|r| r.tai[i]).collect();
                let per = |f: &dyn Fn(&DrawHourly) -> f64| -> Option<Summary> {
                    let v: Vec<f64> = recs
                        .iter()
                        .filter_map(|r| r.hourly.as_ref().map(f))
                        .collect();
                    (!v.is_empty()).then(|| Summary::of(&v))
                };
                sensors.push(SensorCell {
                    level: p.level,
                    sigma,
                    sensor: i,
                    free_tai: free,
                    mape: if free > 0.0 {
                        mean(
                            &t.iter()
                                .map(|&x| percentage_error(x, free).abs())
                                .collect::<Vec<_>>(),
                        )
                    } else {
                        f64::NAN
                    },
                    tai: Summary::of(&t),
                    udi_a: per(&|h| h.udi_a[i]),
                    da: per(&|h| h.da[i]),
                });
            }
        }
    }
    if let Some(((l, k), _)) = by_cell.into_iter().next() {
        return Err(Error::Mismatch(format!(
            "records of GLoD{l} sigma class {k}, which this study does not have"
        )));
    }
    Ok(Results {
        cells,
        sensors,
        materials: prep
            .levels
            .iter()
            .flat_map(|p| {
                p.props.iter().map(|pr| MaterialRow {
                    level: p.level,
                    property: pr.clone(),
                })
            })
            .collect(),
        draws: cfg.draws,
        sigmas: cfg.sigmas.clone(),
        levels: prep.levels.iter().map(|p| p.level).collect(),
        positions: prep.positions.clone(),
    })
}

/// A shard's records and what they came from (`rmcop study --shard K/N --records FILE`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardFile {
    pub format: String,
    pub manifest: Manifest,
    pub records: Vec<DrawRecord>,
}

/// The format name in a [`ShardFile`].
pub const SHARD_FORMAT: &str = "rdaylight-mcop-draws-1";

impl ShardFile {
    pub fn read(path: &str) -> Result<ShardFile> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let f: ShardFile = serde_json::from_str(&text).map_err(|e| {
            Error::parse(
                rdaylight_base::error::Location::line(path, e.line()),
                format!(
                    "not an rmcop records file ({e}); expected what rmcop study --records writes"
                ),
            )
        })?;
        if f.format != SHARD_FORMAT {
            return Err(Error::Mismatch(format!(
                "{path}: format '{}', expected '{SHARD_FORMAT}' (written by another rmcop version)",
                f.format
            )));
        }
        Ok(f)
    }

    pub fn write(&self, path: &str) -> Result<()> {
        let text = serde_json::to_string(self).map_err(|e| Error::Usage(format!("{path}: {e}")))?;
        rdaylight_base::io::write_atomically(std::path::Path::new(path), |w| {
            w.write_all(text.as_bytes())
                .and_then(|_| w.write_all(b"\n"))
                .map_err(|e| Error::io(path, e))
        })
    }
}
