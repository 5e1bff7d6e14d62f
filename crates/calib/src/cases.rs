//! # Hidden-effect test cases
//!
//! A case is a model (what the user has), a truth (the model plus a hidden effect, written
//! by [`super::apply`] as real geometry or materials, or a sensor fault in the readings),
//! and readings simulated from the truth at better settings
//! ([`Settings::truth`](super::simulate::Settings::truth)) with
//! realistic sensor noise: a fixed calibration factor per sensor, `exp(N(0, 0.03))`, and a
//! per-reading factor `exp(N(0, 0.02))` (seeded, so a case is reproducible).
//!
//! Rooms ([`RoomKind`]): the example office (6 x 8 x 3 m, south window 4.8 x 1.6 m, as
//! `examples/room/room.rad`), a deep narrow room (3.5 x 10 x 3 m, one south window) and a
//! room with two windows (6 x 6 x 3 m, south and east).
//!
//! Climates ([`Climate`]): London Gatwick (the bundled IWEC EPW, measured DNI/DHI) and a
//! synthetic sunny site (Madrid, 40.4 N 3.7 W): clear days from Meinel's clear-sky direct
//! normal irradiance `DNI = 1353 x 0.7^(AM^0.678)` (Meinel & Meinel 1976, *Applied Solar
//! Energy*, via Laue 1970) with air mass `1/sin(alt)`, diffuse horizontal `0.1 x DNI sin(alt)
//! + 30`, and every fourth day overcast (no beam, diffuse 40 % of the clear global).

use super::effects::Effect;
use super::measurements::{Bound, Reading};
use super::model::Model;
use super::room::{Room, SurfaceClass};
use super::session::{self, Options};
use crate::error::Result;
use crate::formats::sensors::{Sensor, SensorRay};
use crate::formats::weather::{Site, WeaUnits, Weather, WeatherStep};
use crate::scene::{LoadOptions, Scene, parse_str};
use crate::sky::solar::{SunPosition, day_of_year};
use rand::{Rng, SeedableRng};

/// Per-sensor calibration spread and per-reading noise (relative, log-normal).
pub const SENSOR_SIGMA: f64 = 0.03;
pub const READING_SIGMA: f64 = 0.02;

/// Room geometries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RoomKind {
    Office,
    Deep,
    TwoWindow,
}

impl RoomKind {
    pub const ALL: [RoomKind; 3] = [RoomKind::Office, RoomKind::Deep, RoomKind::TwoWindow];
    pub fn name(self) -> &'static str {
        match self {
            RoomKind::Office => "office",
            RoomKind::Deep => "deep",
            RoomKind::TwoWindow => "two-window",
        }
    }
}

/// A window in a wall: wall index (0 south y=0, 1 east x=W, 2 north, 3 west), horizontal
/// range along the wall from its start, sill and head.
struct Opening {
    wall: usize,
    u: (f64, f64),
    z: (f64, f64),
}

fn poly(mat: &str, id: &str, v: &[[f64; 3]]) -> String {
    let mut s = format!("{mat} polygon {id} 0 0 {}\n", v.len() * 3);
    for p in v {
        s.push_str(&format!("\t{} {} {}\n", p[0], p[1], p[2]));
    }
    s
}

/// A box room `w` (x) by `d` (y) by `h` with openings; every normal faces into the room.
fn box_room(w: f64, d: f64, h: f64, openings: &[Opening]) -> String {
    let mut s = String::from(
        "# rcalib synthetic room\n\
         void plastic wall_mat 0 0 5 0.5 0.5 0.5 0 0\n\
         void plastic floor_mat 0 0 5 0.2 0.2 0.2 0 0\n\
         void plastic ceiling_mat 0 0 5 0.8 0.8 0.8 0 0\n\
         void plastic ground_mat 0 0 5 0.2 0.2 0.2 0 0\n\
         void glass glazing 0 0 3 0.96 0.96 0.96\n",
    );
    s += &poly(
        "floor_mat",
        "floor",
        &[[0., 0., 0.], [w, 0., 0.], [w, d, 0.], [0., d, 0.]],
    );
    s += &poly(
        "ceiling_mat",
        "ceiling",
        &[[0., 0., h], [0., d, h], [w, d, h], [w, 0., h]],
    );
    // Walls: origin, tangent (counter-clockwise seen from above inside), length.
    let walls: [([f64; 3], [f64; 3], f64); 4] = [
        ([0., 0., 0.], [1., 0., 0.], w),
        ([w, 0., 0.], [0., 1., 0.], d),
        ([w, d, 0.], [-1., 0., 0.], w),
        ([0., d, 0.], [0., -1., 0.], d),
    ];
    for (k, (o, t, len)) in walls.iter().enumerate() {
        let at = |u: f64, z: f64| [o[0] + t[0] * u, o[1] + t[1] * u, z];
        // (u0,z0)-(u1,z1) rectangle, counter-clockwise seen from inside (normal = z x t).
        let rect =
            |u0: f64, u1: f64, z0: f64, z1: f64| [at(u0, z0), at(u0, z1), at(u1, z1), at(u1, z0)];
        let mine: Vec<&Opening> = openings.iter().filter(|op| op.wall == k).collect();
        match mine.first() {
            None => s += &poly("wall_mat", &format!("wall{k}"), &rect(0.0, *len, 0.0, h)),
            Some(op) => {
                let (u0, u1) = op.u;
                let (z0, z1) = op.z;
                s += &poly(
                    "wall_mat",
                    &format!("wall{k}_sill"),
                    &rect(0.0, *len, 0.0, z0),
                );
                s += &poly(
                    "wall_mat",
                    &format!("wall{k}_head"),
                    &rect(0.0, *len, z1, h),
                );
                s += &poly("wall_mat", &format!("wall{k}_a"), &rect(0.0, u0, z0, z1));
                s += &poly("wall_mat", &format!("wall{k}_b"), &rect(u1, *len, z0, z1));
                s += &poly("glazing", &format!("window{k}"), &rect(u0, u1, z0, z1));
            }
        }
    }
    s += &poly(
        "ground_mat",
        "ground",
        &[
            [-30., -30., 0.],
            [w + 30., -30., 0.],
            [w + 30., 0., 0.],
            [-30., 0., 0.],
        ],
    );
    s
}

fn grid(xs: &[f64], ys: &[f64]) -> Vec<Sensor> {
    let mut v = Vec::new();
    for y in ys {
        for x in xs {
            v.push(Sensor {
                id: format!("s{:02}", v.len() + 1),
                ray: SensorRay::new([*x, *y, 0.8], [0.0, 0.0, 1.0]),
            });
        }
    }
    v
}

/// Scene text and sensors of a room.
pub fn room(kind: RoomKind) -> (String, Vec<Sensor>) {
    match kind {
        RoomKind::Office => (
            box_room(
                6.0,
                8.0,
                3.0,
                &[Opening {
                    wall: 0,
                    u: (0.6, 5.4),
                    z: (0.9, 2.5),
                }],
            ),
            grid(&[1.5, 3.0, 4.5], &[1.0, 3.0, 5.0, 7.0]),
        ),
        RoomKind::Deep => (
            box_room(
                3.5,
                10.0,
                3.0,
                &[Opening {
                    wall: 0,
                    u: (0.5, 3.0),
                    z: (0.9, 2.4),
                }],
            ),
            grid(&[1.0, 2.5], &[1.0, 3.0, 5.0, 7.0, 9.0]),
        ),
        RoomKind::TwoWindow => (
            box_room(
                6.0,
                6.0,
                3.0,
                &[
                    Opening {
                        wall: 0,
                        u: (1.0, 5.0),
                        z: (0.9, 2.4),
                    },
                    Opening {
                        wall: 1,
                        u: (1.5, 4.5),
                        z: (0.9, 2.4),
                    },
                ],
            ),
            grid(&[1.0, 3.0, 5.0], &[1.0, 3.0, 5.0]),
        ),
    }
}

/// Climates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Climate {
    London,
    Sunny,
}

impl Climate {
    pub fn name(self) -> &'static str {
        match self {
            Climate::London => "london",
            Climate::Sunny => "sunny",
        }
    }
}

/// The synthetic sunny weather (see the module doc): days 1, 8, 15, ... of March to
/// October, hours 7.5 .. 18.5.
pub fn sunny_weather() -> Weather {
    let site = Site {
        name: "Madrid".into(),
        country: "ESP".into(),
        latitude_deg_n: 40.4,
        longitude_deg_e: -3.7,
        meridian_deg_e: 15.0,
        elevation_m: 650.0,
    };
    let mut steps = Vec::new();
    let mut n = 0usize;
    for month in 3..=10u8 {
        for day in [1u8, 8, 15, 22] {
            n += 1;
            let overcast = n % 4 == 0;
            for h in 7..=18 {
                let hour = h as f64 + 0.5;
                let pos = SunPosition::at(&site, day_of_year(month.into(), day.into()), hour);
                let sa = pos.altitude.sin();
                let (dni, dhi) = if sa <= 0.02 {
                    (0.0, 0.0)
                } else {
                    let am = 1.0 / sa;
                    let dni = 1353.0 * 0.7f64.powf(am.powf(0.678));
                    let dhi = 0.1 * dni * sa + 30.0;
                    if overcast {
                        (0.0, 0.4 * (dni * sa + dhi))
                    } else {
                        (dni, dhi)
                    }
                };
                steps.push(WeatherStep {
                    month,
                    day,
                    hour,
                    direct: dni,
                    diffuse: dhi,
                    aod: None,
                    sky_cover: None,
                    dew_point: None,
                    year: None,
                });
            }
        }
    }
    Weather {
        site,
        units: WeaUnits::NormalIrradiance,
        steps,
        epw_text: None,
    }
}

/// `n` measured steps of `w`: daytime steps (global horizontal above 80 W/m2) spread evenly
/// over the candidates, from days between March and October.
pub fn pick_steps(w: &Weather, n: usize, seed: u64) -> Vec<usize> {
    let cand: Vec<usize> = w
        .steps
        .iter()
        .enumerate()
        .filter(|(_, s)| {
            (3..=10).contains(&s.month) && s.diffuse < 1000.0 && s.direct < 2000.0 && {
                s.diffuse + s.direct * 0.5 > 80.0 && s.diffuse > 10.0
            }
        })
        .map(|(i, _)| i)
        .collect();
    if cand.is_empty() {
        return Vec::new();
    }
    let stride = (cand.len() as f64 / n as f64).max(1.0);
    let off = (seed as usize * 7) % (stride as usize).max(1);
    (0..n)
        .map(|k| cand[((k as f64 * stride) as usize + off).min(cand.len() - 1)])
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect()
}

/// A generated case.
pub struct Case {
    pub name: String,
    pub model_text: String,
    pub truth_text: String,
    pub sensors: Vec<Sensor>,
    pub weather: Weather,
    /// Noisy readings (weather step indices).
    pub readings: Vec<Bound>,
    /// Noise-free truth values at the readings.
    pub truth_values: Vec<f64>,
    /// The hidden effects (families), empty for a control.
    pub hidden: Vec<Effect>,
    /// The hidden effects' families where they are not [`Case::hidden`] (cases made
    /// outside rcalib, [`Case::from_dir`]: real geometry, no rcalib parameters); empty:
    /// the families of `hidden`.
    pub families: Vec<String>,
}

/// Parse a case's scene text.
pub fn scene_of(text: &str) -> Result<Scene> {
    parse_str(
        text,
        "<case>",
        std::path::Path::new(""),
        &LoadOptions::default(),
    )
}

fn normal(rng: &mut rand_pcg::Pcg64) -> f64 {
    let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-12), rng.random());
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// Room of a scene text as the effects see it.
pub fn room_of(scene: &Scene, sensors: &[Sensor]) -> Room {
    Room::new(scene, super::room::sensor_centroid(sensors), &[])
}

/// Build a case: `hidden` effects applied to the room's model (sensor faults go into the
/// readings), readings at `nsteps` steps of `weather` simulated with `truth`'s settings
/// (and its cache and progress).
pub fn generate(
    name: &str,
    kind: RoomKind,
    weather: Weather,
    hidden: Vec<Effect>,
    nsteps: usize,
    seed: u64,
    truth: &Options,
) -> Result<Case> {
    let (model_text, sensors) = room(kind);
    generate_with_sensors(
        name,
        &model_text,
        sensors,
        weather,
        hidden,
        nsteps,
        seed,
        truth,
    )
}

/// What the photopic ([`generate_with_sensors`]) and spectral
/// ([`crate::spectral::case::generate`]) case builders share: the truth scene (the model
/// with the hidden effects written by [`super::apply`]; sensor faults are no geometry), the
/// measured steps, the truth settings and the seeded sensor noise. The builders differ
/// only in how they simulate the readings (photopic illuminance with the sensor faults
/// applied, or N bands with per-channel noise).
pub struct Truth {
    pub model_text: String,
    pub truth_text: String,
    pub truth_scene: Scene,
    /// Measured weather steps.
    pub steps: Vec<usize>,
    /// Options of the truth simulation.
    pub opts: Options,
}

impl Truth {
    /// The truth of `model_text` with `hidden` effects at `nsteps` steps of `weather`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        model_text: &str,
        sensors: &[Sensor],
        weather: &Weather,
        hidden: &[Effect],
        nsteps: usize,
        seed: u64,
        truth: &Options,
    ) -> Result<Truth> {
        let model = scene_of(model_text)?;
        let room = room_of(&model, sensors);
        let geometric: Vec<Effect> = hidden
            .iter()
            .filter(|e| !matches!(e, Effect::SensorFault { .. }))
            .cloned()
            .collect();
        let truth_text = super::apply::apply(&model, &room, sensors, &geometric, "hidden effect")?;
        Ok(Truth {
            model_text: model_text.to_string(),
            truth_scene: scene_of(&truth_text)?,
            truth_text,
            steps: pick_steps(weather, nsteps, seed),
            opts: Options {
                reflectance: false,
                classes: Vec::new(),
                ..truth.clone()
            },
        })
    }

    /// One reading per measured step and sensor (step-major), each with `value`.
    pub fn bound(&self, nsensors: usize, value: f64) -> Vec<Bound> {
        self.steps
            .iter()
            .flat_map(|&t| {
                (0..nsensors).map(move |s| Bound {
                    sensor: s,
                    step: t,
                    value,
                })
            })
            .collect()
    }
}

/// The seeded sensor noise of a case (see the module doc): a calibration factor per sensor
/// drawn first, then the per-reading factors in reading order.
pub struct Noise {
    rng: rand_pcg::Pcg64,
    cal: Vec<f64>,
}

impl Noise {
    pub fn new(seed: u64, nsensors: usize) -> Noise {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
        let cal = (0..nsensors)
            .map(|_| (SENSOR_SIGMA * normal(&mut rng)).exp())
            .collect();
        Noise { rng, cal }
    }

    /// The next reading's factors for `sensor`: (calibration, per-reading).
    pub fn reading(&mut self, sensor: usize) -> (f64, f64) {
        (
            self.cal[sensor],
            (READING_SIGMA * normal(&mut self.rng)).exp(),
        )
    }

    /// The next log-normal factor of spread `sigma` (e.g. a spectral channel's noise).
    pub fn factor(&mut self, sigma: f64) -> f64 {
        (sigma * normal(&mut self.rng)).exp()
    }
}

/// [`generate`] for a given model text and sensors (e.g. a denser grid than the room's).
#[allow(clippy::too_many_arguments)]
pub fn generate_with_sensors(
    name: &str,
    model_text: &str,
    sensors: Vec<Sensor>,
    weather: Weather,
    hidden: Vec<Effect>,
    nsteps: usize,
    seed: u64,
    truth: &Options,
) -> Result<Case> {
    let t = Truth::new(model_text, &sensors, &weather, &hidden, nsteps, seed, truth)?;
    let dummy = t.bound(sensors.len(), 1.0);
    let tm = session::build(&t.truth_scene, sensors.clone(), &weather, &dummy, &t.opts)?;
    let mut values = tm.predict(&[]);
    for e in &hidden {
        if let Effect::SensorFault { factors } = e {
            for (v, o) in values.iter_mut().zip(&tm.obs) {
                if let Some((_, f)) = factors.iter().find(|f| f.0 == o.sensor) {
                    *v *= f;
                }
            }
        }
    }
    let mut noise = Noise::new(seed, sensors.len());
    let readings: Vec<Bound> = dummy
        .iter()
        .zip(&values)
        .map(|(b, v)| {
            let (cal, reading) = noise.reading(b.sensor);
            Bound {
                value: v * cal * reading,
                ..*b
            }
        })
        .collect();
    Ok(Case {
        name: name.to_string(),
        model_text: t.model_text,
        truth_text: t.truth_text,
        sensors,
        weather,
        readings,
        truth_values: values,
        hidden,
        families: Vec::new(),
    })
}

impl Case {
    /// A case made outside rcalib (`radiance-fixtures/calib-cases/`, truths by real
    /// Radiance): `model.rad`, `sensors.csv`, `weather.wea` and `readings.csv` (what a
    /// user has), `truth.rad`, `truth.tsv` (two independent runs per reading, whose mean
    /// is the noise-free truth) and `case.json` (the hidden effects' families; a sensor
    /// fault's sensor index and factor).
    pub fn from_dir(dir: &std::path::Path) -> Result<Case> {
        use crate::error::Error;
        let file = |name: &str| dir.join(name).to_string_lossy().into_owned();
        let read = |name: &str| {
            std::fs::read_to_string(dir.join(name))
                .map_err(|e| Error::Usage(format!("{}: {e}", file(name))))
        };
        let l = session::load(
            &[file("model.rad")],
            &file("sensors.csv"),
            &file("weather.wea"),
            &file("readings.csv"),
            &super::measurements::Columns::default(),
        )?;
        let meta: serde_json::Value = serde_json::from_str(&read("case.json")?)
            .map_err(|e| Error::Usage(format!("{}: {e}", file("case.json"))))?;
        let name = meta["name"].as_str().unwrap_or("case").to_string();
        let mut families = Vec::new();
        let mut hidden = Vec::new();
        for h in meta["hidden"].as_array().into_iter().flatten() {
            let fam = h["effect"].as_str().unwrap_or_default().to_string();
            if fam == "sensor-fault" {
                let i = h["sensor"].as_u64().unwrap_or(0) as usize;
                let f = h["factor"].as_f64().unwrap_or(1.0);
                hidden.push(Effect::SensorFault {
                    factors: vec![(i, f)],
                });
            }
            families.push(fam);
        }
        // Truth per (month, day, hour in ms, sensor): the mean of the two runs.
        let key =
            |m: u32, d: u32, h: f64, s: &str| (m, d, (h * 1000.0).round() as i64, s.to_string());
        let mut truth = std::collections::HashMap::new();
        for (n, line) in read("truth.tsv")?.lines().enumerate().skip(1) {
            let f: Vec<&str> = line.split('\t').collect();
            let num = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok());
            match (num(0), num(1), num(2), f.get(3), num(4), num(5)) {
                (Some(m), Some(d), Some(h), Some(s), Some(a), Some(b)) => {
                    truth.insert(key(m as u32, d as u32, h, s), 0.5 * (a + b));
                }
                _ => {
                    return Err(Error::Usage(format!(
                        "{}:{}: expected month, day, hour, sensor and two values",
                        file("truth.tsv"),
                        n + 1
                    )));
                }
            }
        }
        let truth_values = l
            .readings
            .iter()
            .map(|b| {
                let st = &l.weather.steps[b.step];
                let id = &l.sensors[b.sensor].id;
                truth
                    .get(&key(st.month.into(), st.day.into(), st.hour, id))
                    .copied()
                    .ok_or_else(|| {
                        Error::Usage(format!(
                            "{}: no truth for sensor {id} at {}/{} {}",
                            file("truth.tsv"),
                            st.month,
                            st.day,
                            st.hour
                        ))
                    })
            })
            .collect::<Result<Vec<f64>>>()?;
        // The noise-free readings carry the hidden fault, as `generate`'s do.
        let truth_values = truth_values
            .into_iter()
            .zip(&l.readings)
            .map(|(v, b)| {
                hidden.iter().fold(v, |v, e| match e {
                    Effect::SensorFault { factors } => factors
                        .iter()
                        .find(|f| f.0 == b.sensor)
                        .map_or(v, |f| v * f.1),
                    _ => v,
                })
            })
            .collect();
        Ok(Case {
            name,
            model_text: read("model.rad")?,
            truth_text: read("truth.rad")?,
            sensors: l.sensors,
            weather: l.weather,
            readings: l.readings,
            truth_values,
            hidden,
            families,
        })
    }

    /// The hidden families, for the hit rule.
    pub fn hidden_families(&self) -> Vec<String> {
        if self.families.is_empty() {
            self.hidden.iter().map(|e| e.family().to_string()).collect()
        } else {
            self.families.clone()
        }
    }

    /// The model as a scene.
    pub fn model_scene(&self) -> Result<Scene> {
        scene_of(&self.model_text)
    }
    pub fn truth_scene(&self) -> Result<Scene> {
        scene_of(&self.truth_text)
    }
    /// Build the calibration model of a scene text against this case's readings.
    pub fn model(&self, text: &str, opts: &Options) -> Result<Model> {
        session::build(
            &scene_of(text)?,
            self.sensors.clone(),
            &self.weather,
            &self.readings,
            opts,
        )
    }
    /// Readings as CSV records.
    pub fn csv_readings(&self) -> Vec<Reading> {
        self.readings
            .iter()
            .map(|b| {
                let s = &self.weather.steps[b.step];
                Reading {
                    month: s.month.into(),
                    day: s.day.into(),
                    hour: s.hour,
                    sensor: self.sensors[b.sensor].id.clone(),
                    value: b.value,
                    line: 0,
                }
            })
            .collect()
    }
}

/// Hidden effects of the hit-rate table (family name, effect) for a room; sensor indices
/// refer to the room's sensors.
pub fn hidden_effects(kind: RoomKind) -> Vec<(String, Vec<Effect>)> {
    let (_, sensors) = room(kind);
    let ns = sensors.len();
    let south = 180.0;
    let single = vec![
        ("transmittance", vec![Effect::Transmittance { scale: 0.7 }]),
        (
            "obstruction",
            vec![Effect::Obstruction {
                azimuth: south + 20.0,
                half_width: 45.0,
                altitude: 30.0,
            }],
        ),
        (
            "walls",
            vec![Effect::Reflectance {
                class: SurfaceClass::Walls,
                scale: 0.5,
            }],
        ),
        (
            "ground-albedo",
            vec![Effect::Reflectance {
                class: SurfaceClass::Ground,
                scale: 2.5,
            }],
        ),
        (
            "overhang",
            vec![Effect::Overhang {
                window: 0,
                depth: 1.2,
                above: 0.0,
                overrun: 1.2,
            }],
        ),
        (
            "local-obstruction",
            vec![Effect::LocalObstruction {
                sensors: vec![ns / 2 - 1, ns / 2],
                fraction: 0.7,
            }],
        ),
        (
            "sensor-fault",
            vec![Effect::SensorFault {
                factors: vec![(ns - 2, 0.6)],
            }],
        ),
        ("control", vec![]),
        (
            "transmittance+obstruction",
            vec![
                Effect::Transmittance { scale: 0.75 },
                Effect::Obstruction {
                    azimuth: south - 20.0,
                    half_width: 40.0,
                    altitude: 28.0,
                },
            ],
        ),
        (
            "walls+sensor-fault",
            vec![
                Effect::Reflectance {
                    class: SurfaceClass::Walls,
                    scale: 0.5,
                },
                Effect::SensorFault {
                    factors: vec![(1, 1.4)],
                },
            ],
        ),
    ];
    single
        .into_iter()
        .map(|(n, e)| (n.to_string(), e))
        .collect()
}

/// Rounds of [`super::explain::refine`] in [`evaluate`] (as `rcalib explain`'s default).
pub const REFINE_ROUNDS: usize = 2;

/// What the hit-rate table records of one case.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Outcome {
    pub name: String,
    pub hidden: Vec<String>,
    /// Families selected by explain, in order.
    pub selected: Vec<String>,
    pub specs: Vec<String>,
    /// The selected effects as the coefficient model fitted them, before the refinement
    /// against re-simulation (how far the refinement had to move them).
    pub unrefined: Vec<String>,
    /// Single-effect ranking, best first.
    pub ranking: Vec<String>,
    /// Single effect: ranked first and selected first; combined: every hidden family
    /// selected; control: nothing selected.
    pub hit: bool,
    pub rmse_before: f64,
    /// After applying the selected effects to the model and re-simulating with rdc.
    pub rmse_after: f64,
    /// Noise-only error: RMSE_rel of the readings against the noise-free truth values they
    /// were made from (the sensor noise alone; a perfect model simulated without error).
    pub rmse_noise: f64,
    /// The simulation's own error: RMSE_rel (percent) of the truth scene simulated at the
    /// model's settings against the noise-free truth values (converged settings).
    pub rmse_sim: f64,
    /// Apply fidelity: RMSE_rel (percent) of what the fitted effects predicted
    /// ([`Model::predict`]) against the re-simulation of the applied model.
    pub rmse_fit_vs_apply: f64,
    /// The readings the applied model misses most (sensor, step, sun altitude and
    /// azimuth, measured, applied, fitted, truth): where the remaining error comes from.
    pub worst: Vec<String>,
    pub seconds: f64,
}

impl Outcome {
    /// The acceptance rule: hit, and the applied model within `factor` of the noise-only
    /// error (a control passes when nothing is selected).
    pub fn passes(&self, factor: f64) -> bool {
        self.hit && self.rmse_after <= factor * self.rmse_noise
    }
}

/// The floor any fit meets: RMSE_rel (percent) after applying the hidden effects themselves
/// with their main parameter times `factor` (e.g. 1.01), re-simulated like an applied fit.
/// Two rdc runs of nearly the same scene disagree by their Monte Carlo noise where paths
/// diverge; the noise-only error shares the readings' own simulation and has none.
pub fn oracle_rmse(case: &Case, opts: &Options, factor: f64) -> Result<f64> {
    let effects: Vec<Effect> = case
        .hidden
        .iter()
        .map(|e| e.with_primary(e.primary().1 * factor))
        .collect();
    let geometric: Vec<Effect> = effects
        .iter()
        .filter(|e| !matches!(e, Effect::SensorFault { .. }))
        .cloned()
        .collect();
    let faults: Vec<Effect> = effects
        .iter()
        .filter(|e| matches!(e, Effect::SensorFault { .. }))
        .cloned()
        .collect();
    let model = case.model_scene()?;
    let room = room_of(&model, &case.sensors);
    let text = super::apply::apply(&model, &room, &case.sensors, &geometric, "oracle")?;
    let m = case.model(&text, opts)?;
    let sim = m.predict(&faults);
    let pairs: Vec<(f64, f64)> = sim.iter().zip(&m.obs).map(|(y, o)| (*y, o.value)).collect();
    Ok(super::stats::Stats::of(&pairs).rmse_rel)
}

/// Run explain on a case, apply what it selects, re-simulate, compare with the noise-only
/// error.
pub fn evaluate(case: &Case, opts: &Options, sigma_sensor: f64) -> Result<Outcome> {
    let t0 = std::time::Instant::now();
    let with_refl = Options {
        reflectance: true,
        ..opts.clone()
    };
    let m = case.model(&case.model_text, &with_refl)?;
    let model = case.model_scene()?;
    let ex = super::explain::explain(&m, &[], sigma_sensor);
    let unrefined = ex.specs.clone();
    let ex = super::explain::refined(&m, ex, sigma_sensor, REFINE_ROUNDS, &|e| {
        super::explain::simulate_applied(&model, &m, &case.weather, &case.readings, opts, e)
    })?;
    let effects: Vec<Effect> = ex.selected.iter().map(|c| c.effect.clone()).collect();
    let room = room_of(&model, &case.sensors);
    let text = super::apply::apply(&model, &room, &case.sensors, &effects, "evaluation")?;
    let after_model = case.model(&text, opts)?;
    // Sensor faults correct the readings; as the simulation is multiplied instead, the
    // relative error is the same.
    let faults: Vec<Effect> = effects
        .iter()
        .filter(|e| matches!(e, Effect::SensorFault { .. }))
        .cloned()
        .collect();
    let rmse = |m: &Model, sim: &[f64]| {
        let pairs: Vec<(f64, f64)> = sim.iter().zip(&m.obs).map(|(y, o)| (*y, o.value)).collect();
        super::stats::Stats::of(&pairs).rmse_rel
    };
    let after_sim = after_model.predict(&faults);
    let rmse_after = rmse(&after_model, &after_sim);
    let fitted_sim = m.predict(&effects);
    let rmse_fit_vs_apply = {
        let pairs: Vec<(f64, f64)> = fitted_sim
            .iter()
            .zip(&after_sim)
            .map(|(f, a)| (*f, *a))
            .collect();
        super::stats::Stats::of(&pairs).rmse_rel
    };
    let truth = case.model(&case.truth_text, opts)?;
    let hidden_faults: Vec<Effect> = case
        .hidden
        .iter()
        .filter(|e| matches!(e, Effect::SensorFault { .. }))
        .cloned()
        .collect();
    // The truth re-simulated at the model's settings: the best any fit can do through
    // this simulation (shown beside the worst readings).
    let truth_sim = truth.predict(&hidden_faults);
    let rmse_noise = {
        let pairs: Vec<(f64, f64)> = case
            .truth_values
            .iter()
            .zip(&m.obs)
            .map(|(t, o)| (*t, o.value))
            .collect();
        super::stats::Stats::of(&pairs).rmse_rel
    };
    let rmse_sim = {
        let pairs: Vec<(f64, f64)> = truth_sim
            .iter()
            .zip(&case.truth_values)
            .map(|(y, t)| (*y, *t))
            .collect();
        super::stats::Stats::of(&pairs).rmse_rel
    };
    let mut order: Vec<usize> = (0..after_sim.len()).collect();
    let err = |i: usize| (after_sim[i] / m.obs[i].value.max(1.0) - 1.0).abs();
    order.sort_by(|a, b| err(*b).total_cmp(&err(*a)));
    let worst: Vec<String> = order
        .iter()
        .take(6)
        .map(|&i| {
            let o = &m.obs[i];
            let sk = &m.skies[o.step];
            format!(
                "{} t{} sun {:.0}/{:.0} meas {:.0} applied {:.0} fitted {:.0} truth {:.0}",
                case.sensors[o.sensor].id,
                o.step,
                sk.sun_altitude_deg,
                sk.sun_azimuth_deg,
                o.value,
                after_sim[i],
                fitted_sim[i],
                truth_sim[i]
            )
        })
        .collect();
    let hidden = case.hidden_families();
    let selected: Vec<String> = effects.iter().map(|e| e.family().to_string()).collect();
    let ranking: Vec<String> = ex.ranking.iter().map(|c| c.family.clone()).collect();
    let hit = match hidden.len() {
        0 => selected.is_empty(),
        1 => {
            ranking.first() == hidden.first()
                && selected.first() == hidden.first()
                && (ex.ranking[0].delta_bic < -super::score::SIGNIFICANT)
        }
        _ => hidden.iter().all(|h| selected.contains(h)),
    };
    Ok(Outcome {
        name: case.name.clone(),
        hidden,
        selected,
        specs: ex.specs.clone(),
        unrefined,
        ranking,
        hit,
        rmse_before: ex.base.rmse_rel,
        rmse_after,
        rmse_noise,
        rmse_sim,
        rmse_fit_vs_apply,
        worst,
        seconds: t0.elapsed().as_secs_f64(),
    })
}
