//! # `rdc`'s command line: Radiance's letters and meanings, rcontrib's defaults
//!
//! The tools layer's half of `rdc`: the clap struct, the Radiance spellings, and the
//! conversion into the library's typed [`Run`] / [`Config`] (`rdaylight_trace::rdc`), which
//! holds the defaults and every validation rule. `rdc` stands where `rcontrib` (coefficients), `rtrace -I` (point-in-time values) and
//! `rpict` (pictures) stand in a Radiance pipeline, so it takes their option letters
//! (radiance-notes.md 6.2, 11.2). clap cannot parse two-letter short options, so
//! [`radiance_args`] rewrites the Radiance spellings (`-ab 5`, `-I+`, `-h-`, `-oi`) into
//! the long forms clap knows (`--ab 5`, `--irradiance`, `-h`, `--oi`) before parsing, and the
//! view options (`-vta -vp ...`) are taken out beforehand with `View::extract_args`.
//!
//! | option | meaning | default | Radiance | what rdc does with it |
//! |---|---|---|---|---|
//! | `-ab N` | diffuse bounces | 1 | rcontrib `-ab` | path tracer: at most N diffuse bounces, the sensor's hemisphere sample counting as the first (0: glow skies invisible to `-I` sensors, as in Radiance) |
//! | `-ad N` | samples per record and batch | 350 | rcontrib `-ad` | N paths per record (stratified cosine directions for `-I`, jittered pixel positions for pictures) |
//! | `-lw W` | path weight limit | 2e-3 | rcontrib `-lw` | Russian roulette below W, path weight = Radiance's ray weight (1/`-ad` x throughput) |
//! | `-lr N` | reflection limit | -10 | rcontrib `-lr` | at most `|N|` scattering events per path (0: 10); roulette by `-lw` always (Radiance's N <= 0 rule) |
//! | `-dj F` | source jitter | 0.9 | rcontrib `-dj` | shadow rays aim at the source centre; F widens the sun's highlight on flat surfaces by `(1-F) omega/4pi` as Radiance's shading does |
//! | `-st F` | specular threshold | 0.02 | rcontrib `-st` | rough specular lobes at or below F are folded into the diffuse sample (`normal.c`) |
//! | `-ss F` | specular sampling | 1 | rcontrib `-ss` | accepted and ignored: one sampled direction per specular vertex, Radiance's `-ss 1` weighting |
//! | `--no-portals` | no window portals | portals on | | the material's cosine sample alone (see `crate::trace::portals`) |
//! | `--preset P` | `draft`: -ab 3 -ad 1024 -lw 1e-3; `standard`: -ab 5 -ad 4096 -lw 1e-4; `converged`: -ab 7 -ad 16384 -lw 1e-5 | | | |
//!
//! Preset figures: [`Preset`] (docs/benchmarking.md).

use crate::error::{Error, Result};
use crate::formats::matrix::DataFormat;
use crate::formats::sensors::RayFormat;
use crate::formats::shard::Shard;
use crate::formats::view::View;
use crate::material::RgbUplift;
use crate::radiometry::Channels;
use crate::rdc::{
    Adaptive, Config, Flux, Preset, Reweight, Run, Sampling, SenderInput, SunSource, Target,
};
use clap::Parser;

pub const EXAMPLES: &str = "\
Radiance counterparts: sky coefficients = rcontrib -I+ -e MF:N -f reinhart.cal -b rbin
-bn Nrbins -m skyglow (a 360-degree glow source, ground = bin 0); -I without -m = rtrace -I -h;
view options = rpict; --suns = the five-phase sun coefficients (radiance-notes 6.6).
Options are written as Radiance writes them: -ab 5, -ad 4096, -I+, -faf, -h, -vta ...
View options (rpict, turn on picture mode): -vt[vlahsc] -vp x y z -vd x y z -vu x y z
-vh deg -vv deg -vo d -va d -vs s -vl l -vf file; -x -y give the size (default 512).

Examples:
  Two-phase daylight coefficients, then annual illuminance in lux:
    rdc -I -ab 5 -ad 10000 -lw 1e-5 -faf -m 1 room.rad < sensors.pts > dc.mtx
    gendaymtx -m 1 -of site.wea > sky.smx
    dctimestep dc.mtx sky.smx | rmtxop -fa -c 47.4 119.9 11.6 - > ill.txt
  Direct-only coefficients and sun coefficients (DDS / five-phase):
    rdc -I --direct -m 1 -faf room.rad < sensors.pts > dcd.mtx
    rdc -I --suns 6 -faf room.rad < sensors.pts > cds.mtx
  Point-in-time illuminance under a CIE sky (as rtrace -I -h ... | rcalc 179*...):
    gensky 3 21 12 +s > sky.rad; cat skyglow.rad >> sky.rad
    rdc -I -oi --preset standard room.rad sky.rad < sensors.pts
  Three-phase matrices as rfluxmtx (rdc --flux takes rfluxmtx's arguments):
    rdc --flux -I -ab 5 -ad 10000 -lw 1e-5 -faf - window.rad room.rad < sensors.pts > view.vmx
    rdc --flux -ab 2 -ad 1000 -lw 1e-4 -c 1000 -faf window.rad sky.rad room.rad > daylight.dmx
    dctimestep view.vmx blinds.xml daylight.dmx sky.smx | rmtxop -fa -c 47.4 119.9 11.6 - > ill.txt
  (window.rad: '#@rfluxmtx h=kf u=Z' then glow polygons facing into the room; sky.rad:
  '#@rfluxmtx h=u u=Y' on a ground glow source, '#@rfluxmtx h=r1 u=Y' on the sky glow source.)
  A 180-degree fisheye picture, then glare:
    rdc -vta -vp 3 2 1.2 -vd 0 1 0 -vh 180 -vv 180 -x 512 -y 512 room.rad sky.rad > eye.hdr
    evalglare eye.hdr";

/// Daylight coefficients, point-in-time values and pictures (rcontrib / rtrace -I / rpict).
///
/// Sensors (`x y z dx dy dz`, one per line, or float/double with -ff/-fd) are read from
/// standard input; scene files (`.rad`, `-`, or `!command`) are the arguments. Rows of the
/// output follow the input order; results are identical for a given -s seed whatever -n.
/// Without -y, sensors (not results) are read first to count them, so NROWS is always in
/// the header (rmtxop needs it); with -y the input streams in constant memory.
#[derive(Parser, Debug, Clone)]
#[command(name = "rdc", version, disable_help_flag = true, after_help = EXAMPLES)]
pub struct Options {
    /// Ambient bounces (rcontrib -ab; default 1): at most N diffuse bounces per path, the
    /// -I sensor's hemisphere sample counting as the first; specular bounces do not count.
    /// 0 makes glow skies invisible to -I sensors, as in Radiance.
    #[arg(long = "ab", value_name = "N")]
    pub ab: Option<u32>,

    /// Samples per record and batch (rcontrib -ad; default 350): hemisphere samples of a -I
    /// sensor, paths through a pixel (jittered over the pixel) or along a ray.
    #[arg(long = "ad", value_name = "N")]
    pub ad: Option<usize>,

    /// Path weight limit (rcontrib -lw; default 2e-3): a path whose weight (1/-ad x
    /// throughput for -I samples, as Radiance weighs ambient rays) falls below W continues
    /// with probability weight/W (Russian roulette, unbiased: only the noise depends on W).
    #[arg(value_parser = super::finite, long = "lw", value_name = "W")]
    pub lw: Option<f64>,

    /// Reflection limit (rcontrib -lr; default -10): at most |N| reflections and
    /// transmissions per path (0: 10, against endless mirror pairs). Roulette by -lw is
    /// always played (Radiance's N <= 0 behaviour; with N > 0 Radiance instead drops rays
    /// below -lw without compensation).
    #[arg(long = "lr", value_name = "N", allow_hyphen_values = true)]
    pub lr: Option<i32>,

    /// Source jitter (rcontrib -dj; default 0.9). Shadow rays aim at the source centre (no
    /// jitter); F only widens the sun's specular highlight on flat surfaces by (1-F) x
    /// omega/4pi, as Radiance's shading does. No effect on -m/--suns coefficients.
    #[arg(value_parser = super::finite, long = "dj", value_name = "F")]
    pub dj: Option<f64>,

    /// Do not sample the window panes as portals. By default, at the sensor and at every
    /// Lambertian vertex, one extra shadow ray goes through a glass pane that has the sky
    /// behind it and is combined with the cosine sample by multiple importance sampling:
    /// the same expected values with less noise in side-lit rooms (docs/performance.md).
    #[arg(long = "no-portals")]
    pub no_portals: bool,

    /// Ambient accuracy (rcontrib -aa): accepted and ignored, as rcontrib and rfluxmtx
    /// override it with 0 (rcmain.c): rdc never caches irradiance (pure Monte Carlo, the
    /// `-aa 0` result also for -I values). Scripts that pass it (honeybee: `-aa 0.0`) run
    /// unchanged.
    #[arg(value_parser = super::finite, long = "aa", value_name = "F")]
    pub aa: Option<f64>,

    /// Ambient resolution (rcontrib -ar): accepted and ignored (no irradiance cache).
    #[arg(long = "ar", value_name = "N", value_parser = super::at_most::<1_000_000>)]
    pub ar: Option<usize>,

    /// Ambient super-samples (rcontrib -as): accepted and ignored, as rcontrib forces 0.
    #[arg(long = "as", value_name = "N", value_parser = super::at_most::<1_000_000>)]
    pub ambient_super: Option<usize>,

    /// Direct threshold (rcontrib -dt): accepted and ignored, as rcontrib forces 0 (every
    /// distant source is tested).
    #[arg(value_parser = super::finite, long = "dt", value_name = "F")]
    pub dt: Option<f64>,

    /// Direct certainty (rcontrib -dc): accepted and ignored (every distant source is
    /// tested with one shadow ray).
    #[arg(value_parser = super::finite, long = "dc", value_name = "F")]
    pub dc: Option<f64>,

    /// Specular threshold (rcontrib -st; default 0.02): rough specular lobes whose
    /// coefficient is at or below F are folded into the diffuse sample, as Radiance's
    /// normal.c does.
    #[arg(value_parser = super::finite, long = "st", value_name = "F")]
    pub st: Option<f64>,

    /// Specular sampling (rcontrib -ss; default 1). Accepted and ignored: every specular
    /// vertex takes one sampled direction weighted as Radiance's -ss 1.
    #[arg(value_parser = super::finite, long = "ss", value_name = "F")]
    pub ss: Option<f64>,

    /// Named sample settings: draft (-ab 3 -ad 1024 -lw 1e-3), standard (-ab 5 -ad 4096
    /// -lw 1e-4), converged (-ab 7 -ad 16384 -lw 1e-5). Explicit -ab/-ad/-lw win (no
    /// Radiance counterpart).
    #[arg(long = "preset", value_name = "draft|standard|converged")]
    pub preset: Option<PresetArg>,

    /// Irradiance sensors (-I or -I+, as rcontrib -I+ / rtrace -I): each input ray is a
    /// point and a surface normal; the point is moved 1.1e-4 along the normal (rcontrib's
    /// eval_irrad offset). Without -I each ray is a radiance ray.
    #[arg(long = "irradiance")]
    pub irradiance: bool,

    /// Sky coefficients on the Reinhart sky with subdivision MF (1 = Tregenza): columns =
    /// 144 MF^2 + 2 patches, ground first, in gendaymtx -m MF row order (rcontrib -e MF:N -f
    /// reinhart.cal -b rbin -bn Nrbins on a 360-degree glow source). The sky's brightness
    /// is ignored: every path that leaves the scene into a distant glow of the scene (or,
    /// when the scene has no source at all, every path that leaves it) is binned by its
    /// direction; paths that leave toward a `light` source (a sun) count nothing, as
    /// rcontrib does for untracked modifiers.
    #[arg(short = 'm', value_name = "MF")]
    pub mf: Option<usize>,

    /// With -m: direct-only coefficients C_dcd (patches seen straight from the sensor, no
    /// inter-reflection), what Radiance computes with -ab 1 on a black room (DDS, notes 6.6).
    #[arg(long = "direct")]
    pub direct: bool,

    /// Sun coefficients: MF = one unit-radiance sun at each Reinhart MF patch centre
    /// (columns = 144 MF^2 + 2 like gendaymtx -5 0.533 -d -m MF; the ground column is 0);
    /// or a .wea/.epw file = one sun per time step at its solar position (a zero column when
    /// the sun is down). Coefficient = light of a unit-radiance disc, so multiply by the
    /// sun's radiance.
    #[arg(long = "suns", value_name = "MF|weather-file")]
    pub suns: Option<String>,

    /// With --suns: every bounce up to -ab, not only the direct view (each path from a
    /// sensor does next-event estimation towards every sun at every surface it meets;
    /// rcontrib -ab N with the suns as light sources: the five-phase method's sun
    /// coefficients with inter-reflection, all suns from the same paths).
    #[arg(long = "suns-ab")]
    pub suns_ab: bool,

    /// Full apex angle of the --suns discs in degrees (gendaymtx -5 0.533).
    #[arg(value_parser = super::finite, long = "sun-angle", value_name = "DEG", default_value_t = crate::rdc::config::SUN_ANGLE_DEG)]
    pub sun_angle: f64,

    /// Number of spectral channels (Radiance -cs; default 3 = RGB).
    #[arg(long = "cs", value_name = "N")]
    pub cs: Option<usize>,

    /// Wavelength range of -cs channels in nm (Radiance -cw; default 380 780).
    #[arg(value_parser = super::finite, long = "cw", num_args = 2, value_names = ["MIN", "MAX"])]
    pub cw: Option<Vec<f64>>,

    /// How RGB reflectances and transmittances (plastic, metal, trans, mirror, glass)
    /// become bands under -cs N (N > 3). radiance (default): as Radiance 6 does
    /// (setscolor), each band copies R, G or B by its centre wavelength (R above 588 nm, G
    /// 480-588, B below): a step spectrum, identical to rtrace/rcontrib -cs N. basis:
    /// ruplift's default, the most probable smooth reflectance of a basis learned on
    /// measured Munsell chips with exactly that colour. jakob: Jakob & Hanika 2019's
    /// smooth sigmoid spectrum. Light sources and colours outside [0, 1] always take
    /// Radiance's conversion; spectrum/specfile patterns are unaffected.
    #[arg(
        long = "uplift",
        value_name = "radiance|basis|jakob",
        default_value = "radiance"
    )]
    pub uplift: Uplift,

    /// Input/output formats, rtrace's -f[io]: a ascii, f float, d double; c (output only)
    /// RGBE/Radiance_spectra rows. One letter sets both (-ff reads float rays); -faf reads
    /// ascii and writes float. Default -faa. Pictures are always RGBE (or spectra).
    #[arg(short = 'f', value_name = "io")]
    pub format: Option<String>,

    /// No information header (Radiance -h, -h-; -h+ keeps it).
    #[arg(short = 'h')]
    pub no_header: bool,

    /// Worker threads (rcontrib -n; default: all cores). Output does not depend on it.
    #[arg(short = 'n', value_name = "N")]
    pub threads: Option<usize>,

    /// Random seed (Radiance has none: docs/benchmarking.md rule 2). Each record's stream is
    /// derived from (seed, record index).
    #[arg(short = 's', value_name = "SEED", default_value_t = 0)]
    pub seed: u64,

    /// Picture width (rpict -x; default 512), or with -m and a view the pixel columns.
    #[arg(short = 'x', value_name = "X")]
    pub x: Option<usize>,

    /// Picture height (rpict -y; default 512); for sensor input the number of sensors,
    /// written as NROWS and checked (rcontrib -y); the input then streams.
    #[arg(short = 'y', value_name = "Y")]
    pub y: Option<usize>,

    /// Stop sampling a record once its relative standard error (RMS of the column SEs over
    /// the mean column value) is below this target; samples come in batches of -ad, at
    /// most --max-samples (no Radiance counterpart: Radiance only has a fixed -ad).
    #[arg(value_parser = super::finite, long = "target-se", value_name = "REL")]
    pub target_se: Option<f64>,

    /// With --target-se: the target applies to the standard error of each record's row sum
    /// (for sky coefficients, the sensor under a uniform sky) instead of the RMS of its
    /// column SEs; coefficients that feed sky-weighted sums then get the samples the sum
    /// needs (no Radiance counterpart).
    #[arg(long = "se-row")]
    pub se_row: bool,

    /// Upper limit on samples per record with --target-se (default 100 x -ad; no Radiance
    /// counterpart).
    #[arg(long = "max-samples", value_name = "N")]
    pub max_samples: Option<usize>,

    /// Write each record's relative standard error and sample count to FILE (an ascii
    /// matrix, NCOLS=2, NCOMP=1; no Radiance counterpart).
    #[arg(long = "se-out", value_name = "FILE")]
    pub se_out: Option<String>,

    /// Write path re-weighting records to FILE (no Radiance counterpart): per record and
    /// column the contribution split by which tracked materials the paths scattered at, so
    /// that coefficients for scaled material reflectances/transmittances follow without
    /// re-tracing (rdaylight::trace::reweight documents the format and what is exact).
    /// Needs -m or --suns. The normal output is unchanged.
    #[arg(long = "reweight", value_name = "FILE")]
    pub reweight: Option<String>,

    /// Materials tracked by --reweight, comma-separated names (default: every plastic,
    /// metal, trans, glass and mirror on a surface); others count as fixed.
    #[arg(
        long = "reweight-materials",
        value_name = "NAME,...",
        value_delimiter = ','
    )]
    pub reweight_materials: Option<Vec<String>>,

    /// Print timings (load, compile and BVH build, trace), the rays cast by paths and rays
    /// per second to standard error at the end (no Radiance counterpart; cf. rtrace's
    /// report).
    #[arg(long = "stats")]
    pub stats: bool,

    /// Refuse inline `!commands` in scene files (error instead). By default they run, as in
    /// Radiance; also RDAYLIGHT_NO_EXEC=1.
    #[arg(long = "no-exec")]
    pub no_exec: bool,

    /// Write the picture to FILE instead of standard output (rpict/rtpict -o), replaced
    /// only once complete: OpenEXR when FILE ends in .exr (32-bit float R G B, or one
    /// channel per band named by its centre, e.g. S0.768,888889nm: the spectral EXR
    /// layout of Fichet et al. 2021; values unquantised), else the RGBE/Radiance_spectra
    /// picture. Pictures only.
    #[arg(short = 'o', value_name = "FILE")]
    pub output: Option<String>,

    /// Illuminance output for -I: one value per column, 179 x (0.265 R + 0.670 G + 0.065 B)
    /// lux, what rmtxop -c 47.4 119.9 11.6 or rcalc after rtrace -I gives. Not rtrace's
    /// -oi (intersection points), which rdc does not offer.
    #[arg(long = "oi")]
    pub oi: bool,

    /// Compute only the K-th of N contiguous row blocks (K 0-based: 0 <= K < N <= 100000):
    /// sensor rows, or with a view and -m/--suns whole scanlines of pixel rows. Every
    /// sensor is still read; with R rows each shard gets R/N, the first R%N one more.
    /// Records keep the unsharded run's seeds, and `rmtx --cat` of the N outputs gives the
    /// unsharded run's bytes (the header says SHARD= K/N FIRST TOTAL; --shard and
    /// --manifest are left out of the header's command line). No Radiance counterpart.
    #[arg(long = "shard", value_name = "K/N")]
    pub shard: Option<String>,

    /// With --shard: write the shard's manifest to FILE (JSON: command, N, K, seed, rows,
    /// version, every input with its size and 64-bit FNV-1a hash), for
    /// `rmtx --cat ... --manifests`.
    #[arg(long = "manifest", value_name = "FILE")]
    pub manifest: Option<String>,

    /// Sender/receiver mode, rfluxmtx's command line: `rdc --flux [opts] sender.rad|-
    /// receivers.rad scene.rad...` (the first two arguments are the sender and the
    /// receiver file). Surfaces carry `#@rfluxmtx h=kf|kh|kq|rN|u u=[-]X|Y|Z|x,y,z o=FILE`
    /// lines; each receiver modifier gives its basis's columns (to FILE with o=, else all
    /// side by side on standard output); a sender file gives one row per basis patch
    /// (-c N rays each, default 10000), `-` one row per ray or -I sensor from standard
    /// input (the view matrix). Rays leave the back of the sender and arrive at the front
    /// of receivers, as in rfluxmtx. Not offered: -bj, -i octree, h=sc/cie, o=!command.
    #[arg(long = "flux")]
    pub flux: bool,

    /// Compile the scene files into FILE and stop (no records are read or written), as
    /// oconv makes an octree: later runs given FILE as their only scene skip reading the
    /// scene and building its BVH, and trace the same surfaces (the same output). FILE
    /// records the files it was made from (scene files, specfile data, meshes, octrees)
    /// with their sizes and hashes; a run refuses it once one of them changed. Inline
    /// !commands are compiled in, not re-run. No Radiance counterpart.
    #[arg(long = "compile", value_name = "FILE")]
    pub compile: Option<String>,

    /// Keep compiled scenes in DIR (made if missing), one per set of scene files, named by
    /// a hash of their names and bytes: a run whose scene files (and the files they read)
    /// are unchanged loads the compiled scene instead of reading the scene files (the same
    /// output); otherwise it compiles and keeps it. Scenes read from standard input or
    /// !commands are not kept. Also RDAYLIGHT_SCENE_CACHE=DIR. No Radiance counterpart.
    #[arg(long = "scene-cache", value_name = "DIR")]
    pub scene_cache: Option<String>,

    /// With --flux and a sender file: rays per sender patch (rfluxmtx -c; default 10000).
    #[arg(short = 'c', value_name = "N")]
    pub samples: Option<usize>,

    /// Print help.
    #[arg(long = "help", action = clap::ArgAction::Help)]
    pub help: Option<bool>,

    /// Scene files (.rad), `-` (standard input) or `!command`.
    #[arg(value_name = "SCENE")]
    pub scene: Vec<String>,
}

/// `--uplift` values (see [`RgbUplift`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Uplift {
    Radiance,
    Basis,
    Jakob,
}

impl From<Uplift> for RgbUplift {
    fn from(u: Uplift) -> Self {
        match u {
            Uplift::Radiance => RgbUplift::Radiance,
            Uplift::Basis => RgbUplift::Basis,
            Uplift::Jakob => RgbUplift::Jakob,
        }
    }
}

/// `--preset` values (see [`Preset`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PresetArg {
    Draft,
    Standard,
    Converged,
}

impl From<PresetArg> for Preset {
    fn from(p: PresetArg) -> Self {
        match p {
            PresetArg::Draft => Preset::Draft,
            PresetArg::Standard => Preset::Standard,
            PresetArg::Converged => Preset::Converged,
        }
    }
}

/// Rewrite Radiance's option spellings into clap's (program name excluded).
pub fn radiance_args<S: AsRef<str>>(args: &[S]) -> Vec<String> {
    // `-I`/`-h` take a Radiance +/- suffix that clap has no spelling for.
    let mut operands = false;
    let flags = args.iter().filter_map(|a| {
        let a = a.as_ref();
        operands |= a == "--";
        match a {
            _ if operands => Some(a),
            "-I" | "-I+" => Some("--irradiance"),
            "-I-" | "-h+" => None,
            "-h-" => Some("-h"),
            _ => Some(a),
        }
    });
    super::long_spellings(
        flags,
        &[
            "ab", "ad", "lw", "lr", "dj", "st", "ss", "cs", "cw", "oi", "aa", "ar", "as", "dt",
            "dc",
        ],
    )
}

/// The command line without `--shard K/N` and `--manifest FILE` (either spelling: `--x v`
/// or `--x=v`): they say where a piece of the run goes, not what it computes, so every
/// shard's header names the unsharded run's command (`rdaylight::formats::shard`).
pub fn without_shard_options(command: &[String]) -> Vec<String> {
    super::without_options(command, &["--shard", "--manifest"])
}

impl Options {
    /// Sampling after preset, explicit options and rcontrib's defaults.
    pub fn sampling(&self) -> Sampling {
        let base = self
            .preset
            .map(|p| Preset::from(p).sampling())
            .unwrap_or_default();
        Sampling {
            ab: self.ab.unwrap_or(base.ab),
            ad: self.ad.unwrap_or(base.ad),
            lw: self.lw.unwrap_or(base.lw),
            lr: self.lr.unwrap_or(base.lr),
            dj: self.dj.unwrap_or(base.dj),
            st: self.st.unwrap_or(base.st),
            ss: self.ss.unwrap_or(base.ss),
            portals: !self.no_portals,
        }
    }

    /// `-cs N -cw a b` as a channel layout (RGB without them).
    pub fn channels(&self) -> Result<Channels> {
        match (self.cs, &self.cw) {
            (None | Some(3), None) => Ok(Channels::rgb()),
            (n, cw) => {
                let (lo, hi) = match cw.as_deref() {
                    Some([a, b]) => (*a, *b),
                    _ => (380.0, 780.0),
                };
                Channels::spectral(n.unwrap_or(3), lo, hi)
            }
        }
    }

    /// `-f[io]`: sensor input and data output formats.
    pub fn formats(&self) -> Result<(RayFormat, DataFormat)> {
        let f = self.format.as_deref().unwrap_or("aa");
        let bad = || {
            Error::Usage(format!(
                "-f{f}: expected -f[a|f|d][a|f|d|c] (e.g. -faf: ascii rays in, float out)"
            ))
        };
        let mut cs = f.chars();
        let (i, o) = match (cs.next(), cs.next(), cs.next()) {
            (Some(c), None, None) => (c, c),
            (Some(i), Some(o), None) => (i, o),
            _ => return Err(bad()),
        };
        let input = if i == 'c' {
            return Err(bad());
        } else {
            RayFormat::from_letter(i).ok_or_else(bad)?
        };
        let output = match o {
            'a' => DataFormat::Ascii,
            'f' => DataFormat::Float,
            'd' => DataFormat::Double,
            'c' => DataFormat::Rgbe,
            _ => return Err(bad()),
        };
        Ok((input, output))
    }

    /// The tracer's typed configuration; the rules that only concern how options combine
    /// on the command line are checked here, the rest by [`Config::validate`].
    pub fn to_config(&self) -> Result<Config> {
        let usage = |m: &str| Err(Error::Usage(m.into()));
        if self.mf.is_some() && self.suns.is_some() {
            return usage("-m and --suns: one kind of coefficients per run");
        }
        if self.direct && self.mf.is_none() {
            return usage("--direct needs -m MF (direct-only sky coefficients)");
        }
        if self.suns_ab && self.suns.is_none() {
            return usage("--suns-ab needs --suns MF|weather-file");
        }
        if self.se_row && self.target_se.is_none() {
            return usage("--se-row needs --target-se REL (the row sum's relative error target)");
        }
        if self.reweight_materials.is_some() && self.reweight.is_none() {
            return usage("--reweight-materials needs --reweight FILE");
        }
        if self.samples.is_some() && !self.flux {
            return usage("-c N needs --flux (rays per sender patch)");
        }
        if self.flux {
            if self.mf.is_some() || self.suns.is_some() {
                return usage(
                    "--flux with -m or --suns: the receivers' #@rfluxmtx h= lines give the columns",
                );
            }
            let [sender, receiver, ..] = self.scene.as_slice() else {
                return usage(
                    "--flux needs a sender (a file or - for standard input) and a receiver file before the scene files",
                );
            };
            let sender = if sender == "-" {
                SenderInput::Stdin
            } else {
                SenderInput::File(sender.clone())
            };
            return self.config_with(Target::Flux(Flux {
                sender,
                receiver: receiver.clone(),
                samples: self.samples,
            }));
        }
        let target = match (self.mf, &self.suns) {
            (Some(mf), _) => Target::Sky {
                mf,
                direct_only: self.direct,
                below_horizon: false,
            },
            (None, Some(s)) => Target::Suns {
                suns: SunSource::parse(s),
                angle_deg: self.sun_angle,
                bounces: self.suns_ab,
            },
            (None, None) => Target::Values,
        };
        self.config_with(target)
    }

    /// The configuration for `target` with every other option.
    fn config_with(&self, target: Target) -> Result<Config> {
        Ok(Config {
            sampling: self.sampling(),
            channels: self.channels()?,
            uplift: self.uplift.into(),
            target,
            irradiance: self.irradiance,
            adaptive: self.target_se.map(|target_se| Adaptive {
                target_se,
                per_row: self.se_row,
                max_samples: self.max_samples,
            }),
            seed: self.seed,
            threads: self.threads,
            reweight: self.reweight.as_ref().map(|path| Reweight {
                path: Some(path.clone()),
                materials: self.reweight_materials.clone(),
            }),
        })
    }

    /// The whole run: the config plus streams, view and output choices.
    pub fn to_run(&self, view: Option<View>, command: &[String]) -> Result<Run> {
        let (input, output) = self.formats()?;
        let mut load = crate::scene::LoadOptions::from_env();
        load.allow_exec &= !self.no_exec;
        // With --flux the first two arguments are the sender and the receiver file.
        let scene = if self.flux {
            self.scene.iter().skip(2).cloned().collect()
        } else {
            self.scene.clone()
        };
        let run = Run {
            config: self.to_config()?,
            scene,
            load,
            input,
            output,
            header: !self.no_header,
            illuminance: self.oi,
            view,
            x: self.x,
            y: self.y,
            picture_file: self.output.clone(),
            se_out: self.se_out.clone(),
            stats: self.stats,
            command: without_shard_options(command),
            shard: self
                .shard
                .as_deref()
                .map(|s| Shard::parse(s, "--shard"))
                .transpose()?,
            manifest: self.manifest.clone(),
            compile: self.compile.clone(),
            scene_cache: self
                .scene_cache
                .clone()
                .or_else(|| {
                    std::env::var("RDAYLIGHT_SCENE_CACHE")
                        .ok()
                        .filter(|v| !v.is_empty())
                })
                .map(std::path::PathBuf::from),
        };
        run.validate()?;
        Ok(run)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_options_leave_the_header_command() {
        let cmd: Vec<String> = [
            "rdc",
            "-I",
            "--shard",
            "1/3",
            "-m",
            "1",
            "--manifest=m.json",
            "--shard=1/3",
            "--manifest",
            "x.json",
            "room.rad",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        assert_eq!(
            without_shard_options(&cmd),
            ["rdc", "-I", "-m", "1", "room.rad"]
        );
    }

    fn parse(args: &[&str]) -> Options {
        let mut v = vec!["rdc".to_string()];
        v.extend(radiance_args(args));
        Options::try_parse_from(v).unwrap()
    }

    #[test]
    fn radiance_spellings_reach_clap() {
        let o = parse(&[
            "-I+",
            "-ab",
            "5",
            "-ad",
            "1000",
            "-lw",
            "1e-5",
            "-lr",
            "-10",
            "-faf",
            "-h",
            "-m",
            "4",
            "-oi",
            "scene.rad",
        ]);
        assert!(o.irradiance && o.no_header && o.oi);
        assert_eq!(
            (o.ab, o.ad, o.lr, o.mf),
            (Some(5), Some(1000), Some(-10), Some(4))
        );
        assert_eq!(o.lw, Some(1e-5));
        assert_eq!(o.formats().unwrap(), (RayFormat::Ascii, DataFormat::Float));
        assert_eq!(o.scene, ["scene.rad"]);
    }

    #[test]
    fn presets_yield_to_explicit_options() {
        let o = parse(&["--preset", "draft", "-ad", "10"]);
        let s = o.sampling();
        assert_eq!((s.ab, s.ad, s.lw), (3, 10, 1e-3));
        let d = parse(&[]).sampling();
        assert_eq!((d.ab, d.ad, d.lw, d.lr), (1, 350, 2e-3, -10));
    }

    #[test]
    fn flux_takes_rfluxmtx_arguments() {
        let o = parse(&[
            "--flux", "-c", "100", "-ab", "2", "w.rad", "sky.rad", "room.rad",
        ]);
        let run = o.to_run(None, &["rdc".into()]).unwrap();
        assert_eq!(run.scene, ["room.rad"]);
        assert_eq!(
            run.config.target,
            Target::Flux(Flux {
                sender: SenderInput::File("w.rad".into()),
                receiver: "sky.rad".into(),
                samples: Some(100),
            })
        );
        let o = parse(&["--flux", "-I+", "-", "w.rad", "room.rad"]);
        let c = o.to_config().unwrap();
        assert!(c.irradiance);
        assert!(matches!(
            c.target,
            Target::Flux(Flux {
                sender: SenderInput::Stdin,
                ..
            })
        ));
        for bad in [
            &["-c", "5", "room.rad"][..],
            &["--flux", "-m", "1", "w.rad", "s.rad"],
            &["--flux", "w.rad"],
        ] {
            assert!(parse(bad).to_config().is_err(), "{bad:?}");
        }
    }

    #[test]
    fn bad_formats_are_errors() {
        for f in ["-fx", "-fca", "-faaa"] {
            assert!(parse(&[f]).formats().is_err(), "{f}");
        }
    }
}
