//! # The `rcalib` commands as library calls
//!
//! Each command of `rcalib` is a typed configuration ([`Compare`], [`Explain`], [`Apply`],
//! [`Tmscan`], [`Synth`], [`Spectral`]) and one function that reads the files, computes and
//! writes the reports and text the tool prints (to `out`; notes to `err`). The command line
//! (clap, option spellings) is the tools layer's (`rdaylight::cli::rcalib`); a library user
//! fills the structs directly. Options are checked where they are turned into these
//! structs; what can only be checked against the files (effect names, sensor numbers) is
//! checked here, with the same one-line messages naming the option.

use crate::cases::{self, Climate, RoomKind};
use crate::compare::{Comparison, compare};
use crate::effects::Effect;
use crate::error::{Error, Result};
use crate::explain::{Explanation, explain, refined, simulate_applied};
use crate::formats::sensors::{Sensor, write_csv as write_sensors};
use crate::formats::weather::Weather;
use crate::measurements::{Columns, Measurements, write_csv};
use crate::model::Model;
use crate::session::{self, Loaded, Options};
use crate::simulate::Settings;
use crate::{apply, report, tmscan};
use rdaylight_base::io::write_atomically;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The measured case: model scene files, sensors, weather and readings.
#[derive(Debug, Clone, Default)]
pub struct Files {
    pub scene: Vec<String>,
    pub sensors: String,
    pub weather: String,
    pub measured: String,
    /// `--columns`: names of the readings' columns where they are not the accepted ones.
    pub columns: Columns,
}

impl Files {
    /// Every file read, for the reports' provenance.
    pub fn paths(&self) -> Vec<String> {
        let mut v = self.scene.clone();
        v.extend([
            self.sensors.clone(),
            self.weather.clone(),
            self.measured.clone(),
        ]);
        v
    }
}

/// Where the HTML report and the JSON data go (each optional).
#[derive(Debug, Clone, Default)]
pub struct Reports {
    pub html: Option<PathBuf>,
    pub json: Option<PathBuf>,
}

/// `rcalib compare`: simulate the measured steps and report where the model fails.
#[derive(Debug, Clone)]
pub struct Compare {
    pub files: Files,
    /// Another model (e.g. before `apply`) shown side by side; empty: none.
    pub before: Vec<String>,
    pub options: Options,
    pub reports: Reports,
}

/// `rcalib explain`: fit the candidate missing effects, rank and select them.
#[derive(Debug, Clone)]
pub struct Explain {
    pub files: Files,
    /// With the reflectance sensitivities (`Options::reflectance`).
    pub options: Options,
    /// Effect families to try (empty: all); see [`Explain::check`].
    pub families: Vec<String>,
    pub sensor_sigma: f64,
    /// Rounds of refinement by re-simulation.
    pub refine: usize,
    /// Where to write the selected effects as `--effect SPEC` arguments.
    pub effects_out: Option<PathBuf>,
    pub reports: Reports,
}

/// `rcalib apply`: the model with effects added as geometry or materials.
#[derive(Debug, Clone)]
pub struct Apply {
    pub scene: Vec<String>,
    pub sensors: String,
    /// Effect specs `NAME:params`, as `explain` prints them.
    pub effects: Vec<String>,
    /// With sensor-fault effects: the readings to correct and where to write them.
    pub measured: Option<String>,
    /// `--columns` of `measured`.
    pub columns: Columns,
    pub corrected: Option<PathBuf>,
    /// Surface classes of materials ([`crate::room::parse_classes`]).
    pub classes: Vec<(String, crate::room::SurfaceClass)>,
    /// The scene's destination (`None`: `out`).
    pub output: Option<PathBuf>,
}

/// `rcalib tmscan`: the seed's chapter-6 transmittance scan.
#[derive(Debug, Clone)]
pub struct Tmscan {
    pub files: Files,
    pub options: Options,
}

/// Weather of a synthetic case.
#[derive(Debug, Clone, PartialEq)]
pub enum SynthClimate {
    /// The synthetic clear-sky site ([`cases::sunny_weather`]).
    Sunny,
    /// London: the weather file given (the London Gatwick EPW).
    London(String),
}

impl SynthClimate {
    /// `--climate NAME` with `--weather FILE`, checked.
    pub fn parse(name: &str, weather: Option<&str>) -> Result<SynthClimate> {
        match (name, weather) {
            ("sunny", _) => Ok(SynthClimate::Sunny),
            ("london", Some(w)) => Ok(SynthClimate::London(w.to_string())),
            ("london", None) => Err(Error::Usage(
                "--climate london needs --weather (the London Gatwick EPW)".into(),
            )),
            (c, _) => Err(Error::Usage(format!(
                "--climate {c}: expected london or sunny"
            ))),
        }
    }
}

/// `--room NAME`, checked.
pub fn parse_room(name: &str) -> Result<RoomKind> {
    match name {
        "office" => Ok(RoomKind::Office),
        "deep" => Ok(RoomKind::Deep),
        "two-window" => Ok(RoomKind::TwoWindow),
        r => Err(Error::Usage(format!(
            "--room {r}: expected office, deep or two-window"
        ))),
    }
}

/// `rcalib synth`: a hidden-effect test case written to a directory.
#[derive(Debug, Clone)]
pub struct Synth {
    pub room: RoomKind,
    pub climate: SynthClimate,
    /// Hidden effect specs (empty: a control case).
    pub effects: Vec<String>,
    pub steps: usize,
    pub noise_seed: u64,
    pub out: PathBuf,
    /// Spectral readings (`-cs 18 -cw 380 780`) with a control sensor at the window.
    pub spectral: bool,
    /// With `spectral`: the room's sensors to keep (`--keep`, 1-based, comma separated).
    pub keep: Option<String>,
    /// Simulate the readings at `options` as given, not at converged settings.
    pub as_model: bool,
    pub options: Options,
}

/// `rcalib spectral`: the chapter-6 workflow on spectral readings.
#[derive(Debug, Clone)]
pub struct Spectral {
    pub files: Files,
    /// Channel response curves (CSV).
    pub response: Option<String>,
    /// Control sensor id (`None`: nearest a window).
    pub control: Option<String>,
    /// Simulated bands.
    pub channels: crate::radiometry::Channels,
    pub explain: bool,
    pub sensor_sigma: f64,
    pub effects_out: Option<PathBuf>,
    pub reports: Reports,
    /// Options of the simulation; the explanation adds the reflectance sensitivities.
    pub options: Options,
}

fn write_file(path: &Path, text: &str) -> Result<()> {
    write_atomically(path, |w| {
        w.write_all(text.as_bytes())
            .map_err(|e| Error::io(path.display().to_string(), e))
    })
}

fn stdout_err(e: std::io::Error) -> Error {
    Error::io("<stdout>", e)
}

fn load(files: &Files, scene: &[String]) -> Result<Loaded> {
    session::load(
        scene,
        &files.sensors,
        &files.weather,
        &files.measured,
        &files.columns,
    )
}

fn model_of(l: &Loaded, opts: &Options) -> Result<Model> {
    session::build(&l.scene, l.sensors.clone(), &l.weather, &l.readings, opts)
}

fn to_json<T: serde::Serialize>(doc: &T) -> Result<String> {
    serde_json::to_string_pretty(doc).map_err(|e| Error::Usage(format!("JSON: {e}")))
}

fn write_reports(
    comps: &[&Comparison],
    ex: Option<&Explanation>,
    to: &Reports,
    inputs: &[String],
) -> Result<()> {
    if let Some(p) = &to.html {
        write_file(p, &report::html(comps, ex, inputs)?)?;
    }
    if let Some(p) = &to.json {
        let doc = report::Json {
            comparisons: comps.to_vec(),
            explanation: ex,
        };
        write_file(p, &to_json(&doc)?)?;
    }
    Ok(())
}

/// The `apply with: rcalib apply ...` line for `specs`.
fn apply_hint(scene: &[String], sensors: &str, specs: &[String]) -> String {
    let effects: Vec<String> = specs.iter().map(|s| format!("--effect {s}")).collect();
    format!(
        "apply with: rcalib apply {} --sensors {} {}",
        scene.join(" "),
        sensors,
        effects.join(" ")
    )
}

/// `specs` as `--effect SPEC` arguments on one line, to `path`.
fn write_effects(path: &Path, specs: &[String]) -> Result<()> {
    let args: Vec<String> = specs.iter().map(|s| format!("--effect {s}")).collect();
    write_file(path, &format!("{}\n", args.join(" ")))
}

/// Run `rcalib compare`.
pub fn compare_run(c: &Compare, out: &mut dyn Write) -> Result<()> {
    let l = load(&c.files, &c.files.scene)?;
    let m = model_of(&l, &c.options)?;
    let after = compare(&m, &m.predict(&[]), &c.files.scene.join(" "));
    let before = if c.before.is_empty() {
        None
    } else {
        let lb = load(&c.files, &c.before)?;
        let mb = model_of(&lb, &c.options)?;
        Some(compare(&mb, &mb.predict(&[]), &c.before.join(" ")))
    };
    if let Some(b) = &before {
        write!(out, "{}", report::text_summary(b)).map_err(stdout_err)?;
    }
    write!(out, "{}", report::text_summary(&after)).map_err(stdout_err)?;
    if let Some(b) = &before {
        writeln!(
            out,
            "RMSE_rel {:.1} % -> {:.1} %, MBE_rel {:+.1} % -> {:+.1} %",
            b.overall.rmse_rel, after.overall.rmse_rel, b.overall.mbe_rel, after.overall.mbe_rel
        )
        .map_err(stdout_err)?;
    }
    let comps: Vec<&Comparison> = before.iter().chain(std::iter::once(&after)).collect();
    let mut inputs = c.files.paths();
    inputs.extend(c.before.iter().cloned());
    write_reports(&comps, None, &c.reports, &inputs)
}

impl Explain {
    /// Check the effect families (`--effects`).
    pub fn check(&self) -> Result<()> {
        let known = crate::effects::FAMILIES;
        match self.families.iter().find(|f| !known.contains(&f.as_str())) {
            Some(f) => Err(Error::Usage(format!(
                "--effects: unknown family '{f}'; expected some of {}",
                known.join(", ")
            ))),
            None => Ok(()),
        }
    }
}

/// Run `rcalib explain`.
pub fn explain_run(x: &Explain, out: &mut dyn Write) -> Result<()> {
    let l = load(&x.files, &x.files.scene)?;
    let m = model_of(&l, &x.options)?;
    x.check()?;
    let fams: Vec<&str> = x.families.iter().map(String::as_str).collect();
    let ex = explain(&m, &fams, x.sensor_sigma);
    let ex = refined(&m, ex, x.sensor_sigma, x.refine, &|e| {
        simulate_applied(&l.scene, &m, &l.weather, &l.readings, &x.options, e)
    })?;
    write!(out, "{}", report::explain_summary(&ex)).map_err(stdout_err)?;
    if !ex.specs.is_empty() {
        writeln!(
            out,
            "{}",
            apply_hint(&x.files.scene, &x.files.sensors, &ex.specs)
        )
        .map_err(stdout_err)?;
    }
    if let Some(p) = &x.effects_out {
        write_effects(p, &ex.specs)?;
    }
    let c = compare(&m, &m.predict(&[]), &x.files.scene.join(" "));
    let c2 = compare(&m, &ex.final_sim, "with the selected effects (predicted)");
    write_reports(&[&c, &c2], Some(&ex), &x.reports, &x.files.paths())
}

/// Effect specs parsed against the sensors and the room's windows.
fn parse_effects(
    specs: &[String],
    sensors: &[Sensor],
    room: &crate::room::Room,
) -> Result<Vec<Effect>> {
    let ids: Vec<String> = sensors.iter().map(|s| s.id.clone()).collect();
    let wids: Vec<String> = room.windows.iter().map(|w| w.id.clone()).collect();
    specs
        .iter()
        .map(|s| Effect::parse(s, &ids, &wids))
        .collect()
}

/// Run `rcalib apply`: the scene to `a.output` or `out`; a note on `err` when sensor
/// faults were given without readings to correct.
pub fn apply_run(a: &Apply, out: &mut dyn Write, err: &mut dyn Write) -> Result<()> {
    let scene = crate::scene::load(&a.scene, &crate::scene::LoadOptions::from_env())?;
    let sensors = crate::inputs::load_sensors(&a.sensors)?;
    let inside = crate::room::sensor_centroid(&sensors);
    let room = crate::room::Room::new(&scene, inside, &a.classes);
    let effects = parse_effects(&a.effects, &sensors, &room)?;
    let why = format!(
        "fitted to measurements by rcalib explain ({})",
        a.effects.join(" ")
    );
    let text = apply::apply(&scene, &room, &sensors, &effects, &why)?;
    let faults = effects
        .iter()
        .any(|e| matches!(e, Effect::SensorFault { .. }));
    match (&a.measured, &a.corrected) {
        (Some(m), Some(path)) => {
            let readings = Measurements::read_path_with(m, &a.columns)?;
            let ids: Vec<String> = sensors.iter().map(|s| s.id.clone()).collect();
            let fixed = apply::correct_readings(&readings.readings, &ids, &effects);
            write_atomically(path, |w| write_csv(w, &fixed))?;
        }
        _ if faults => {
            let _ = writeln!(
                err,
                "rcalib: sensor-fault changes the readings, not the model: add --measured IN \
                 --corrected OUT to write corrected readings"
            );
        }
        _ => {}
    }
    match &a.output {
        Some(p) => write_file(p, &text),
        None => out.write_all(text.as_bytes()).map_err(stdout_err),
    }
}

/// Run `rcalib tmscan`.
pub fn tmscan_run(t: &Tmscan, out: &mut dyn Write) -> Result<()> {
    let l = load(&t.files, &t.files.scene)?;
    let m = model_of(&l, &t.options)?;
    let (rows, best) = tmscan::scan(&m);
    let mut text =
        String::from("option          factor  transmissivity   MAE (lx)  MBE_rel %  RMSE_rel %\n");
    for (i, r) in rows.iter().enumerate() {
        text.push_str(&format!(
            "{:14} {:7.3} {:15.3} {:10.1} {:+10.1} {:11.1}{}\n",
            r.name,
            r.factor,
            r.transmissivity,
            r.mae,
            r.stats.mbe_rel,
            r.stats.rmse_rel,
            if i == best {
                "  <- lowest MAE (Eq. 6.1)"
            } else {
                ""
            }
        ));
    }
    text.push_str(&format!(
        "apply with: rcalib apply {} --sensors {} --effect transmittance:{:.4}\n",
        t.files.scene.join(" "),
        t.files.sensors,
        rows[best].factor
    ));
    out.write_all(text.as_bytes()).map_err(stdout_err)
}

impl Synth {
    /// The settings the readings are simulated with: converged ([`Settings::truth`],
    /// keeping `-m`) unless `as_model`.
    fn truth_options(&self) -> Options {
        let mut opts = self.options.clone();
        if !self.as_model {
            opts.settings = Settings {
                mf: opts.settings.mf,
                ..Settings::truth()
            };
        }
        opts
    }

    fn climate(&self) -> Climate {
        match self.climate {
            SynthClimate::Sunny => Climate::Sunny,
            SynthClimate::London(_) => Climate::London,
        }
    }

    /// The sensors of a spectral case: the control sensor at the window, then the room's
    /// sensors (or those `keep` names).
    fn spectral_sensors(&self, room: &crate::room::Room, all: Vec<Sensor>) -> Result<Vec<Sensor>> {
        let mut sensors: Vec<Sensor> = crate::spectral::case::window_control(room)
            .into_iter()
            .collect();
        let Some(k) = &self.keep else {
            sensors.extend(all);
            return Ok(sensors);
        };
        for item in k.split(',') {
            let i: usize = item.trim().parse().map_err(|_| {
                Error::Usage(format!("--keep '{item}': expected 1-based sensor numbers"))
            })?;
            let s = all.get(i.wrapping_sub(1)).ok_or_else(|| {
                Error::Usage(format!("--keep {i}: the room has {} sensors", all.len()))
            })?;
            sensors.push(s.clone());
        }
        Ok(sensors)
    }
}

/// What a synthetic case writes besides its readings.
struct CaseFiles<'a> {
    model_text: &'a str,
    truth_header: String,
    truth_text: &'a str,
    sensors: &'a [Sensor],
    weather: &'a Weather,
    steps: &'a [usize],
}

fn write_case(dir: &Path, f: &CaseFiles) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir.display().to_string(), e))?;
    write_file(&dir.join("model.rad"), f.model_text)?;
    write_file(
        &dir.join("truth.rad"),
        &format!("{}\n{}", f.truth_header, f.truth_text),
    )?;
    write_atomically(&dir.join("sensors.csv"), |w| write_sensors(w, f.sensors))?;
    write_file(
        &dir.join("weather.wea"),
        &crate::simulate::subset_wea(f.weather, f.steps),
    )
}

/// Run `rcalib synth`: write the case to `s.out` and say so on `out`.
pub fn synth_run(s: &Synth, out: &mut dyn Write) -> Result<()> {
    let weather = match &s.climate {
        SynthClimate::Sunny => cases::sunny_weather(),
        SynthClimate::London(w) => Weather::read_path(w)?,
    };
    let (text, sensors) = cases::room(s.room);
    let scene = crate::scene::parse_str(
        &text,
        "<room>",
        Path::new(""),
        &crate::scene::LoadOptions::default(),
    )?;
    let room = cases::room_of(&scene, &sensors);
    let hidden = parse_effects(&s.effects, &sensors, &room)?;
    let opts = s.truth_options();
    if s.spectral {
        return synth_spectral(s, &room, weather, sensors, hidden, &opts, out);
    }
    let case = cases::generate(
        &format!("{}-{}", s.room.name(), s.climate().name()),
        s.room,
        weather,
        hidden,
        s.steps,
        s.noise_seed,
        &opts,
    )?;
    let mut idx: Vec<usize> = case.readings.iter().map(|b| b.step).collect();
    idx.sort_unstable();
    idx.dedup();
    write_case(
        &s.out,
        &CaseFiles {
            model_text: &case.model_text,
            truth_header: format!(
                "# truth of synthetic case {} (hidden: {})",
                case.name,
                s.effects.join(" ")
            ),
            truth_text: &case.truth_text,
            sensors: &case.sensors,
            weather: &case.weather,
            steps: &idx,
        },
    )?;
    write_atomically(&s.out.join("measured.csv"), |w| {
        write_csv(w, &case.csv_readings())
    })?;
    writeln!(
        out,
        "wrote {}: model.rad truth.rad sensors.csv weather.wea measured.csv ({} readings, {} sensors, {} steps)",
        s.out.display(),
        case.readings.len(),
        case.sensors.len(),
        idx.len()
    )
    .map_err(stdout_err)
}

fn synth_spectral(
    s: &Synth,
    room: &crate::room::Room,
    weather: Weather,
    room_sensors: Vec<Sensor>,
    hidden: Vec<Effect>,
    opts: &Options,
    out: &mut dyn Write,
) -> Result<()> {
    use crate::spectral::{case, readings};
    let sensors = s.spectral_sensors(room, room_sensors)?;
    let c = case::generate(
        &format!("{}-{}-spectral", s.room.name(), s.climate().name()),
        s.room,
        sensors,
        weather,
        hidden,
        s.steps,
        s.noise_seed,
        opts,
        &crate::spectral::seed_channels(),
    )?;
    let (idx, _) = crate::spectral::measured_steps(&c.bound);
    write_case(
        &s.out,
        &CaseFiles {
            model_text: &c.model_text,
            truth_header: format!(
                "# truth of synthetic spectral case {} (hidden: {})",
                c.name,
                s.effects.join(" ")
            ),
            truth_text: &c.truth_text,
            sensors: &c.sensors,
            weather: &c.weather,
            steps: &idx,
        },
    )?;
    let r = c.readings();
    write_atomically(&s.out.join("measured.csv"), |w| {
        readings::write_csv(w, &r.names, &r.readings)
    })?;
    writeln!(
        out,
        "wrote {}: model.rad truth.rad sensors.csv weather.wea measured.csv ({} spectral readings, {} channels, {} sensors, {} steps)",
        s.out.display(),
        c.bound.len(),
        r.names.len(),
        c.sensors.len(),
        idx.len()
    )
    .map_err(stdout_err)
}

/// Run `rcalib spectral`.
pub fn spectral_run(a: &Spectral, out: &mut dyn Write) -> Result<()> {
    use crate::spectral::{self, explain as sx, scan};
    let f = &a.files;
    let inp = spectral::load(
        &f.scene,
        &f.sensors,
        &f.weather,
        &f.measured,
        a.response.as_deref(),
        &a.channels,
    )?;
    let control = inp.control(a.control.as_deref())?;
    let sm = inp.model(&a.options)?;
    let room = crate::room::Room::new(&inp.scene, crate::room::sensor_centroid(&inp.sensors), &[]);
    let depth = |s: usize| inp.depth(&room, s);
    let sc = scan::scan(&sm, control, &depth);
    write!(out, "{}", scan::text(&sc)).map_err(stdout_err)?;
    let ex = if a.explain {
        let opts = Options {
            reflectance: true,
            ..a.options.clone()
        };
        let pm = inp.photopic(&sm, &opts)?;
        let ex = sx::explain(&pm, &sm, &[], a.sensor_sigma);
        write!(out, "{}", sx::text(&ex)).map_err(stdout_err)?;
        if !ex.specs.is_empty() {
            writeln!(out, "{}", apply_hint(&f.scene, &f.sensors, &ex.specs)).map_err(stdout_err)?;
        }
        Some(ex)
    } else {
        writeln!(
            out,
            "{}",
            apply_hint(&f.scene, &f.sensors, std::slice::from_ref(&sc.effect))
        )
        .map_err(stdout_err)?;
        None
    };
    if let Some(p) = &a.effects_out {
        let specs = match &ex {
            Some(e) => e.specs.clone(),
            None => vec![sc.effect.clone()],
        };
        write_effects(p, &specs)?;
    }
    if let Some(p) = &a.reports.html {
        write_file(p, &scan::html(&sc, ex.as_ref().map(sx::text).as_deref()))?;
    }
    if let Some(p) = &a.reports.json {
        let doc = serde_json::json!({ "scan": sc, "explanation": ex });
        write_file(p, &to_json(&doc)?)?;
    }
    Ok(())
}
