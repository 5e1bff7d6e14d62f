//! # The typed configuration of a tracing run
//!
//! What `rdc` (and every library caller: calibration, annual glare, levels of detail,
//! material uncertainty, sharded jobs) asks of the tracer, as plain validated values, with
//! no command-line parsing in sight. The `rdc` tool's option letters map one to one onto
//! these fields (the table in `bin/rdc.rs`'s help; radiance-notes.md 6.2, 11.2):
//!
//! | field | `rdc` option | Radiance |
//! |---|---|---|
//! | [`Sampling`] `ab ad lw lr dj st ss` | `-ab -ad -lw -lr -dj -st -ss`, `--preset` | rcontrib's letters and defaults |
//! | [`Config::channels`] | `-cs N -cw a b` | Radiance 6 spectral sampling |
//! | [`Config::target`] | `-m MF [--direct]`, `--suns MF\|file [--suns-ab] [--sun-angle]`, `--flux sender receiver [-c N]`, none | rcontrib `-e MF:N`, five-phase suns, `rfluxmtx`, `rtrace -I` / `rpict` |
//! | [`Config::irradiance`] | `-I` | `rtrace -I`, `rcontrib -I+` |
//! | [`Config::adaptive`] | `--target-se`, `--se-row`, `--max-samples` | (none) |
//! | [`Config::seed`], [`Config::threads`] | `-s`, `-n` | (Radiance has no seed) |
//! | [`Config::reweight`] | `--reweight FILE`, `--reweight-materials` | (none) |
//!
//! [`Config::validate`] holds every rule about combinations, so that a caller that builds a
//! `Config` by hand gets the same one-line errors as a user of the tool.

use crate::error::{Error, Result, at_most};
use crate::material::RgbUplift;
use crate::radiometry::Channels;

/// rcontrib 6.0a's defaults (radiance-notes.md 11.2, `rcontrib -defaults`).
pub const RCONTRIB_AB: u32 = 1;
pub const RCONTRIB_AD: usize = 350;
pub const RCONTRIB_LW: f64 = 2e-3;
pub const RCONTRIB_LR: i32 = -10;
pub const RCONTRIB_DJ: f64 = 0.9;
pub const RCONTRIB_ST: f64 = 0.02;
pub const RCONTRIB_SS: f64 = 1.0;
/// rpict's default picture size (`-x 512 -y 512`).
pub const RPICT_RES: usize = 512;
/// The sun's apparent diameter in degrees (`--sun-angle`; gendaymtx `-5 .533`).
pub const SUN_ANGLE_DEG: f64 = 0.533;
/// rcontrib's `eval_irrad` moves an `-I` sensor this far along its normal (`rcontrib.c`).
pub const IRRADIANCE_OFFSET: f64 = 1.1e-4;
/// Largest accepted Reinhart subdivision (MF 30: 129 602 columns per row).
pub const MAX_MF: usize = 30;

/// Sampling settings with Radiance's meanings (radiance-notes.md 11.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sampling {
    /// Diffuse bounces; the `-I` sensor's hemisphere sample counts as the first.
    pub ab: u32,
    /// Samples per record and batch.
    pub ad: usize,
    /// Path weight limit for Russian roulette (weights start at 1/`ad` for `-I` samples).
    pub lw: f64,
    /// Reflection limit (`|lr|` events; 0 means 10; roulette by `lw` always).
    pub lr: i32,
    /// Source jitter (widens the sun's highlight on flat surfaces).
    pub dj: f64,
    /// Specular threshold.
    pub st: f64,
    /// Specular sampling (accepted; one direction per specular vertex).
    pub ss: f64,
    /// Sample the window panes as portals at Lambertian vertices (`crate::trace::portals`;
    /// `--no-portals` turns it off): the same expectation with less noise.
    pub portals: bool,
}

impl Sampling {
    /// The main job's `-ab 5 -ad 10000 -lw 1e-5` (the Radiance references' settings, about
    /// 1 % per sensor in the example rooms): the studies' default.
    pub fn main_job() -> Sampling {
        Sampling {
            ab: 5,
            ad: 10000,
            lw: 1e-5,
            ..Sampling::default()
        }
    }
}

impl Default for Sampling {
    /// rcontrib's defaults.
    fn default() -> Self {
        Sampling {
            ab: RCONTRIB_AB,
            ad: RCONTRIB_AD,
            lw: RCONTRIB_LW,
            lr: RCONTRIB_LR,
            dj: RCONTRIB_DJ,
            st: RCONTRIB_ST,
            ss: RCONTRIB_SS,
            portals: true,
        }
    }
}

/// Named sampling levels (`--preset`). Figures: docs/benchmarking.md measured `-ab 3 -ad
/// 1000` at 5.8 % median run-to-run spread and 9.7 % low against `-ab 5` in the side-lit
/// office, and the `-ab 5 -ad 10000 -lw 1e-5` references at about 1 %; `Standard` sits
/// between, `Converged` beyond the references.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Preset {
    Draft,
    Standard,
    Converged,
}

impl Preset {
    /// `(ab, ad, lw)` of the preset.
    pub fn settings(self) -> (u32, usize, f64) {
        match self {
            Preset::Draft => (3, 1024, 1e-3),
            Preset::Standard => (5, 4096, 1e-4),
            Preset::Converged => (7, 16384, 1e-5),
        }
    }

    /// rcontrib's defaults with the preset's `ab`, `ad`, `lw`.
    pub fn sampling(self) -> Sampling {
        let (ab, ad, lw) = self.settings();
        Sampling {
            ab,
            ad,
            lw,
            ..Sampling::default()
        }
    }
}

/// Where `--suns` puts its suns.
#[derive(Debug, Clone, PartialEq)]
pub enum SunSource {
    /// At the centres of the Reinhart MF patches (ground column empty): the five-phase
    /// method's sun coefficients.
    Patches(usize),
    /// One sun per time step of a weather file (`.wea` or EPW), an empty column while the
    /// sun is down.
    Weather(String),
    /// The same for weather already in memory.
    Steps(crate::formats::weather::Weather),
}

impl SunSource {
    /// `--suns MF|weather-file`: a number is a subdivision, anything else a file.
    pub fn parse(spec: &str) -> SunSource {
        match spec.parse::<usize>() {
            Ok(mf) => SunSource::Patches(mf),
            Err(_) => SunSource::Weather(spec.to_string()),
        }
    }
}

/// What a run computes for each record.
#[derive(Debug, Clone, PartialEq)]
pub enum Target {
    /// Point-in-time values under the scene's own sky and sources (`rtrace -I`, `rpict`).
    Values,
    /// Sky-patch coefficients over the Reinhart MF patches (146 columns at MF 1, ground
    /// first; rcontrib `-e MF:N -f reinhart.cal -b rbin`); `direct_only`: the direct-only
    /// coefficients C_dcd of the five-phase method. `below_horizon`: twice the columns, the
    /// second half the lower hemisphere resolved as the mirror image (z -> -z) of the
    /// patches (the ground column 0 stays empty): where, in altitude and azimuth, a scene's
    /// paths escape into the one ground column, so that a ground whose radiance varies
    /// (gendaylit's horizon blend, `perezlum.cal`) can be averaged as this scene sees it.
    Sky {
        mf: usize,
        direct_only: bool,
        below_horizon: bool,
    },
    /// Sun coefficients: one column per sun (solid angle of `angle_deg` in diameter);
    /// `bounces`: with inter-reflection, every sun from one set of paths.
    Suns {
        suns: SunSource,
        angle_deg: f64,
        bounces: bool,
    },
    /// Flux transfer between sender and receiver surfaces (`rfluxmtx`): columns = the
    /// receivers' basis patches.
    Flux(Flux),
}

impl Target {
    /// Sky coefficients (total, not direct-only) over the Reinhart MF patches.
    pub fn sky(mf: usize) -> Target {
        Target::Sky {
            mf,
            direct_only: false,
            below_horizon: false,
        }
    }

    /// True for coefficient runs (sky patches or suns).
    pub fn is_coefficients(&self) -> bool {
        !matches!(self, Target::Values)
    }
}

/// Where a flux run's rows come from.
#[derive(Debug, Clone, PartialEq)]
pub enum SenderInput {
    /// `-`: sensors or rays from standard input, one row each (the view matrix V).
    Stdin,
    /// A sender surface file (`#@rfluxmtx h=kf ...`): one row per basis patch (the
    /// daylight matrix D, a window-to-window T).
    File(String),
}

/// `rdc --flux sender receiver scene...`: flux transfer matrices between sender and
/// receiver surfaces, as `rfluxmtx` ([`crate::rdc::flux`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Flux {
    pub sender: SenderInput,
    /// The receiver file (`#@rfluxmtx h=... u=... o=...`), traced with the scene.
    pub receiver: String,
    /// `-c N`: rays per sender patch (rfluxmtx's default 10000 with a sender file; with
    /// standard input only 1).
    pub samples: Option<usize>,
}

/// Adaptive sampling: batches of `ad` until the relative standard error reaches `target_se`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Adaptive {
    /// Relative standard error to reach per record (`--target-se`).
    pub target_se: f64,
    /// Judge the row sum (the sensor under a uniform sky) instead of the worst column
    /// (`--se-row`).
    pub per_row: bool,
    /// Cap on samples per record (`--max-samples`; default 100 `ad`).
    pub max_samples: Option<usize>,
}

/// Path re-weighting records (`--reweight`): where they go and which materials to track.
#[derive(Debug, Clone, PartialEq)]
pub struct Reweight {
    /// The file [`crate::rdc::run::main`] writes; `None` when the caller only wants the
    /// terms in memory ([`crate::rdc::RecordResult::terms`] of [`crate::rdc::Tracer::compute`]).
    pub path: Option<String>,
    /// Material names to track (all reflecting materials when `None`).
    pub materials: Option<Vec<String>>,
}

/// Everything the tracer needs to know, validated by [`Config::validate`].
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    pub sampling: Sampling,
    /// RGB (the default) or N spectral bands.
    pub channels: Channels,
    /// How RGB materials become spectra in spectral runs.
    pub uplift: RgbUplift,
    pub target: Target,
    /// Sensors measure irradiance (`-I`): origin moved off the surface, cosine-weighted
    /// hemisphere; otherwise radiance along the ray.
    pub irradiance: bool,
    pub adaptive: Option<Adaptive>,
    /// Seed of every record's random stream: the same seed gives the same bytes whatever the
    /// thread count.
    pub seed: u64,
    /// Worker threads (all cores when `None`).
    pub threads: Option<usize>,
    pub reweight: Option<Reweight>,
}

impl Default for Config {
    /// rcontrib's defaults, RGB, point-in-time radiance, seed 0.
    fn default() -> Self {
        Config {
            sampling: Sampling::default(),
            channels: Channels::rgb(),
            uplift: RgbUplift::Radiance,
            target: Target::Values,
            irradiance: false,
            adaptive: None,
            seed: 0,
            threads: None,
            reweight: None,
        }
    }
}

pub use crate::error::MAX_THREADS;

/// Most samples per record (`-ad`, `--max-samples`): 2^24, a thousand times the converged
/// preset's 16,384. Its standard error is 1/4096 of one sample's spread, below what anyone
/// measures, and a record already takes minutes; `-ad 1e18` ran for ever (issue #19).
pub const MAX_AD: usize = 1 << 24;

/// Most bounces (`-ab`) and reflections (`|-lr|`): a path that survived 1000 bounces at
/// albedo 0.9 carries 0.9^1000 = 2e-46 of its weight, nothing an f32 output can hold.
pub const MAX_BOUNCES: u32 = 1000;

impl Config {
    /// Sensor coefficients (`-I -m MF`) with the given sampling.
    pub fn sky_coefficients(mf: usize, sampling: Sampling) -> Config {
        Config {
            sampling,
            target: Target::sky(mf),
            irradiance: true,
            ..Config::default()
        }
    }

    /// Every rule about values and combinations; `picture`: the run renders a view.
    pub fn validate(&self, picture: bool) -> Result<()> {
        let usage = |m: &str| Err(Error::Usage(m.into()));
        let s = &self.sampling;
        if s.ad == 0 {
            return usage("-ad 0: expected at least 1 sample");
        }
        let samples_why = "2^24 samples per record: standard error 1/4096 of one sample's spread";
        at_most("-ad", s.ad as u64, MAX_AD as u64, samples_why)?;
        let bounce_why = "a path's weight after 1000 bounces at albedo 0.9 is 2e-46";
        at_most("-ab", s.ab.into(), MAX_BOUNCES.into(), bounce_why)?;
        at_most(
            "-lr",
            s.lr.unsigned_abs().into(),
            MAX_BOUNCES.into(),
            bounce_why,
        )?;
        if s.lw.is_nan() || s.lw < 0.0 {
            return Err(Error::Usage(format!("-lw {}: expected >= 0", s.lw)));
        }
        if let Some(n) = self.threads {
            if n > MAX_THREADS {
                return Err(Error::Usage(format!(
                    "-n {n}: at most {MAX_THREADS} threads (more than the cores only costs memory)"
                )));
            }
        }
        match &self.target {
            Target::Values => {}
            Target::Sky { mf, .. } => {
                if *mf == 0 || *mf > MAX_MF {
                    return Err(Error::Usage(format!(
                        "-m {mf}: expected a Reinhart subdivision from 1 (Tregenza) to {MAX_MF}"
                    )));
                }
            }
            Target::Suns { angle_deg, .. } => {
                if !(*angle_deg > 0.0 && *angle_deg < 180.0) {
                    return usage("--sun-angle: expected degrees between 0 and 180");
                }
            }
            Target::Flux(f) => {
                if let Some(c) = f.samples {
                    if c == 0 {
                        return usage("-c 0: expected at least 1 ray per sender patch");
                    }
                    at_most("-c", c as u64, MAX_AD as u64, samples_why)?;
                }
                match &f.sender {
                    SenderInput::Stdin => {
                        if f.samples.is_some_and(|c| c > 1) {
                            return usage(
                                "-c N with senders from standard input (-): rdc gives one row per ray; average rows afterwards (rmtx) or give a sender file",
                            );
                        }
                    }
                    SenderInput::File(_) => {
                        if self.irradiance {
                            return usage(
                                "-I with a sender file: a sender's rays are radiance rays; -I is for sensors from standard input (-)",
                            );
                        }
                    }
                }
                if picture {
                    return usage(
                        "--flux with view options: give rays on standard input (vwrays) with - as the sender",
                    );
                }
                if self.adaptive.is_some() {
                    return usage("--target-se with --flux: use a fixed -c / -ad");
                }
                if self.reweight.is_some() {
                    return usage("--reweight with --flux: re-weighting records are for -m/--suns");
                }
            }
        }
        if let Some(a) = &self.adaptive {
            if let Some(m) = a.max_samples {
                at_most("--max-samples", m as u64, MAX_AD as u64, samples_why)?;
            }
            if a.target_se.is_nan() || a.target_se <= 0.0 {
                return Err(Error::Usage(format!(
                    "--target-se {}: expected > 0",
                    a.target_se
                )));
            }
        }
        if self.reweight.is_some() && !self.target.is_coefficients() {
            return usage(
                "--reweight needs coefficients (-m MF or --suns): point-in-time values are not re-weighted",
            );
        }
        if picture && self.irradiance {
            return usage("-I with view options: pictures are radiance (drop -I or the view)");
        }
        if self.uplift != RgbUplift::Radiance && !self.channels.is_spectral() {
            return usage("--uplift basis|jakob changes spectral runs only: add -cs N (N > 3)");
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_keep_rcontribs_other_defaults() {
        let s = Preset::Draft.sampling();
        assert_eq!((s.ab, s.ad, s.lw, s.lr), (3, 1024, 1e-3, -10));
        let d = Sampling::default();
        assert_eq!((d.ab, d.ad, d.lw, d.lr), (1, 350, 2e-3, -10));
    }

    #[test]
    fn validation_names_the_option() {
        let mut c = Config::sky_coefficients(31, Sampling::default());
        assert!(c.validate(false).unwrap_err().to_string().contains("-m 31"));
        c.target = Target::sky(1);
        assert!(c.validate(false).is_ok());
        assert!(c.validate(true).unwrap_err().to_string().contains("-I"));
        c.sampling.ad = 0;
        assert!(c.validate(false).unwrap_err().to_string().contains("-ad 0"));
        c.sampling.ad = MAX_AD + 1;
        let e = c.validate(false).unwrap_err().to_string();
        assert!(e.starts_with("-ad 16777217: at most 16777216 ("), "{e}");
        c.sampling.ad = 1;
        c.sampling.lr = i32::MIN;
        assert!(
            c.validate(false)
                .unwrap_err()
                .to_string()
                .starts_with("-lr 2147483648: at most 1000")
        );
        let c = Config {
            threads: Some(100_000),
            ..Config::default()
        };
        assert!(c.validate(false).unwrap_err().to_string().contains("-n"));
        let c = Config {
            uplift: RgbUplift::Basis,
            ..Config::default()
        };
        assert!(c.validate(false).unwrap_err().to_string().contains("-cs"));
    }
}
