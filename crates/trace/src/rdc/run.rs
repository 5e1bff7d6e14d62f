//! # The parallel driver
//!
//! Records (sensors from standard input, or picture pixels) are processed in blocks: a block
//! is read, its records are computed in parallel with rayon, and its rows are written in
//! input order before the next block is read, so memory holds one block of rows whatever the
//! input size (the block shrinks for wide rows: at most [`BLOCK_BYTES`] of results).
//!
//! Determinism: record `i` draws from [`record_rng`]`(seed, i)` and is computed start to end
//! by one thread, so the output is a function of the inputs and `-s` only, never of `-n`.
//!
//! Per record: batches of `-ad` samples go to the [`Estimator`]; without `--target-se` one
//! batch is taken, with it batches continue until the record's relative standard error
//! ([`Tally::relative_se`]) is at most the target or `--max-samples` is reached. The value
//! written is the mean over all samples taken.

use super::config::{Config, IRRADIANCE_OFFSET, MAX_MF, RPICT_RES, SunSource, Target};
use super::intake;
use super::output::{self, Sink};
use super::traced::Traced;
use super::tracer::{Estimator, Mode, Quantity, Query, Rng, Stratum, SunDisc, Tally, chunk_rng};
use crate::error::{Error, Location, Result};
use crate::formats::matrix::DataFormat;
use crate::formats::sensors::{RayFormat, RayReader, SensorRay};
use crate::formats::shard::{
    HashingReader, HashingWriter, InputSum, Manifest, Shard, ShardInfo, SharedHash,
};
use crate::formats::view::{Camera, View};
use crate::geometry::vec3::normalized;
use crate::material::ShadingOptions;
use crate::progress::{Progress, QUIET, Stage};
use crate::radiometry::{Channels, RGB_PHOTOPIC, luminance_rounded};
use crate::scene::{CompactScene, LoadOptions, Scene};
use crate::sky::SkyPatches;
use crate::trace::Renderable;
use crate::trace::compiled::{self, CompiledScene};
use crate::trace::reweight::{RowWriter, Signature};
use rand::Rng as _;
use rayon::prelude::*;
use std::io::{BufRead, Write};

/// The rows a run wrote: `start..end` of `total` (all of them unless sharded).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rows {
    pub start: usize,
    pub end: usize,
    pub total: usize,
}

impl Rows {
    fn of(shard: Option<Shard>, total: usize) -> Rows {
        let r = shard.map_or(0..total, |s| s.rows(total));
        Rows {
            start: r.start,
            end: r.end,
            total,
        }
    }
    pub fn len(&self) -> usize {
        self.end - self.start
    }
    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }
    /// The header of a sharded run: `SHARD=` and the shard's NROWS (unchanged otherwise).
    fn mark(&self, shard: Option<Shard>, header: &mut crate::formats::header::Header) {
        if let Some(shard) = shard {
            let info = ShardInfo {
                shard,
                first: self.start,
                total: self.total,
            };
            info.mark(header, self.len());
        }
    }
}

/// Upper bound on the results held for one block (bytes of f64 rows).
pub const BLOCK_BYTES: usize = 64 << 20;
/// Records per block at most (keeps progress reports and latency reasonable).
pub const BLOCK_RECORDS: usize = 4096;
/// Samples per chunk: the unit of work below a record ([`Job::compute`]). Big enough that a
/// chunk's tally costs little next to its paths, small enough that a record of `-ad 10000`
/// spreads over 20 workers.
pub const CHUNK: usize = 512;

/// One record's result.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordResult {
    /// `ncols * ncomp` values.
    pub values: Vec<f64>,
    /// Relative standard error ([`Tally::relative_se`]).
    pub rel_se: f64,
    pub samples: u64,
    /// Re-weighting terms `(column, signature, ncomp means)` when the job keeps them.
    pub terms: Vec<(u32, Signature, Vec<f64>)>,
}

/// What every record shares.
pub struct Job<'a> {
    pub estimator: &'a dyn Estimator,
    pub mode: Mode<'a>,
    pub ncomp: usize,
    /// Channel weights of the scalar whose variance is tracked.
    pub weights: Vec<f64>,
    pub ad: usize,
    pub target_se: Option<f64>,
    /// `--se-row`: `target_se` bounds the row sum's error ([`Tally::row_relative_se`]).
    pub se_row: bool,
    pub max_samples: usize,
    pub seed: u64,
    /// Keep re-weighting terms per record (`--reweight`).
    pub terms: bool,
}

impl Job<'_> {
    /// Compute record `index`; `query` gives the sample's ray (`None`: a zero sample, e.g. a
    /// flush ray or a pixel corner outside a fisheye).
    ///
    /// Each batch of `-ad` samples is cut into chunks of [`CHUNK`] samples (the last one
    /// shorter) computed in parallel, each from its own random stream
    /// ([`super::tracer::chunk_rng`]) into its own tally, and the chunks' tallies are added
    /// in chunk order: the result depends on `-s`, `-ad` and the record's index, never on
    /// how many threads share the work, and a few records with many samples spread over
    /// every core.
    pub fn compute(
        &self,
        index: u64,
        query: &(dyn Fn(Stratum, &mut Rng) -> Option<Query> + Sync),
        tally: &mut Tally,
    ) -> RecordResult {
        tally.clear();
        let nchunks = self.ad.div_ceil(CHUNK).max(1);
        let mut batch = 0u64;
        loop {
            let chunk = |c: usize| {
                let mut part = tally.empty_like();
                let mut rng = chunk_rng(self.seed, index, batch * nchunks as u64 + c as u64);
                for k in c * CHUNK..((c + 1) * CHUNK).min(self.ad) {
                    let stratum = Stratum {
                        index: k,
                        count: self.ad,
                    };
                    if let Some(q) = query(stratum, &mut rng) {
                        self.estimator
                            .sample(&q, &self.mode, stratum, &mut rng, &mut part);
                    }
                    part.end_sample();
                }
                part
            };
            if nchunks == 1 {
                tally.merge(&chunk(0));
            } else {
                let parts: Vec<Tally> = (0..nchunks).into_par_iter().map(chunk).collect();
                for p in &parts {
                    tally.merge(p);
                }
            }
            batch += 1;
            match self.target_se {
                None => break,
                Some(t) => {
                    let se = if self.se_row {
                        tally.row_relative_se()
                    } else {
                        tally.relative_se()
                    };
                    if se <= t || tally.samples() as usize >= self.max_samples {
                        break;
                    }
                }
            }
        }
        self.estimator.add_rays(tally.rays());
        let mut values = vec![0.0; tally.ncols() * tally.ncomp()];
        tally.mean_into(&mut values);
        RecordResult {
            values,
            rel_se: if self.se_row {
                tally.row_relative_se()
            } else {
                tally.relative_se()
            },
            samples: tally.samples(),
            terms: tally.terms(),
        }
    }

    /// Compute a block of records in parallel; results in input order. Each finished
    /// record advances `progress` by one.
    pub fn block<T: Sync>(
        &self,
        first_index: u64,
        items: &[T],
        query: &(dyn Fn(&T, Stratum, &mut Rng) -> Option<Query> + Sync),
        progress: &dyn Progress,
    ) -> Vec<RecordResult> {
        let ncols = self.mode.ncols();
        items
            .par_iter()
            .enumerate()
            .with_min_len(4)
            .map_init(
                || {
                    let t = Tally::new(ncols, self.ncomp, &self.weights);
                    if self.terms { t.with_terms() } else { t }
                },
                |tally, (i, item)| {
                    let r = self.compute(
                        first_index + i as u64,
                        &|stratum, rng| query(item, stratum, rng),
                        tally,
                    );
                    progress.advance(1);
                    r
                },
            )
            .collect()
    }

    /// Records per block for this row width.
    pub fn block_len(&self) -> usize {
        let row = (self.mode.ncols() * self.ncomp * 8).max(1);
        (BLOCK_BYTES / row).clamp(1, BLOCK_RECORDS)
    }
}

/// A scene compiled for one [`Config`]: the typed entry point of the tracer. `rdc` builds
/// one per run; library callers (calibration, annual glare, levels of detail, material
/// uncertainty, shards) build theirs from an in-memory [`Scene`] and compute records with
/// [`Tracer::compute`].
///
/// ```no_run
/// use rdaylight_formats::scene::{self, LoadOptions};
/// use rdaylight_formats::sensors::SensorRay;
/// use rdaylight_trace::rdc::{Config, Sampling, Tracer};
/// let scene = scene::load(&["room.rad"], &LoadOptions::default())?;
/// let config = Config::sky_coefficients(1, Sampling { ab: 3, ad: 512, ..Sampling::default() });
/// let tracer = Tracer::new(&config, &scene)?;
/// let rows = tracer.compute(&[SensorRay::new([3.0, 2.0, 0.8], [0.0, 0.0, 1.0])])?;
/// assert_eq!(rows[0].values.len(), 146 * 3);
/// # Ok::<(), rdaylight_base::Error>(())
/// ```
pub struct Tracer {
    pub channels: Channels,
    config: Config,
    pub(crate) estimator: Traced,
    patches: Option<SkyPatches>,
    suns: Option<Vec<SunDisc>>,
    /// Where `--reweight` terms go (the estimator then tracks materials).
    reweight: Option<ReweightOut>,
    /// Names of the tracked materials (empty without `--reweight`), in the order the
    /// records' signatures number them.
    tracked: Vec<String>,
    /// What each tracked number stands for ([`crate::trace::reweight::Entry`]).
    entries: Vec<crate::trace::reweight::Entry>,
    /// `--stats` figures: compile time, surfaces, primitives, BVH build.
    compile_time: std::time::Duration,
    nsurfaces: usize,
    nprims: usize,
    bvh_build: std::time::Duration,
}

impl Tracer {
    /// Compile `scene` for `config` (validated first). Errors (unsupported primitives, bad
    /// settings, a point-in-time run without a sky) come with file:line before any input.
    pub fn new(config: &Config, scene: &Scene) -> Result<Tracer> {
        let compact = CompactScene::from_scene(scene)?;
        Tracer::build(config, SceneInput::Compact(&compact), None, &[])
    }

    /// [`Tracer::new`] for a compiled scene file ([`crate::trace::compiled`], `rdc
    /// --compile`): the same records as for the scene it was compiled from.
    pub fn from_compiled(config: &Config, scene: CompiledScene) -> Result<Tracer> {
        Tracer::build(config, SceneInput::Compiled(Box::new(scene)), None, &[])
    }

    /// As [`Tracer::new`]; `names` (the scene's inputs) go into the no-sky error and
    /// `command` into the `--reweight` file's header.
    pub(crate) fn build(
        config: &Config,
        scene: SceneInput,
        names: Option<&[String]>,
        command: &[String],
    ) -> Result<Tracer> {
        config.validate(false)?;
        let sampling = config.sampling;
        let channels = config.channels;
        let t_start = std::time::Instant::now();
        // Compile the surfaces (materials through modifier chains, one BVH) before any
        // input is read: unsupported primitives stop here with file:line.
        let shading = ShadingOptions {
            dj: sampling.dj,
            st: sampling.st,
            uplift: config.uplift,
            ..ShadingOptions::rcontrib()
        };
        let renderable = match scene {
            SceneInput::Compact(scene) => {
                // The table's plain surfaces are all of supported types.
                scene.rest.check_supported(intake::SUPPORTED)?;
                Renderable::compile_compact(scene, &channels, &shading)?
            }
            SceneInput::Compiled(c) => Renderable::from_compiled(*c, &channels, &shading)?,
        };
        let compile_time = t_start.elapsed();
        let nsurfaces = renderable.surface_count();
        let nprims = renderable.bvh().primitive_count();
        let bvh_build = renderable.bvh().build_time();
        let (patches, suns) = match &config.target {
            Target::Values => {
                check_sky(&renderable, names)?;
                (None, None)
            }
            Target::Sky { mf, .. } => (Some(SkyPatches::new(*mf)), None),
            Target::Suns {
                suns, angle_deg, ..
            } => (None, Some(sun_discs(suns, *angle_deg)?)),
            Target::Flux(_) => (None, None),
        };
        let tracking = match &config.reweight {
            Some(r) => Some(renderable.tracking(r.materials.as_deref())?),
            None => None,
        };
        let mut estimator = Traced::new(renderable, &sampling, sampling.ad);
        let mut reweight = None;
        let tracked = tracking
            .as_ref()
            .map(|t| t.names.clone())
            .unwrap_or_default();
        let entries = tracking
            .as_ref()
            .map(|t| t.entries.clone())
            .unwrap_or_default();
        if let (Some(r), Some(t)) = (&config.reweight, tracking) {
            reweight = r.path.as_ref().map(|path| ReweightOut {
                path: path.clone(),
                materials: t.names.clone(),
                entries: t.entries.clone(),
                command: command.join(" "),
            });
            estimator = estimator.with_tracking(t);
        }
        Ok(Tracer {
            channels,
            config: config.clone(),
            estimator,
            patches,
            suns,
            reweight,
            tracked,
            entries,
            compile_time,
            nsurfaces,
            nprims,
            bvh_build,
        })
    }

    /// The configuration this tracer was built for.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The materials re-weighting records track (signature entry `i + 1` is `[i]`).
    pub fn tracked_materials(&self) -> &[String] {
        &self.tracked
    }

    /// What each tracked number of the records' signatures stands for (a material, and for
    /// glass an angle bin); give it to [`crate::trace::reweight::Reweighting::with_entries`].
    pub fn tracked_entries(&self) -> &[crate::trace::reweight::Entry] {
        &self.entries
    }

    /// The job every record shares: mode (sky patches, suns or the scene's sky), sampling
    /// and seed.
    pub fn job(&self) -> Job<'_> {
        let mode = match (&self.config.target, &self.patches, &self.suns) {
            (
                Target::Sky {
                    direct_only,
                    below_horizon,
                    ..
                },
                Some(p),
                _,
            ) => Mode::Sky {
                patches: p,
                direct_only: *direct_only,
                below_horizon: *below_horizon,
            },
            (Target::Suns { bounces, .. }, _, Some(s)) => Mode::Suns {
                suns: s,
                bounces: *bounces,
            },
            _ => Mode::Values,
        };
        let weights = if self.channels.ncomp == 3 {
            RGB_PHOTOPIC.to_vec()
        } else {
            vec![1.0 / self.channels.ncomp as f64; self.channels.ncomp]
        };
        Job {
            estimator: &self.estimator,
            mode,
            ncomp: self.channels.ncomp,
            weights,
            ad: self.config.sampling.ad,
            target_se: self.config.adaptive.map(|a| a.target_se),
            se_row: self.config.adaptive.is_some_and(|a| a.per_row),
            max_samples: self
                .config
                .adaptive
                .and_then(|a| a.max_samples)
                .unwrap_or(100 * self.config.sampling.ad),
            seed: self.config.seed,
            terms: self.config.reweight.is_some(),
        }
    }

    /// A thread pool of `-n` workers (all cores by default).
    pub fn pool(&self) -> Result<rayon::ThreadPool> {
        rayon::ThreadPoolBuilder::new()
            .num_threads(self.config.threads.unwrap_or(0))
            .build()
            .map_err(|e| Error::Usage(format!("-n: cannot start threads: {e}")))
    }

    /// Records for `rays` in memory, in input order: sensor rows (irradiance when the
    /// config says so) of sky coefficients, sun coefficients or point-in-time values; each
    /// [`RecordResult`] holds `ncols * ncomp` values (columns outer). Record `i` is seeded as
    /// row `i` of the `rdc` tool, so the numbers equal its output.
    pub fn compute(&self, rays: &[SensorRay]) -> Result<Vec<RecordResult>> {
        self.compute_reporting(rays, &QUIET)
    }

    /// [`Tracer::compute`], advancing `progress` by one per record (the caller names the
    /// stage: `Stage::new(p, "sky coefficients", Some(rays.len() as u64), "records")`).
    pub fn compute_reporting(
        &self,
        rays: &[SensorRay],
        progress: &dyn Progress,
    ) -> Result<Vec<RecordResult>> {
        let job = self.job();
        let irradiance = self.config.irradiance;
        let query = move |r: &SensorRay, _: Stratum, _: &mut Rng| sensor_query(r, irradiance);
        let pool = self.pool()?;
        Ok(pool.install(|| {
            let mut out = Vec::with_capacity(rays.len());
            for (b, block) in rays.chunks(job.block_len()).enumerate() {
                let first = (b * job.block_len()) as u64;
                out.extend(job.block(first, block, &query, progress));
            }
            out
        }))
    }

    /// Columns per record (patches, suns, or 1 for values).
    pub fn ncols(&self) -> usize {
        self.job().mode.ncols()
    }
}

/// A scene for [`Tracer::build`]: loaded from `.rad` files, or a compiled scene.
pub(crate) enum SceneInput<'a> {
    Compact(&'a CompactScene),
    Compiled(Box<CompiledScene>),
}

/// What the `rdc` tool does beyond the tracer's [`Config`]: where the scene and the
/// records come from, and how results are written.
#[derive(Debug, Clone)]
pub struct Run {
    pub config: Config,
    /// Scene inputs as `oconv` names them (paths, `-`, `!command`).
    pub scene: Vec<String>,
    pub load: LoadOptions,
    /// Sensor ray input format (`-fa`, `-ff`, `-fd`).
    pub input: RayFormat,
    /// Output data format (`-f?a`, `-f?f`, `-f?d`, `-f?c`).
    pub output: DataFormat,
    /// Write the information header (`-h` turns it off).
    pub header: bool,
    /// `-oi`: RGB irradiance to illuminance in lux.
    pub illuminance: bool,
    /// Picture mode (view options).
    pub view: Option<View>,
    /// `-x`, `-y`: picture size, or with sensors `-y` = the number of sensors (streaming).
    pub x: Option<usize>,
    pub y: Option<usize>,
    /// `-o FILE`: the picture to a file (`.exr` for OpenEXR).
    pub picture_file: Option<String>,
    /// `--se-out FILE`: per-record standard errors and sample counts.
    pub se_out: Option<String>,
    /// `--stats`: load, compile and trace figures on stderr.
    pub stats: bool,
    /// The command line, for headers (and manifests). With `shard` it is the unsharded
    /// run's: leave `--shard` and `--manifest` out, so the merged header equals a single
    /// run's (`crate::formats::shard`).
    pub command: Vec<String>,
    /// `--shard K/N`: compute only the K-th (0-based) of N row blocks (sensor rows, or
    /// whole scanlines of per-pixel coefficients), seeded as in the unsharded run.
    pub shard: Option<Shard>,
    /// `--manifest FILE`: the shard's inputs, hashes, seed and version as JSON.
    pub manifest: Option<String>,
    /// `--compile FILE`: write the scene compiled to FILE and stop (no records).
    pub compile: Option<String>,
    /// `--scene-cache DIR`: compiled scenes kept in DIR by their sources' hash, used when
    /// the sources are unchanged ([`crate::trace::compiled`]).
    pub scene_cache: Option<std::path::PathBuf>,
}

impl Run {
    /// The rules that involve the streams as well as the tracer.
    pub fn validate(&self) -> Result<()> {
        self.config.validate(self.view.is_some())?;
        if self.view.is_some() {
            // Before the view trims one side to its aspect: -x 1e8 -y 1e8 aborted on
            // allocation (issue #19).
            let (x, y) = (self.x.unwrap_or(RPICT_RES), self.y.unwrap_or(RPICT_RES));
            crate::formats::picture::check_size(
                &format!("-x {x} -y {y}"),
                x,
                y,
                self.config.channels.ncomp,
            )?;
        }
        if self.illuminance && (!self.config.irradiance || self.config.channels.ncomp != 3) {
            return Err(Error::Usage(
                "-oi needs -I and RGB channels (illuminance from irradiance)".into(),
            ));
        }
        if let Some(s) = &self.shard {
            s.validate()?;
            if self.view.is_some() && !self.config.target.is_coefficients() {
                return Err(Error::Usage(
                    "--shard with a view: pictures cannot be merged; give -m or --suns \
                     (per-pixel coefficient rows, sharded by scanlines)"
                        .into(),
                ));
            }
            if self.output == DataFormat::Rgbe {
                return Err(Error::Usage(
                    "--shard: write shards with -f?a, -f?f or -f?d (rmtx --cat merges those)"
                        .into(),
                ));
            }
        }
        if matches!(self.config.target, Target::Flux(_)) {
            // -y (the sensor count, as honeybee passes it to rfluxmtx) is checked with
            // sensors from standard input; a sender file sets the rows itself.
            let sender_file = matches!(
                &self.config.target,
                Target::Flux(f) if matches!(f.sender, super::config::SenderInput::File(_))
            );
            let refused = [
                (self.shard.is_some(), "--shard"),
                (self.y.is_some() && sender_file, "-y and a sender file"),
                (self.illuminance, "-oi"),
                (self.se_out.is_some(), "--se-out"),
            ];
            if let Some((_, what)) = refused.iter().find(|(on, _)| *on) {
                return Err(Error::Usage(format!(
                    "{what} with --flux: not offered for sender/receiver matrices (convert afterwards with rmtx)"
                )));
            }
        }
        if matches!(self.config.target, Target::Flux(_)) {
            if self.compile.is_some() {
                return Err(Error::Usage(
                    "--compile with --flux: sender and receiver surfaces are read from .rad files each run; compile without --flux"
                        .into(),
                ));
            }
            if let Some(f) = self
                .scene
                .iter()
                .find(|f| compiled::is_compiled_file(std::path::Path::new(f)))
            {
                return Err(Error::Usage(format!(
                    "{f} is a compiled scene: --flux reads its sender, receivers and scene from .rad files; give those instead"
                )));
            }
        }
        if let Some(out) = &self.compile {
            if self.scene.is_empty() {
                return Err(Error::Usage(format!(
                    "--compile {out}: give the scene files to compile"
                )));
            }
            if let Some(f) = self
                .scene
                .iter()
                .find(|f| compiled::is_compiled_file(std::path::Path::new(f)))
            {
                return Err(Error::Usage(format!(
                    "--compile {out}: {f} is compiled already; give the .rad scene files"
                )));
            }
            let refused = [
                (self.view.is_some(), "view options"),
                (self.shard.is_some(), "--shard"),
                (self.se_out.is_some(), "--se-out"),
                (self.picture_file.is_some(), "-o"),
            ];
            if let Some((_, what)) = refused.iter().find(|(on, _)| *on) {
                return Err(Error::Usage(format!(
                    "--compile writes a compiled scene and traces nothing: {what} has nothing to do"
                )));
            }
        }
        if self.manifest.is_some() && self.shard.is_none() {
            return Err(Error::Usage(
                "--manifest describes a shard: it needs --shard K/N (0/1 for a whole run)".into(),
            ));
        }
        if self.picture_file.is_some()
            && (self.view.is_none() || self.config.target.is_coefficients())
        {
            return Err(Error::Usage(
                "-o FILE writes pictures: give view options (-vt.. -vp ..) and no -m/--suns".into(),
            ));
        }
        Ok(())
    }
}

/// Everything `rdc` does after option parsing: load and compile the scene, then stream
/// sensors from standard input (or the picture's pixels) to standard output. The stages
/// (loading, compiling, tracing) are reported to `progress`.
pub fn main(run: &Run, progress: &dyn Progress) -> Result<()> {
    run.validate()?;
    if let Target::Flux(flux) = &run.config.target {
        return super::flux::main(run, flux, progress);
    }
    if let Some(out) = &run.compile {
        let stage = Stage::uncounted(progress, "compiling the scene");
        let scene = crate::scene::load_compact(&run.scene, &run.load)?;
        compiled::compile(
            std::path::Path::new(out),
            &run.command.join(" "),
            &run.scene,
            &scene,
        )?;
        drop(stage);
        return Ok(());
    }
    // Scene first: its errors come before anything is read or written.
    let t_start = std::time::Instant::now();
    let stage = Stage::uncounted(progress, "loading the scene");
    let loaded = load_scene(run)?;
    drop(stage);
    let load_time = t_start.elapsed();
    let stage = Stage::uncounted(progress, "compiling the scene");
    let names = Some(run.scene.as_slice());
    let tracer = match loaded {
        Loaded::Compact(scene) => Tracer::build(
            &run.config,
            SceneInput::Compact(&scene),
            names,
            &run.command,
        )?,
        Loaded::Compiled(c) => Tracer::build(
            &run.config,
            SceneInput::Compiled(Box::new(c)),
            names,
            &run.command,
        )?,
    };
    drop(stage);
    let channels = tracer.channels;
    let job = tracer.job();
    let pool = tracer.pool()?;
    let out_channels = if run.illuminance {
        Channels::mono()
    } else {
        channels
    };
    let stdout = std::io::stdout();
    let seekable = crate::io::stdout_is_file();
    let reweight = tracer.reweight.as_ref();
    let t_trace = std::time::Instant::now();
    let sensor_hash = SharedHash::default();
    // What goes to standard output is hashed for a shard's manifest (`output`), so a merge
    // or a resume can tell a complete shard from a damaged one.
    let (result, written) = pool.install(|| {
        let mut out = HashingWriter::new(stdout.lock());
        let result = match &run.view {
            Some(v) => picture(
                run,
                &job,
                *v,
                out_channels,
                (&mut out, seekable),
                reweight,
                progress,
            ),
            None => {
                let stdin = std::io::stdin();
                let hashed = HashingReader::new(stdin.lock(), sensor_hash.clone());
                let reader = RayReader::new(hashed, "<stdin>", run.input);
                sensors(
                    run,
                    &job,
                    reader,
                    out_channels,
                    (&mut out, seekable),
                    reweight,
                    progress,
                )
            }
        };
        (result, out.sum("<stdout>"))
    });
    let result = match (result, &run.manifest, run.shard) {
        (Ok(rows), Some(path), Some(shard)) => {
            let mut inputs = Vec::new();
            for name in &run.scene {
                inputs.push(InputSum::of_scene_input(name)?);
            }
            if run.view.is_none() {
                let (h, n) = *sensor_hash.lock().unwrap_or_else(|e| e.into_inner());
                inputs.push(InputSum {
                    name: "<stdin>".into(),
                    bytes: n,
                    fnv1a64: h.hex(),
                });
            }
            Manifest {
                tool: "rdc".into(),
                version: env!("CARGO_PKG_VERSION").into(),
                command: run.command.clone(),
                shard,
                seed: run.config.seed,
                first_row: rows.start,
                rows: rows.len(),
                total_rows: rows.total,
                inputs,
                output: Some(written),
            }
            .write(path)
        }
        (r, _, _) => r.map(|_| ()),
    };
    if run.stats {
        let trace = t_trace.elapsed().as_secs_f64();
        let rays = tracer.estimator.rays();
        eprintln!(
            "rdc: load {:.3} s, compile {:.3} s (BVH build {:.3} s; {} surfaces, {} primitives), trace {trace:.3} s, {rays} path rays, {:.3e} rays/s",
            load_time.as_secs_f64(),
            tracer.compile_time.as_secs_f64(),
            tracer.bvh_build.as_secs_f64(),
            tracer.nsurfaces,
            tracer.nprims,
            rays as f64 / trace.max(1e-9)
        );
    }
    result
}

/// A scene as `rdc` got it.
enum Loaded {
    Compact(CompactScene),
    Compiled(CompiledScene),
}

/// The scene of a run: a compiled scene when it is the only input (refused when its
/// sources changed); with `--scene-cache`, the cached compiled scene of unchanged sources
/// (compiled and kept on a miss); else the `.rad` inputs, column-wise.
fn load_scene(run: &Run) -> Result<Loaded> {
    if let [only] = run.scene.as_slice() {
        if compiled::is_compiled_file(std::path::Path::new(only)) {
            let c = compiled::read(std::path::Path::new(only))?;
            return Ok(Loaded::Compiled(c));
        }
    }
    if let Some(dir) = &run.scene_cache {
        if let Some(key) = compiled::cache_key(&run.scene)? {
            let path = dir.join(format!("{key:016x}.rdb"));
            // A damaged or outdated entry is compiled again.
            if path.is_file() {
                if let Ok(c) = compiled::read(&path) {
                    return Ok(Loaded::Compiled(c));
                }
            }
            let scene = crate::scene::load_compact(&run.scene, &run.load)?;
            if scene.commands.is_empty() {
                std::fs::create_dir_all(dir)
                    .map_err(|e| Error::io(dir.display().to_string(), e))?;
                let c = compiled::compile(&path, &run.command.join(" "), &run.scene, &scene)?;
                return Ok(Loaded::Compiled(c));
            }
            return Ok(Loaded::Compact(scene));
        }
    }
    Ok(Loaded::Compact(crate::scene::load_compact(
        &run.scene, &run.load,
    )?))
}

/// `scene`: the inputs' names as the user gave them (`None` for an in-memory scene).
fn check_sky(r: &Renderable, scene: Option<&[String]>) -> Result<()> {
    if r.sources().is_empty() {
        let what = match scene {
            None => "no sky in the scene".to_string(),
            Some([]) => "no scene given".to_string(),
            Some(names) => format!("no sky in {}", names.join(" ")),
        };
        return Err(Error::Usage(format!(
            "{what}: point-in-time values need glow or light sources (gensky + skyglow.rad); \
             use -m MF for sky coefficients"
        )));
    }
    Ok(())
}

/// Suns for `--suns`: a number = Reinhart patch centres (ground column empty), otherwise a
/// weather file = one sun per time step (an empty column while the sun is down).
pub fn sun_discs(suns: &SunSource, angle: f64) -> Result<Vec<SunDisc>> {
    let none = SunDisc {
        dir: [0.0, 0.0, -1.0],
        cos_half: 2.0, // contains no direction
        solid_angle: 0.0,
    };
    let read;
    let w = match suns {
        SunSource::Weather(path) => {
            read = crate::formats::weather::Weather::read_path(path)?;
            &read
        }
        SunSource::Steps(w) => w,
        &SunSource::Patches(mf) => {
            if mf == 0 || mf > MAX_MF {
                return Err(Error::Usage(format!(
                    "--suns {mf}: expected a Reinhart subdivision from 1 to {MAX_MF}"
                )));
            }
            let p = SkyPatches::new(mf);
            return Ok((0..p.len())
                .map(|i| {
                    if i == 0 {
                        none
                    } else {
                        SunDisc::new(p.centre(i), angle)
                    }
                })
                .collect());
        }
    };
    let mut leap = crate::sky::solar::LeapDayTracker::new();
    Ok(w.steps
        .iter()
        .map(|s| {
            let jd = leap.day_of_year(u32::from(s.month), u32::from(s.day));
            let pos = crate::sky::SunPosition::at(&w.site, jd, s.hour);
            if pos.altitude > 0.0 {
                SunDisc::new(pos.direction(), angle)
            } else {
                none
            }
        })
        .collect())
}

/// The sensor's query: `-I` moves the origin 1.1e-4 along the normal (rcontrib's
/// `eval_irrad`); a zero direction (rtrace's flush) gives an empty record.
pub(crate) fn sensor_query(ray: &SensorRay, irradiance: bool) -> Option<Query> {
    if ray.is_flush() {
        return None;
    }
    let dir = normalized(ray.dir);
    let (org, quantity) = if irradiance {
        let o = ray.org;
        (
            [
                o[0] + IRRADIANCE_OFFSET * dir[0],
                o[1] + IRRADIANCE_OFFSET * dir[1],
                o[2] + IRRADIANCE_OFFSET * dir[2],
            ],
            Quantity::Irradiance,
        )
    } else {
        (ray.org, Quantity::Radiance)
    };
    Some(Query { org, dir, quantity })
}

/// `-oi`: RGB irradiance to illuminance, 179 x (0.265, 0.670, 0.065) per column.
fn to_output(values: &[f64], oi: bool) -> Vec<f64> {
    if !oi {
        return values.to_vec();
    }
    values
        .chunks_exact(3)
        .map(|c| luminance_rounded([c[0], c[1], c[2]]))
        .collect()
}

/// Sensor mode: rays from `reader`, one output row per ray (with `--shard`, per ray of the
/// shard's block: every ray is read, so the split and the seeds are the unsharded run's).
#[allow(clippy::too_many_arguments)]
pub fn sensors<R: BufRead, W: Write>(
    run: &Run,
    job: &Job,
    mut reader: RayReader<R>,
    channels: Channels,
    (out, seekable): (W, bool),
    reweight: Option<&ReweightOut>,
    progress: &dyn Progress,
) -> Result<Rows> {
    let (command, format) = (&run.command, run.output);
    let irradiance = run.config.irradiance;
    let query = move |r: &SensorRay, _: Stratum, _: &mut Rng| sensor_query(r, irradiance);
    // Without -y the sensors are read first (their count goes in NROWS); with -y they
    // stream and the count is checked at the end.
    let mut pending: Vec<SensorRay> = Vec::new();
    let nrows = match run.y {
        Some(y) => y,
        None => {
            for r in reader.by_ref() {
                pending.push(r?);
            }
            // An empty input made an NROWS=0 matrix and exit 0 (issue #19): no sensors is
            // a mistake (an empty file, the wrong redirection), not a result.
            if pending.is_empty() {
                return Err(crate::formats::sensors::no_sensors("<stdin>"));
            }
            pending.len()
        }
    };
    let ncols = job.mode.ncols();
    let rows = Rows::of(run.shard, nrows);
    let mut header = output::header(command, None, &channels, Some(nrows), ncols, format);
    rows.mark(run.shard, &mut header);
    // The --se-out file first: an unwritable path must fail before stdout gets a header.
    let mut se_out = output::SeWriter::open(run.se_out.as_deref(), command, rows.len())?;
    let mut rw_out = ReweightFile::open(reweight, rows.len(), ncols, job.ncomp)?;
    let mut sink = Sink::matrix(
        out,
        header,
        rows.len(),
        ncols,
        channels,
        format,
        run.header,
        seekable,
    )?;
    let stage = Stage::new(progress, "tracing", Some(rows.len() as u64), "records");
    let block_len = job.block_len();
    let mut pending = pending.into_iter();
    // Rays before the shard's block are read (counted for -y) and skipped.
    let mut done = 0usize;
    while done < rows.start {
        let skipped = if run.y.is_some() {
            reader.next().transpose()?.is_some()
        } else {
            pending.next().is_some()
        };
        if !skipped {
            break;
        }
        done += 1;
    }
    loop {
        let mut block = Vec::with_capacity(block_len);
        let want = block_len.min(rows.end.saturating_sub(done));
        if run.y.is_some() {
            for r in reader.by_ref().take(want) {
                block.push(r?);
            }
        } else {
            block.extend(pending.by_ref().take(want));
        }
        if block.is_empty() {
            break;
        }
        if done + block.len() > nrows {
            return Err(Error::parse(
                Location::file("<stdin>"),
                format!("more than the {nrows} sensors announced with -y"),
            ));
        }
        let results = job.block(done as u64, &block, &query, progress);
        for r in &results {
            sink.write_row(&to_output(&r.values, run.illuminance))?;
            se_out.write(r)?;
            rw_out.write(r)?;
        }
        sink.flush()?;
        done += block.len();
    }
    drop(stage);
    // Rays after the shard's block: read, so that -y's count is still checked.
    if run.y.is_some() && done == rows.end {
        for r in reader.by_ref() {
            r?;
            done += 1;
            if done > nrows {
                return Err(Error::parse(
                    Location::file("<stdin>"),
                    format!("more than the {nrows} sensors announced with -y"),
                ));
            }
        }
    } else if run.y.is_none() {
        done += pending.len();
    }
    if done != nrows {
        return Err(Error::parse(
            Location::file("<stdin>"),
            format!("{done} sensors read, -y announced {nrows}"),
        ));
    }
    se_out.finish()?;
    rw_out.finish()?;
    sink.finish()?;
    Ok(rows)
}

/// Picture mode: one record per pixel, rows top to bottom; a picture under a sky, or with
/// coefficient modes one matrix row per pixel.
#[allow(clippy::too_many_arguments)]
fn picture<W: Write>(
    run: &Run,
    job: &Job,
    view: View,
    channels: Channels,
    (out, seekable): (W, bool),
    reweight: Option<&ReweightOut>,
    progress: &dyn Progress,
) -> Result<Rows> {
    let (command, format) = (&run.command, run.output);
    let cam: Camera = view.setup()?;
    let (xres, yres, _) =
        cam.normalize_resolution(run.x.unwrap_or(RPICT_RES), run.y.unwrap_or(RPICT_RES), 1.0);
    if xres == 0 || yres == 0 {
        return Err(Error::Usage(format!(
            "picture size {xres} x {yres}: expected at least 1 x 1"
        )));
    }
    let jitter = job.ad > 1;
    let query = move |&(px, py): &(usize, usize), _: Stratum, rng: &mut Rng| {
        let (u, v) = if jitter {
            (rng.random::<f64>(), rng.random::<f64>())
        } else {
            (0.5, 0.5)
        };
        let x = (px as f64 + u) / xres as f64;
        let y = ((yres - 1 - py) as f64 + v) / yres as f64;
        cam.view_ray(x, y).map(|r| Query {
            org: r.org,
            dir: r.dir,
            quantity: Quantity::Radiance,
        })
    };
    // A shard takes whole scanlines (validated: only per-pixel coefficient rows), so its
    // rows are pixel rows lines.start * xres .. lines.end * xres.
    let lines = Rows::of(run.shard, yres);
    let rows = Rows {
        start: lines.start * xres,
        end: lines.end * xres,
        total: xres * yres,
    };
    let nrec = rows.len();
    let ncols = job.mode.ncols();
    let matrix = !matches!(job.mode, Mode::Values);
    let mut se_out = output::SeWriter::open(run.se_out.as_deref(), command, nrec)?;
    let mut rw_out = ReweightFile::open(reweight, nrec, ncols, job.ncomp)?;
    let mut sink = if matrix {
        let mut header = output::header(
            command,
            Some(cam.view()),
            &channels,
            Some(rows.total),
            ncols,
            format,
        );
        rows.mark(run.shard, &mut header);
        Sink::matrix(
            out, header, nrec, ncols, channels, format, run.header, seekable,
        )?
    } else {
        let header = output::header(command, Some(cam.view()), &channels, None, 0, format);
        Sink::picture_to(
            run.picture_file.as_deref(),
            out,
            header,
            xres,
            yres,
            channels,
        )?
    };
    let stage = Stage::new(progress, "tracing", Some(nrec as u64), "pixels");
    // Whole scanlines per block, so picture rows can be written as they complete.
    let lines_per_block = (job.block_len() / xres).max(1);
    let mut py = lines.start;
    while py < lines.end {
        let end = (py + lines_per_block).min(lines.end);
        let pixels: Vec<(usize, usize)> = (py..end)
            .flat_map(|y| (0..xres).map(move |x| (x, y)))
            .collect();
        let results = job.block((py * xres) as u64, &pixels, &query, progress);
        if matrix {
            for r in &results {
                sink.write_row(&r.values)?;
            }
        } else {
            for line in results.chunks(xres) {
                let vals: Vec<f64> = line.iter().flat_map(|r| r.values.clone()).collect();
                sink.write_row(&vals)?;
            }
        }
        for r in &results {
            se_out.write(r)?;
            rw_out.write(r)?;
        }
        sink.flush()?;
        py = end;
    }
    drop(stage);
    se_out.finish()?;
    rw_out.finish()?;
    sink.finish()?;
    Ok(rows)
}

/// Where `--reweight` goes and what its header says.
pub struct ReweightOut {
    pub path: String,
    pub materials: Vec<String>,
    pub entries: Vec<crate::trace::reweight::Entry>,
    pub command: String,
}

/// The `--reweight` file being written: rows go to a temporary file beside the target,
/// renamed over it by [`ReweightFile::finish`] (a failed run leaves nothing half-written).
struct ReweightFile {
    inner: Option<(
        String,
        std::path::PathBuf,
        RowWriter<std::io::BufWriter<std::fs::File>>,
    )>,
}

impl ReweightFile {
    fn open(r: Option<&ReweightOut>, nrows: usize, ncols: usize, ncomp: usize) -> Result<Self> {
        let Some(r) = r else {
            return Ok(ReweightFile { inner: None });
        };
        let tmp = crate::io::temp_beside(std::path::Path::new(&r.path));
        let f = std::fs::File::create(&tmp).map_err(|e| Error::io(&r.path, e))?;
        let w = RowWriter::start(
            std::io::BufWriter::new(f),
            &r.materials,
            &r.entries,
            nrows,
            ncols,
            ncomp,
            &r.command,
        )
        .map_err(|e| Error::io(&r.path, e))?;
        Ok(ReweightFile {
            inner: Some((r.path.clone(), tmp, w)),
        })
    }

    fn write(&mut self, r: &RecordResult) -> Result<()> {
        if let Some((path, _, w)) = &mut self.inner {
            w.row(&r.terms).map_err(|e| Error::io(path.as_str(), e))?;
        }
        Ok(())
    }

    fn finish(mut self) -> Result<()> {
        if let Some((path, tmp, w)) = self.inner.take() {
            let mut f = w.into_inner();
            let closed = f.flush();
            drop(f);
            crate::io::replace_with(&tmp, &path, closed)?;
        }
        Ok(())
    }
}

impl Drop for ReweightFile {
    fn drop(&mut self) {
        if let Some((_, tmp, _)) = self.inner.take() {
            let _ = std::fs::remove_file(tmp);
        }
    }
}
