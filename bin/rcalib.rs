//! `rcalib`: compare a daylight model with measured illuminances, explain the difference by
//! missing physical effects, apply them to the model, and generate hidden-effect test cases.
//! The physics is in `rdaylight::calib`; this file parses options, reads and writes files.

use clap::{Args, Parser, Subcommand};
use rdaylight::Error;
use rdaylight::calib::cases::{self, Climate, RoomKind};
use rdaylight::calib::compare::{Comparison, compare};
use rdaylight::calib::effects::Effect;
use rdaylight::calib::explain::{Explanation, explain, refined, simulate_applied};
use rdaylight::calib::measurements::{Measurements, write_csv};
use rdaylight::calib::model::Model;
use rdaylight::calib::room::parse_classes;
use rdaylight::calib::score::DEFAULT_SENSOR_SIGMA;
use rdaylight::calib::session::{self, Loaded, Options};
use rdaylight::calib::simulate::Settings;
use rdaylight::calib::{apply, report, tmscan};
use rdaylight::formats::sensors::write_csv as write_sensors;
use rdaylight::formats::weather::Weather;
use std::path::{Path, PathBuf};

const EXAMPLES: &str = "\
Examples (the bundled case, examples/calib):
  rcalib compare examples/calib/model.rad --sensors examples/calib/sensors.csv \\
      --weather examples/calib/weather.wea --measured examples/calib/measured.csv \\
      --report before.html
  rcalib explain examples/calib/model.rad --sensors ... --weather ... --measured ... \\
      --report explain.html
  rcalib apply examples/calib/model.rad --sensors examples/calib/sensors.csv \\
      --effect transmittance:0.70 > calibrated.rad
  rcalib compare calibrated.rad --before examples/calib/model.rad --sensors ... \\
      --weather ... --measured ... --report after.html
  rcalib tmscan model.rad --sensors ... --weather ... --measured ...   (seed ch. 6)
  rcalib synth --room deep --climate sunny --effect walls:0.5 --out case/
  rcalib spectral model.rad --sensors ... --weather ... --measured spectral.csv --explain
      (spectral readings: month,day,hour,sensor,410nm,...; seed ch. 6 + glazing tint)

Readings CSV: month,day,hour,sensor,lux (hour in the weather file's convention, e.g.
12.5); sensors: .pts (ids = line numbers) or CSV id,x,y,z,dx,dy,dz; weather: .wea or
.epw covering the measured time steps (its DNI/DHI are the measured conditions).
Coefficients are cached in --cache (default .rcalib-cache): re-runs trace nothing.";

#[derive(Parser)]
#[command(
    name = "rcalib",
    version,
    about = "Compare a daylight model with measurements, explain the error by missing \
             physical effects, apply them and watch the error fall",
    after_help = EXAMPLES
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Simulate the measured time steps and report where the model fails.
    Compare(CompareArgs),
    /// Fit candidate missing effects, rank them and select the significant ones.
    Explain(ExplainArgs),
    /// Write the model with effects added as geometry/materials (to standard output).
    Apply(ApplyArgs),
    /// The seed's chapter-6 procedure: scan window transmittance options by MAE.
    Tmscan(CommonArgs),
    /// Generate a hidden-effect test case (model, truth, sensors, weather, readings).
    Synth(SynthArgs),
    /// Spectral readings: the seed's chapter-6 workflow (window options by 18-channel MAE at
    /// the control sensor, Table 6.4 for Ev, m-EDI, M/P), optionally explain with the tint.
    Spectral(SpectralArgs),
}

#[derive(Args)]
struct SpectralArgs {
    /// Scene files of the model (.rad).
    #[arg(required = true)]
    scene: Vec<String>,
    /// Sensors: .pts or CSV with ids.
    #[arg(long)]
    sensors: String,
    /// Weather of the measurement period (.wea or .epw).
    #[arg(long)]
    weather: String,
    /// Spectral readings: month,day,hour,sensor,<one column per channel, e.g. 410nm>.
    #[arg(long)]
    measured: String,
    /// Channel response curves: wavelength,<channel>,... (default: each channel is the
    /// simulated band containing its centre wavelength).
    #[arg(long)]
    response: Option<String>,
    /// Control sensor id (default: the sensor nearest a window).
    #[arg(long)]
    control: Option<String>,
    /// Simulated bands (Radiance -cs).
    #[arg(long = "cs", default_value_t = 18)]
    cs: usize,
    /// Simulated wavelength range in nm (Radiance -cw).
    #[arg(long = "cw", num_args = 2, default_values_t = [380.0, 780.0])]
    cw: Vec<f64>,
    /// Also explain: fit the photopic effects and the glazing tint, print `--effect`s.
    #[arg(long)]
    explain: bool,
    /// Assumed per-sensor spread for --explain (relative).
    #[arg(long, default_value_t = DEFAULT_SENSOR_SIGMA)]
    sensor_sigma: f64,
    /// Write the selected effects here as `--effect SPEC` arguments for `rcalib apply`
    /// (with --explain; else the selected window option).
    #[arg(long)]
    effects_out: Option<PathBuf>,
    /// Write the tables as HTML here.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Write the tables (and the explanation) as JSON here.
    #[arg(long)]
    json: Option<PathBuf>,
    #[command(flatten)]
    sim: SimArgs,
}

#[derive(Args, Clone)]
struct SimArgs {
    /// Ambient bounces of the coefficient runs (Radiance -ab).
    #[arg(long = "ab", default_value_t = Settings::model().ab)]
    ab: u32,
    /// Samples per sensor (Radiance -ad).
    #[arg(long = "ad", default_value_t = Settings::model().ad)]
    ad: usize,
    /// Path weight limit (Radiance -lw).
    #[arg(long = "lw", default_value_t = Settings::model().lw)]
    lw: f64,
    /// Sample each sensor until its relative standard error is below this (rdc
    /// --target-se --se-row; 0: exactly -ad samples, as Radiance).
    #[arg(long = "target-se", default_value_t = Settings::model().target_se.unwrap_or(0.0))]
    target_se: f64,
    /// Cap on samples per sensor with --target-se.
    #[arg(long = "max-samples", default_value_t = Settings::model().max_samples)]
    max_samples: usize,
    /// Reinhart sky subdivision (gendaymtx -m; 1 = Tregenza).
    #[arg(short = 'm', default_value_t = 1)]
    mf: usize,
    /// Random seed of the coefficient runs.
    #[arg(short = 's', long = "seed", default_value_t = 1)]
    seed: u64,
    /// Coefficient cache directory.
    #[arg(long, default_value = ".rcalib-cache")]
    cache: PathBuf,
    /// Do not read or write the cache.
    #[arg(long)]
    no_cache: bool,
    /// Surface classes of materials: material=walls|ceiling|floor|ground,... (default: by
    /// keywords in material names).
    #[arg(long)]
    classes: Option<String>,
}

impl SimArgs {
    fn options(&self, reflectance: bool) -> Result<Options, Error> {
        Ok(Options {
            settings: Settings {
                ab: self.ab,
                ad: self.ad,
                lw: self.lw,
                mf: self.mf,
                seed: self.seed,
                target_se: (self.target_se > 0.0).then_some(self.target_se),
                max_samples: self.max_samples,
            },
            cache: (!self.no_cache).then(|| self.cache.clone()),
            classes: match &self.classes {
                Some(c) => parse_classes(c)?,
                None => Vec::new(),
            },
            reflectance,
        })
    }
}

#[derive(Args, Clone)]
struct CommonArgs {
    /// Scene files of the model (.rad).
    #[arg(required = true)]
    scene: Vec<String>,
    /// Sensors: .pts or CSV with ids.
    #[arg(long)]
    sensors: String,
    /// Weather of the measurement period (.wea or .epw).
    #[arg(long)]
    weather: String,
    /// Readings: month,day,hour,sensor,lux.
    #[arg(long)]
    measured: String,
    #[command(flatten)]
    sim: SimArgs,
}

#[derive(Args)]
struct CompareArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Also simulate this model (e.g. the one before apply) and show both side by side.
    #[arg(long)]
    before: Vec<String>,
    /// Write the HTML report here.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Write the figures' data as JSON here.
    #[arg(long)]
    json: Option<PathBuf>,
}

#[derive(Args)]
struct ExplainArgs {
    #[command(flatten)]
    common: CommonArgs,
    /// Only these effect families (comma separated; default all).
    #[arg(long)]
    effects: Option<String>,
    /// Assumed per-sensor spread (calibration class + model noise), relative.
    #[arg(long, default_value_t = DEFAULT_SENSOR_SIGMA)]
    sensor_sigma: f64,
    /// Write the selected effects here as `--effect SPEC` arguments for `rcalib apply`
    /// (empty when nothing significant is missing).
    #[arg(long)]
    effects_out: Option<PathBuf>,
    /// Rounds of refinement: apply the kept effects, re-simulate, and fit them again with
    /// the coefficient model corrected by that re-simulation (0: none).
    #[arg(long, default_value_t = cases::REFINE_ROUNDS)]
    refine: usize,
    #[arg(long)]
    report: Option<PathBuf>,
    #[arg(long)]
    json: Option<PathBuf>,
}

#[derive(Args)]
struct ApplyArgs {
    /// Scene files of the model (.rad).
    #[arg(required = true)]
    scene: Vec<String>,
    /// Sensors (ids for local obstructions and sensor faults).
    #[arg(long)]
    sensors: String,
    /// Effect NAME:params (repeatable), as `rcalib explain` prints them.
    #[arg(long = "effect", required = true)]
    effects: Vec<String>,
    /// With sensor-fault effects: the readings to correct ...
    #[arg(long)]
    measured: Option<String>,
    /// ... and where to write the corrected readings.
    #[arg(long)]
    corrected: Option<PathBuf>,
    /// Surface classes (as for explain).
    #[arg(long)]
    classes: Option<String>,
    /// Write here instead of standard output.
    #[arg(short = 'o')]
    output: Option<PathBuf>,
}

#[derive(Args)]
struct SynthArgs {
    /// office (6 x 8 m, south window), deep (3.5 x 10 m), two-window (6 x 6 m, S + E).
    #[arg(long, default_value = "office")]
    room: String,
    /// london (needs --weather with the London EPW) or sunny (synthetic clear-sky site).
    #[arg(long, default_value = "sunny")]
    climate: String,
    /// Weather file for the london climate.
    #[arg(long)]
    weather: Option<String>,
    /// Hidden effects NAME:params (none: a control case).
    #[arg(long = "effect")]
    effects: Vec<String>,
    /// Measured time steps.
    #[arg(long, default_value_t = 30)]
    steps: usize,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
    noise_seed: u64,
    /// Output directory (model.rad, truth.rad, sensors.csv, weather.wea, measured.csv).
    #[arg(long)]
    out: PathBuf,
    /// Spectral readings: one channel per band of -cs 18 -cw 380 780 (W m-2 nm-1), and a
    /// control sensor inside the first window (as the seed's); effects may include
    /// tint:SCALE,SLOPE,CURVATURE.
    #[arg(long)]
    spectral: bool,
    /// With --spectral: keep only these sensors of the room (1-based, comma separated).
    #[arg(long)]
    keep: Option<String>,
    /// Simulate the readings with the simulation options below as given. Without it they
    /// come from converged settings (-ab 12 -ad 1024 -lw 2e-5 --target-se 0.005
    /// --max-samples 262144 -s 7), so that their only error is the sensor noise; -m,
    /// --cache and --classes apply either way.
    #[arg(long)]
    as_model: bool,
    #[command(flatten)]
    sim: SimArgs,
}

fn main() {
    rdaylight::cli::run("rcalib", real_main)
}

/// Radiance spellings (-ab 5) to the long options clap knows (--ab 5).
fn radiance_spellings(args: impl Iterator<Item = String>) -> Vec<String> {
    args.map(|a| match a.as_str() {
        "-ab" | "-ad" | "-lw" | "-cs" | "-cw" => format!("-{a}"),
        _ => a,
    })
    .collect()
}

fn real_main() -> Result<(), Error> {
    let cli = match Cli::try_parse_from(radiance_spellings(std::env::args())) {
        Ok(c) => c,
        Err(e) if !e.use_stderr() => e.exit(),
        Err(e) => {
            let text = e.to_string();
            let first = text.lines().next().unwrap_or("bad command line");
            return Err(Error::Usage(
                first.trim_start_matches("error: ").to_string(),
            ));
        }
    };
    match cli.cmd {
        Cmd::Compare(a) => cmd_compare(a),
        Cmd::Explain(a) => cmd_explain(a),
        Cmd::Apply(a) => cmd_apply(a),
        Cmd::Tmscan(a) => cmd_tmscan(a),
        Cmd::Synth(a) => cmd_synth(a),
        Cmd::Spectral(a) => cmd_spectral(a),
    }
}

fn load(c: &CommonArgs, scene: &[String]) -> Result<Loaded, Error> {
    session::load(scene, &c.sensors, &c.weather, &c.measured)
}

fn model_of(l: &Loaded, opts: &Options) -> Result<Model, Error> {
    session::build(&l.scene, l.sensors.clone(), &l.weather, &l.readings, opts)
}

fn write_file(path: &Path, text: &str) -> Result<(), Error> {
    rdaylight::io::write_atomically(path, |w| {
        w.write_all(text.as_bytes())
            .map_err(|e| Error::io(path.display().to_string(), e))
    })
}

fn write_reports(
    comps: &[&Comparison],
    ex: Option<&Explanation>,
    html: &Option<PathBuf>,
    json: &Option<PathBuf>,
) -> Result<(), Error> {
    if let Some(p) = html {
        write_file(p, &report::html(comps, ex))?;
    }
    if let Some(p) = json {
        let doc = report::Json {
            comparisons: comps.to_vec(),
            explanation: ex,
        };
        let text =
            serde_json::to_string_pretty(&doc).map_err(|e| Error::Usage(format!("JSON: {e}")))?;
        write_file(p, &text)?;
    }
    Ok(())
}

fn cmd_compare(a: CompareArgs) -> Result<(), Error> {
    let opts = a.common.sim.options(false)?;
    let l = load(&a.common, &a.common.scene)?;
    let m = model_of(&l, &opts)?;
    let after = compare(&m, &m.predict(&[]), &a.common.scene.join(" "));
    let before = if a.before.is_empty() {
        None
    } else {
        let lb = load(&a.common, &a.before)?;
        let mb = model_of(&lb, &opts)?;
        Some(compare(&mb, &mb.predict(&[]), &a.before.join(" ")))
    };
    if let Some(b) = &before {
        print!("{}", report::text_summary(b));
    }
    print!("{}", report::text_summary(&after));
    if let Some(b) = &before {
        println!(
            "RMSE_rel {:.1} % -> {:.1} %, MBE_rel {:+.1} % -> {:+.1} %",
            b.overall.rmse_rel, after.overall.rmse_rel, b.overall.mbe_rel, after.overall.mbe_rel
        );
    }
    let comps: Vec<&Comparison> = before.iter().chain(std::iter::once(&after)).collect();
    write_reports(&comps, None, &a.report, &a.json)
}

fn cmd_explain(a: ExplainArgs) -> Result<(), Error> {
    let opts = a.common.sim.options(true)?;
    let l = load(&a.common, &a.common.scene)?;
    let m = model_of(&l, &opts)?;
    let fams: Vec<String> = a
        .effects
        .as_deref()
        .map(|s| s.split(',').map(|x| x.trim().to_string()).collect())
        .unwrap_or_default();
    for f in &fams {
        if !rdaylight::calib::effects::FAMILIES.contains(&f.as_str()) {
            return Err(Error::Usage(format!(
                "--effects: unknown family '{f}'; expected some of {}",
                rdaylight::calib::effects::FAMILIES.join(", ")
            )));
        }
    }
    let fam_refs: Vec<&str> = fams.iter().map(String::as_str).collect();
    let ex = explain(&m, &fam_refs, a.sensor_sigma);
    let ex = refined(&m, ex, a.sensor_sigma, a.refine, &|e| {
        simulate_applied(&l.scene, &m, &l.weather, &l.readings, &opts, e)
    })?;
    print!("{}", report::explain_summary(&ex));
    if !ex.specs.is_empty() {
        println!(
            "apply with: rcalib apply {} --sensors {} {}",
            a.common.scene.join(" "),
            a.common.sensors,
            ex.specs
                .iter()
                .map(|s| format!("--effect {s}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    if let Some(p) = &a.effects_out {
        let args: Vec<String> = ex.specs.iter().map(|s| format!("--effect {s}")).collect();
        write_file(p, &format!("{}\n", args.join(" ")))?;
    }
    let c = compare(&m, &m.predict(&[]), &a.common.scene.join(" "));
    let effects: Vec<Effect> = ex.selected.iter().map(|c| c.effect.clone()).collect();
    let c2 = compare(
        &m,
        &m.predict(&effects),
        "with the selected effects (coefficient model)",
    );
    write_reports(&[&c, &c2], Some(&ex), &a.report, &a.json)
}

fn cmd_apply(a: ApplyArgs) -> Result<(), Error> {
    let scene = rdaylight::scene::load(&a.scene, &rdaylight::scene::LoadOptions::from_env())?;
    let sensors = rdaylight::calib::inputs::load_sensors(&a.sensors)?;
    let classes = match &a.classes {
        Some(c) => parse_classes(c)?,
        None => Vec::new(),
    };
    let inside = rdaylight::calib::room::sensor_centroid(&sensors);
    let room = rdaylight::calib::room::Room::new(&scene, inside, &classes);
    let ids: Vec<String> = sensors.iter().map(|s| s.id.clone()).collect();
    let wids: Vec<String> = room.windows.iter().map(|w| w.id.clone()).collect();
    let effects = a
        .effects
        .iter()
        .map(|s| Effect::parse(s, &ids, &wids))
        .collect::<Result<Vec<_>, _>>()?;
    let why = format!(
        "fitted to measurements by rcalib explain ({})",
        a.effects.join(" ")
    );
    let text = apply::apply(&scene, &room, &sensors, &effects, &why)?;
    let faults = effects
        .iter()
        .any(|e| matches!(e, Effect::SensorFault { .. }));
    match (&a.measured, &a.corrected) {
        (Some(m), Some(out)) => {
            let readings = Measurements::read_path(m)?;
            let fixed = apply::correct_readings(&readings.readings, &ids, &effects);
            rdaylight::io::write_atomically(out, |w| write_csv(w, &fixed))?;
        }
        _ if faults => eprintln!(
            "rcalib: sensor-fault changes the readings, not the model: add --measured IN \
             --corrected OUT to write corrected readings"
        ),
        _ => {}
    }
    match &a.output {
        Some(p) => write_file(p, &text),
        None => {
            use std::io::Write;
            std::io::stdout()
                .write_all(text.as_bytes())
                .map_err(|e| Error::io("<stdout>", e))
        }
    }
}

fn cmd_tmscan(a: CommonArgs) -> Result<(), Error> {
    let opts = a.sim.options(false)?;
    let l = load(&a, &a.scene)?;
    let m = model_of(&l, &opts)?;
    let (rows, best) = tmscan::scan(&m);
    println!("option          factor  transmissivity   MAE (lx)  MBE_rel %  RMSE_rel %");
    for (i, r) in rows.iter().enumerate() {
        println!(
            "{:14} {:7.3} {:15.3} {:10.1} {:+10.1} {:11.1}{}",
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
        );
    }
    println!(
        "apply with: rcalib apply {} --sensors {} --effect transmittance:{:.4}",
        a.scene.join(" "),
        a.sensors,
        rows[best].factor
    );
    Ok(())
}

fn cmd_synth(a: SynthArgs) -> Result<(), Error> {
    let kind = match a.room.as_str() {
        "office" => RoomKind::Office,
        "deep" => RoomKind::Deep,
        "two-window" => RoomKind::TwoWindow,
        r => {
            return Err(Error::Usage(format!(
                "--room {r}: expected office, deep or two-window"
            )));
        }
    };
    let weather = match (a.climate.as_str(), &a.weather) {
        ("sunny", _) => cases::sunny_weather(),
        ("london", Some(w)) => Weather::read_path(w)?,
        ("london", None) => {
            return Err(Error::Usage(
                "--climate london needs --weather (the London Gatwick EPW)".into(),
            ));
        }
        (c, _) => {
            return Err(Error::Usage(format!(
                "--climate {c}: expected london or sunny"
            )));
        }
    };
    let climate = if a.climate == "sunny" {
        Climate::Sunny
    } else {
        Climate::London
    };
    let (text, sensors) = cases::room(kind);
    let scene = rdaylight::scene::parse_str(
        &text,
        "<room>",
        Path::new(""),
        &rdaylight::scene::LoadOptions::default(),
    )?;
    let room = cases::room_of(&scene, &sensors);
    let ids: Vec<String> = sensors.iter().map(|s| s.id.clone()).collect();
    let wids: Vec<String> = room.windows.iter().map(|w| w.id.clone()).collect();
    let hidden = a
        .effects
        .iter()
        .map(|s| Effect::parse(s, &ids, &wids))
        .collect::<Result<Vec<_>, _>>()?;
    let mut opts = a.sim.options(false)?;
    if !a.as_model {
        opts.settings = Settings {
            mf: opts.settings.mf,
            ..Settings::truth()
        };
    }
    if a.spectral {
        return synth_spectral(&a, kind, climate, weather, &scene, sensors, hidden, &opts);
    }
    let case = cases::generate(
        &format!("{}-{}", kind.name(), climate.name()),
        kind,
        weather,
        hidden,
        a.steps,
        a.noise_seed,
        &opts.settings,
        opts.cache.clone(),
    )?;
    std::fs::create_dir_all(&a.out).map_err(|e| Error::io(a.out.display().to_string(), e))?;
    write_file(&a.out.join("model.rad"), &case.model_text)?;
    write_file(
        &a.out.join("truth.rad"),
        &format!(
            "# truth of synthetic case {} (hidden: {})\n{}",
            case.name,
            a.effects.join(" "),
            case.truth_text
        ),
    )?;
    rdaylight::io::write_atomically(&a.out.join("sensors.csv"), |w| {
        write_sensors(w, &case.sensors)
    })?;
    let idx: Vec<usize> = {
        let mut v: Vec<usize> = case.readings.iter().map(|b| b.step).collect();
        v.sort_unstable();
        v.dedup();
        v
    };
    write_file(
        &a.out.join("weather.wea"),
        &rdaylight::calib::simulate::subset_wea(&case.weather, &idx),
    )?;
    rdaylight::io::write_atomically(&a.out.join("measured.csv"), |w| {
        write_csv(w, &case.csv_readings())
    })?;
    println!(
        "wrote {}: model.rad truth.rad sensors.csv weather.wea measured.csv ({} readings, {} sensors, {} steps)",
        a.out.display(),
        case.readings.len(),
        case.sensors.len(),
        idx.len()
    );
    Ok(())
}

fn cmd_spectral(a: SpectralArgs) -> Result<(), Error> {
    use rdaylight::calib::spectral::{self, explain as sx, scan};
    let (lo, hi) = match a.cw.as_slice() {
        [lo, hi] => (*lo, *hi),
        _ => return Err(Error::Usage("-cw: expected MIN MAX in nm".into())),
    };
    let ch = rdaylight::radiometry::Channels::spectral(a.cs, lo, hi)?;
    let inp = spectral::load(
        &a.scene,
        &a.sensors,
        &a.weather,
        &a.measured,
        a.response.as_deref(),
        &ch,
    )?;
    let control = inp.control(a.control.as_deref())?;
    let opts = a.sim.options(false)?;
    let sm = inp.model(&opts)?;
    let room = rdaylight::calib::room::Room::new(
        &inp.scene,
        rdaylight::calib::room::sensor_centroid(&inp.sensors),
        &[],
    );
    let depth = |s: usize| inp.depth(&room, s);
    let sc = scan::scan(&sm, control, &depth);
    print!("{}", scan::text(&sc));
    let ex = if a.explain {
        let pm = inp.photopic(&sm, &a.sim.options(true)?)?;
        let ex = sx::explain(&pm, &sm, &[], a.sensor_sigma);
        print!("{}", sx::text(&ex));
        if !ex.specs.is_empty() {
            println!(
                "apply with: rcalib apply {} --sensors {} {}",
                a.scene.join(" "),
                a.sensors,
                ex.specs
                    .iter()
                    .map(|s| format!("--effect {s}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            );
        }
        Some(ex)
    } else {
        println!(
            "apply with: rcalib apply {} --sensors {} --effect {}",
            a.scene.join(" "),
            a.sensors,
            sc.effect
        );
        None
    };
    if let Some(p) = &a.effects_out {
        let specs = match &ex {
            Some(e) => e.specs.clone(),
            None => vec![sc.effect.clone()],
        };
        let args: Vec<String> = specs.iter().map(|s| format!("--effect {s}")).collect();
        write_file(p, &format!("{}\n", args.join(" ")))?;
    }
    if let Some(p) = &a.report {
        write_file(p, &scan::html(&sc, ex.as_ref().map(sx::text).as_deref()))?;
    }
    if let Some(p) = &a.json {
        let doc = serde_json::json!({ "scan": sc, "explanation": ex });
        let text =
            serde_json::to_string_pretty(&doc).map_err(|e| Error::Usage(format!("JSON: {e}")))?;
        write_file(p, &text)?;
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn synth_spectral(
    a: &SynthArgs,
    kind: RoomKind,
    climate: Climate,
    weather: Weather,
    scene: &rdaylight::scene::Scene,
    room_sensors: Vec<rdaylight::formats::sensors::Sensor>,
    hidden: Vec<Effect>,
    opts: &Options,
) -> Result<(), Error> {
    use rdaylight::calib::spectral::{case, readings};
    let room = cases::room_of(scene, &room_sensors);
    let mut sensors: Vec<_> = case::window_control(&room).into_iter().collect();
    match &a.keep {
        Some(k) => {
            for item in k.split(',') {
                let i: usize = item.trim().parse().map_err(|_| {
                    Error::Usage(format!("--keep '{item}': expected 1-based sensor numbers"))
                })?;
                let s = room_sensors.get(i.wrapping_sub(1)).ok_or_else(|| {
                    Error::Usage(format!(
                        "--keep {i}: the room has {} sensors",
                        room_sensors.len()
                    ))
                })?;
                sensors.push(s.clone());
            }
        }
        None => sensors.extend(room_sensors),
    }
    let c = case::generate(
        &format!("{}-{}-spectral", kind.name(), climate.name()),
        kind,
        sensors,
        weather,
        hidden,
        a.steps,
        a.noise_seed,
        &opts.settings,
        opts.cache.clone(),
        &rdaylight::calib::spectral::seed_channels(),
    )?;
    std::fs::create_dir_all(&a.out).map_err(|e| Error::io(a.out.display().to_string(), e))?;
    write_file(&a.out.join("model.rad"), &c.model_text)?;
    write_file(
        &a.out.join("truth.rad"),
        &format!(
            "# truth of synthetic spectral case {} (hidden: {})\n{}",
            c.name,
            a.effects.join(" "),
            c.truth_text
        ),
    )?;
    rdaylight::io::write_atomically(&a.out.join("sensors.csv"), |w| write_sensors(w, &c.sensors))?;
    let (idx, _) = rdaylight::calib::spectral::measured_steps(&c.bound);
    write_file(
        &a.out.join("weather.wea"),
        &rdaylight::calib::simulate::subset_wea(&c.weather, &idx),
    )?;
    let r = c.readings();
    rdaylight::io::write_atomically(&a.out.join("measured.csv"), |w| {
        readings::write_csv(w, &r.names, &r.readings)
    })?;
    println!(
        "wrote {}: model.rad truth.rad sensors.csv weather.wea measured.csv ({} spectral readings, {} channels, {} sensors, {} steps)",
        a.out.display(),
        c.bound.len(),
        r.names.len(),
        c.sensors.len(),
        idx.len()
    );
    Ok(())
}
