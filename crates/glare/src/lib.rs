//! # Glare evaluation of fisheye and perspective pictures (evalglare 3.x counterpart)
//!
//! Source: evalglare 3.06 (`src/util/evalglare.c`, `src/util/pictool.c` of Radiance,
//! J. Wienold, Fraunhofer ISE / EPFL); what its *code* does, documented in
//! `docs/radiance-notes.md` §9, where it differs from its older man page (v2.10): the default
//! detection threshold is **2000 cd/m² absolute** (a multiple of the task luminance only
//! with `-t`/`-T`), and the low-light DGP correction is **off** unless `-C l+` is given.
//!
//! Pipeline ([`evaluate`]):
//! 1. [`pixels`]: per-pixel direction, solid angle (the spherical quadrilateral of the
//!    pixel's corner rays), luminance and validity, in evalglare's pixel layout;
//! 2. E_v = Σ cos·ω·L, the mean luminance L̄ = Σ ω L / Σ ω and per-pixel position-weighted
//!    statistics over valid pixels;
//! 3. [`detect`]: glare sources (threshold, search-radius merging, peak extraction);
//! 4. [`posindex`]: each source's position index (Guth above, Iwata below the line of sight);
//! 5. [`metrics`]: DGP, DGI, UGR, VCP, CGI, Lveil and the others;
//! 6. [`report`]: evalglare's output lines; [`check`]: the check picture.
//!
//! Known residuals: a source's direction (σ, τ, position index, Lveil) is taken at its
//! centroid *truncated* to a pixel, as evalglare does; a centroid that is an integer in
//! exact arithmetic (one- or two-pixel sources) can land one pixel apart when the last bits
//! of the running means differ (seen once in 28 fixtures: Lveil 14088 vs 14479 on
//! `furnished_clear_window`, every other printed metric equal). `-vth` rim pixels: see
//! [`pixels`].
//!
//! Annual glare without pictures (`rglare annual`, dcglare's counterpart): [`annual`] on
//! the view rays of [`viewrays`], command line in [`annual_cli`].
//!
//! Agreement with evalglare 3.06 is tested on the pictures of `radiance-fixtures/glare/`
//! and `radiance-fixtures/pictures/` (`tests/all/rglare.rs`).

use rdaylight_base::{error, progress, radiometry, vec3};
use rdaylight_formats as formats;
use rdaylight_formats::scene;
use rdaylight_physics::sky;
use rdaylight_trace::rdc;

pub mod annual;
pub mod check;
pub mod detect;
pub mod metrics;
pub mod pixels;
pub mod posindex;
pub mod report;
pub mod viewrays;

pub use detect::{DetectOptions, Detection, Method, Source};
pub use metrics::{DgpCoefficients, Metrics};
pub use pixels::Pixels;
pub use posindex::PosModel;

use crate::error::{Error, Location, Result};
use crate::formats::picture::Picture;
use crate::formats::view::{View, ViewType};
use pixels::dot;

/// Background luminance choice (`-q`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Background {
    /// `(E_v − E_dir)/π` (`-q 0`, default).
    #[default]
    Cosine,
    /// Mean luminance without the sources (`-q 1`).
    MeanWithoutSources,
    /// `E_v/π` (`-q 2`).
    Ev,
}

/// Everything that shapes an evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Detection.
    pub detect: DetectOptions,
    /// Position-index model (`-P`).
    pub model: PosModel,
    /// DGP coefficients (`-w`).
    pub dgp: DgpCoefficients,
    /// Low-light correction (`-C l+`).
    pub low_light: bool,
    /// Background luminance (`-q`).
    pub background: Background,
    /// Compute [`PositionStats`] (a position index per pixel and three medians over a
    /// million pixels: a third of the work on a large fisheye). evalglare prints them only
    /// with `-d`, so `rglare` turns this off for its other outputs. Default on.
    pub position_stats: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            detect: DetectOptions::default(),
            model: PosModel::default(),
            dgp: DgpCoefficients::default(),
            low_light: false,
            background: Background::default(),
            position_stats: true,
        }
    }
}

/// evalglare's per-pixel position-weighted statistics over the valid pixels (the last
/// values of its `-d` line).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PositionStats {
    /// evalglare's `av_lum_pos`: Σ (L/P) ω / Σω.
    pub av_lum_pos: f64,
    /// evalglare's `av_lum_pos2`: Σ (L/P²) ω / (Σω)² (divided twice in its code).
    pub av_lum_pos2: f64,
    /// Median luminance of valid pixels.
    pub med_lum: f64,
    /// Median of L/P.
    pub med_lum_pos: f64,
    /// Median of L/P².
    pub med_lum_pos2: f64,
}

/// One glare source as reported (evalglare's `-d` table row).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SourceReport {
    /// Pixels.
    pub npix: f64,
    /// Centroid x (pixels from the left).
    pub x: f64,
    /// Centroid y (pixels from the top, as evalglare prints `ysize − y`).
    pub y: f64,
    /// Mean luminance (cd/m²).
    pub lum: f64,
    /// Solid angle (sr).
    pub omega: f64,
    /// Position index.
    pub pos: f64,
    /// Angle from the view direction (deg).
    pub sigma_deg: f64,
    /// Direction of the centroid pixel.
    pub dir: [f64; 3],
    /// Σ cos·ω·L (lx).
    pub eglare: f64,
    /// CIE veiling luminance `10·Eglare/θ²`.
    pub lveil_cie: f64,
    /// θ (deg) from the view direction, as used for `lveil_cie`.
    pub teta: f64,
    /// Share of the DGP log term: this source's term over the total.
    pub r_contrast: f64,
    /// This source's term over DGP.
    pub r_dgp: f64,
}

/// The result for one picture.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// Sources in evalglare's order.
    pub sources: Vec<SourceReport>,
    /// Metrics.
    pub metrics: Metrics,
    /// Vertical illuminance (lx).
    pub e_v: f64,
    /// Direct vertical illuminance from the sources (lx).
    pub e_dir: f64,
    /// Mean luminance over valid pixels.
    pub avlum: f64,
    /// Background luminance per `-q`.
    pub lum_backg: f64,
    /// Task luminance (the mean luminance without a task).
    pub lum_task: f64,
    /// Largest pixel luminance.
    pub abs_max: f64,
    /// Σω L / Σω of the sources.
    pub lum_sources: f64,
    /// Σω of the sources.
    pub omega_sources: f64,
    /// Σ Lveil_cie.
    pub lveil_cie: f64,
    /// Position-weighted statistics (`None` unless [`Options::position_stats`]).
    pub position: Option<PositionStats>,
    /// Threshold used (cd/m²) and how.
    pub threshold: f64,
    /// How the threshold was obtained.
    pub method: Method,
    /// Warnings and notices evalglare would print on stderr.
    pub notices: Vec<String>,
    /// Source number of every pixel (evalglare layout, renumbered 1..=n, 0 = none); for
    /// the check picture.
    pub gsn: Vec<u32>,
}

/// The view to evaluate `pic` with: its header's `VIEW=` lines, then `user` options on top
/// (evalglare replaces the header view by the command-line view when one is given).
/// Errors: no view, parallel view, invalid view.
pub fn picture_view(pic: &Picture, name: &str, user: Option<&View>) -> Result<View> {
    let view = match user {
        Some(v) => *v,
        None => {
            let mut v = View::default();
            if v.apply_header(&pic.header, name)? == 0 {
                return Err(Error::parse(
                    Location::file(name),
                    "no view in the header (no VIEW= line); give one with -vf or -vt/-vh/-vv",
                ));
            }
            v
        }
    };
    if view.vtype == ViewType::Parallel {
        return Err(Error::parse(
            Location::file(name),
            "parallel view (-vtl) cannot be evaluated for glare; expected a fisheye or perspective view",
        ));
    }
    Ok(view)
}

/// Median of `v` (the mean of the two middle values for an even count), reordering `v`.
fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    // Selection instead of a full sort (a million pixels, three medians per picture): the
    // same order statistics, in linear time.
    let n = v.len();
    let (below, mid, _) = v.select_nth_unstable_by(n / 2, |a, b| a.total_cmp(b));
    let mid = *mid;
    if n % 2 == 0 {
        let lower = below
            .iter()
            .copied()
            .max_by(|a, b| a.total_cmp(b))
            .unwrap_or(mid);
        (mid + lower) / 2.0
    } else {
        mid
    }
}

/// [`PositionStats`] of the valid pixels, summed in pixel order as evalglare does.
fn position_stats(p: &Pixels, model: PosModel, sang: f64) -> PositionStats {
    use rayon::prelude::*;
    let frame = posindex::Frame::new(p.camera.dir(), p.camera.view().vu);
    let ok = |i: usize| p.inview[i] && p.valid[i];
    let mut lum: Vec<f64> = (0..p.lum.len())
        .filter(|&i| ok(i))
        .map(|i| p.lum[i])
        .collect();
    let mut lum_pos = vec![0.0; lum.len()];
    let mut lum_pos2 = vec![0.0; lum.len()];
    // the position index of every valid pixel (the costly part), in parallel
    let valid: Vec<usize> = (0..p.lum.len()).filter(|&i| ok(i)).collect();
    valid
        .par_iter()
        .zip(lum_pos.par_iter_mut())
        .zip(lum_pos2.par_iter_mut())
        .for_each(|((&i, a), b)| {
            let pos = frame.posindex(p.dir[i], model);
            *a = p.lum[i] / pos;
            *b = p.lum[i] / pos / pos;
        });
    let (mut pos1, mut pos2) = (0.0, 0.0);
    for (k, &i) in valid.iter().enumerate() {
        let om = p.omega[i];
        pos1 += lum_pos[k] * om;
        pos2 += lum_pos2[k] * om;
    }
    drop(valid);
    PositionStats {
        av_lum_pos: pos1 / sang,
        av_lum_pos2: pos2 / sang / sang,
        med_lum: median(&mut lum),
        med_lum_pos: median(&mut lum_pos),
        med_lum_pos2: median(&mut lum_pos2),
    }
}

/// Vertical illuminance only (`-V`).
pub fn vertical_illuminance(p: &Pixels) -> f64 {
    let vdir = p.camera.dir();
    (0..p.dir.len())
        .filter(|&i| p.inview[i] && p.valid[i])
        .map(|i| dot(vdir, p.dir[i]) * p.omega[i] * p.lum[i])
        .sum()
}

/// Evaluate one picture with a view already chosen.
pub fn evaluate(pic: &Picture, view: &View, opts: &Options) -> Result<Evaluation> {
    let camera = view.setup()?;
    let p = Pixels::new(pic, camera);
    Ok(evaluate_pixels(&p, opts))
}

/// Evaluate prepared pixels.
pub fn evaluate_pixels(p: &Pixels, opts: &Options) -> Evaluation {
    let vdir = p.camera.dir();
    let vup = p.camera.view().vu;
    let model = opts.model;
    let mut notices = Vec::new();
    if p.camera.view().vtype == ViewType::Perspective {
        notices.push("warning: image has perspective view type specified in header !".into());
    }

    // pass over valid pixels: E_v, mean luminance (in pixel order, as evalglare sums)
    let (mut sang, mut e_v, mut avlum, mut abs_max) = (0.0, 0.0, 0.0, 0.0f64);
    for i in 0..p.lum.len() {
        if !(p.inview[i] && p.valid[i]) {
            continue;
        }
        let (om, l) = (p.omega[i], p.lum[i]);
        abs_max = abs_max.max(l);
        sang += om;
        e_v += dot(vdir, p.dir[i]) * om * l;
        avlum += om * l;
    }
    let avlum = avlum / sang;
    let position = opts
        .position_stats
        .then(|| position_stats(p, opts.model, sang));

    let det = detect::detect(p, &opts.detect, avlum);
    notices.extend(det.warnings.iter().map(|w| format!("warning: {w}")));

    // active sources in internal order, renumbered 1..=n
    let mut renum = vec![0u32; det.sources.len()];
    let mut active = Vec::new();
    for (g, s) in det.sources.iter().enumerate() {
        if s.npix > 0.0 {
            active.push(g);
            renum[g] = active.len() as u32;
        }
    }
    // fold from +0: an empty f64 sum is −0, which would print as "-0.000000"
    let e_dir = active.iter().fold(0.0, |s, &g| s + det.sources[g].eglare);
    let lum_backg_cos = (e_v - e_dir) / metrics::PI_EG;

    let mut terms = Vec::with_capacity(active.len());
    let mut dirs = Vec::with_capacity(active.len());
    for &g in &active {
        let s = &det.sources[g];
        let d = p.dir_at(s.posx, s.posy).unwrap_or([0.0; 3]);
        let ang = posindex::angles(vdir, vup, d);
        terms.push(metrics::SourceTerm {
            lum: s.lum,
            omega: s.omega,
            pos: posindex::posindex(vdir, vup, d, model),
            sigma: ang.sigma,
        });
        dirs.push(d);
    }
    let lum_sources_sum: f64 = terms.iter().map(|t| t.lum * t.omega).sum();
    let omega_sources: f64 = terms.iter().map(|t| t.omega).sum();
    let lum_backg = match opts.background {
        Background::Cosine => lum_backg_cos,
        Background::Ev => e_v / metrics::PI_EG,
        Background::MeanWithoutSources => {
            if sang == omega_sources {
                avlum
            } else {
                (sang * avlum - lum_sources_sum) / (sang - omega_sources)
            }
        }
    };
    let lum_sources = if terms.is_empty() {
        0.0
    } else {
        lum_sources_sum / omega_sources
    };
    let m = metrics::metrics(
        &terms,
        e_v,
        e_dir,
        lum_backg,
        lum_backg_cos,
        avlum,
        &opts.dgp,
        opts.low_light,
    );

    // the per-source table
    let c2 = opts.dgp.c[1];
    let a3 = opts.dgp.a[2];
    let sum_term: f64 = terms
        .iter()
        .map(|t| t.lum.powi(2) * t.omega / t.pos.powi(2))
        .sum();
    let sum_glare = c2 * (1.0 + sum_term / e_v.powf(a3)).log10();
    let mut sources = Vec::with_capacity(active.len());
    let mut lveil_cie = 0.0;
    for (k, &g) in active.iter().enumerate() {
        let s = &det.sources[g];
        let t = &terms[k];
        let teta = posindex::DEG * dot(vdir, dirs[k]).acos();
        let lc = 10.0 * s.eglare / (teta * teta + 0.0000000000000001);
        lveil_cie += lc;
        let r_glare = c2 * (1.0 + t.lum.powi(2) * t.omega / t.pos.powi(2) / e_v.powf(a3)).log10();
        sources.push(SourceReport {
            npix: s.npix,
            x: s.posx,
            y: p.yres as f64 - s.posy,
            lum: s.lum,
            omega: s.omega,
            pos: t.pos,
            sigma_deg: t.sigma * posindex::DEG,
            dir: dirs[k],
            eglare: s.eglare,
            lveil_cie: lc,
            teta,
            r_contrast: r_glare / sum_glare,
            r_dgp: r_glare / m.dgp_raw,
        });
    }

    if e_v < 100.0 {
        notices.push("Notice: Vertical illuminance is below 100 lux !!".into());
    }
    if m.dgp <= 0.2 {
        notices.push(
            "Notice: Low brightness scene. dgp below 0.2! dgp might underestimate glare sources"
                .into(),
        );
    }
    if e_v < 380.0 {
        notices.push("Notice: Low brightness scene. Vertical illuminance less than 380 lux! dgp might underestimate glare sources".into());
    }
    let mut gsn = det.gsn;
    for g in &mut gsn {
        *g = renum[*g as usize];
    }
    Evaluation {
        sources,
        metrics: m,
        e_v,
        e_dir,
        avlum,
        lum_backg,
        lum_task: det.lum_task,
        abs_max,
        lum_sources,
        omega_sources,
        lveil_cie,
        position,
        threshold: det.threshold,
        method: det.method,
        notices,
        gsn,
    }
}
