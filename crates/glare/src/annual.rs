//! # Annual glare without pictures (imageless DGP from daylight coefficients)
//!
//! Radiance's `dcglare` (N. Jones, `src/util/dcglare.c`, `cmglare.c`; Jones 2019, "Fast
//! climate-based glare analysis and spatial mapping", Building Simulation 2019) computes an
//! *enhanced simplified* DGP per time step from an eye sensor's daylight coefficients: every
//! sky patch seen directly is a glare source whose luminance is the patch's sky luminance;
//! Ev comes from the total coefficients. That finds the sky through a window but never a
//! sunlit floor or a bright surface, and its sources are sky patches (0.04 sr at MF 1).
//!
//! This module keeps dcglare's idea (coefficients once, a sky matrix, sources by a fixed
//! luminance threshold, Guth index from view direction and up, DGP per step) but, as the
//! issue asks, takes the luminances from a **coarse grid of view rays**
//! ([`super::viewrays::ViewRays`], e.g. 64 × 64 over a 180° fisheye, ≈3 200 rays) so what
//! evalglare would see in a picture (window, sunlit surfaces) is there at a few thousand
//! rays instead of the 1e6 of an 1000² picture. Per view, computed once with `rdc`
//! ([`crate::rdc::Tracer`]):
//!
//! | quantity | rdc run | meaning |
//! |---|---|---|
//! | `C_ray` | `-m MF -ab N` view rays | luminance of each ray per sky patch (total) |
//! | `C_ray0` | `-m MF -ab 0` view rays | the part seen straight through the glazing |
//! | `C_eye`, `C_eye,d` | `-I -m MF -ab N`, `-I --direct -m MF` | the eye sensor, facing the view direction |
//! | `C_sun` | `-I --suns weather` | exact sun per time step, direct only (`T cos θ Ω`) |
//!
//! and per time step `t` with the Perez sky vector `s_t` (gendaymtx, sun spread over its
//! four nearest patches) and its sun part `s_t,sun` (the same sun entries alone), with the
//! sun's radiance `R_t = E_dir,n / (179 Ω_sun)`:
//!
//! ```text
//! L_i  = 179 Y( C_ray,i · s_t  − C_ray0,i · s_t,sun )        rays (sun only as reflected)
//! E_sun = 179 Y( C_sun,t ) R_t                                   the exact disc's E_v
//! E_v  = Σ_i L_i cos θ_i ω_i + E_sun                             (default, `--ev rays`)
//!      or 179 Y( C_eye · s_t − C_eye,d · s_t,sun ) + E_sun        (`--ev sensor`; DDS,
//!                                                                 Bourgeois et al. 2008)
//! sun  = source of luminance E_sun/(cos θ Ω_sun), solid angle Ω_sun (0.533°)
//!        when the sun is in the view and not blocked
//! ```
//!
//! Why E_v from the rays by default: it is what evalglare integrates from a picture, and
//! the sensor's indirect-sun term rests on the few of its samples that leave through the
//! window into the four sun patches, so it is noisy (measured: the 4/11 12:30 cross-check
//! hour varied by ±7 % of E_v over seeds at `--eye-ad 65536`), while the rays pool
//! `-ad` samples of thousands of rays (±1 % there at 32 × 32 rays, `-ad 128`). A view ray
//! that hits a surface counts `-ab` bounces from there, as rpict does, so match rpict's
//! `-ab` when comparing with pictures (the sensor's `-ab` counts the eye's own bounce).
//!
//! `Y` is Radiance's RGB luminance ([`RGB_PHOTOPIC`]). Subtracting the directly seen sun
//! patches from the rays removes the smeared sun (a 0.17 sr patch group at 1e6 cd/m² would
//! be a glare source no picture shows); the exact disc replaces it.
//!
//! Glare sources: rays above the threshold (`-b`, default **2000 cd/m² absolute**, as
//! evalglare 3.x and dcglare; at most 100 it is a factor times E_v/π, dcglare's rule) merged
//! when 8-connected on the grid (each merged source: Σω, mean luminance Σ Lω/Σω, the
//! direction of its ω-weighted centroid), plus the sun disc. DGP (Wienold & Christoffersen
//! 2006) from [`super::metrics::dgp`] with the position index of [`super::posindex`];
//! evalglare's low-light correction only with `-C l+` (dcglare always applies it and uses
//! its own rounded constants 0.0918/0.16, evalglare's are kept here). A step without light
//! (E_v = 0) has DGP 0, as in dcglare.
//!
//! What the imageless route loses against a picture (see the cross-check in
//! `radiance-fixtures/glare/annual/`): contrast below the grid (a 2.8° ray cell averages a
//! window frame with the sky behind it; a source smaller than a cell is diluted), the
//! evalglare search-radius merge and peak extraction, and the picture's own sun sampling
//! (rpict hits or misses the 0.53° disc per pixel).

use super::metrics::{self, DgpCoefficients, SourceTerm};
use super::pixels::{V3, dot};
use super::posindex::{self, PosModel};
use super::viewrays::ViewRays;
use crate::error::{Error, Result};
use crate::formats::sensors::SensorRay;
use crate::formats::weather::Weather;
use crate::progress::{Progress, Stage};
use crate::radiometry::Channels;
use crate::radiometry::{RGB_PHOTOPIC, WHITE_EFFICACY};
use crate::rdc::config::{MAX_MF, SUN_ANGLE_DEG};
use crate::rdc::{Config, SunSource, Target, Tracer};
use crate::scene::Scene;
use crate::sky::matrix::time_steps;
use crate::sky::perez::{GENDAYMTX_GROUND_REFLECTANCE, GENDAYMTX_SKY_COLOUR, PerezOptions};
use crate::sky::{SkyPatches, perez::perez_sky_vector};
use rayon::prelude::*;

/// Below this threshold value `-b` is a factor of E_v/π (dcglare's `LUMINANCE_THRESHOLD`).
pub const THRESHOLD_FACTOR_LIMIT: f64 = 100.0;

/// EN 17037:2018 glare-protection limits (DGP not exceeded in 95 % of occupied hours).
pub const EN17037_LIMITS: [f64; 3] = [0.35, 0.40, 0.45];

/// Settings of the evaluation (not of the coefficients).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnnualOptions {
    /// `-b`: > 100 absolute cd/m², else a factor of E_v/π.
    pub threshold: f64,
    /// `-l`: DGP limit of glare autonomy (DGP < limit counts as free of glare).
    pub limit: f64,
    /// `-C l+`: evalglare's low-light correction.
    pub low_light: bool,
    /// DGP coefficients.
    pub dgp: DgpCoefficients,
    /// Position-index model.
    pub model: PosModel,
    /// Sun disc apex angle (degrees).
    pub sun_angle: f64,
    /// E_v from the view rays (Σ L cos θ ω, as evalglare integrates a picture) plus the
    /// exact sun, instead of the eye sensor (`--ev rays|sensor`).
    pub ev_from_rays: bool,
}

impl Default for AnnualOptions {
    fn default() -> Self {
        AnnualOptions {
            threshold: 2000.0,
            limit: 0.4,
            low_light: false,
            dgp: DgpCoefficients::default(),
            model: PosModel::GuthIwata,
            sun_angle: 0.533,
            ev_from_rays: true,
        }
    }
}

/// Coefficients of one view, as luminance (or illuminance) per unit of sky scalar.
#[derive(Debug, Clone)]
pub struct Coefficients {
    /// Sky patches including the ground (146 at MF 1).
    pub npatch: usize,
    /// Per ray: `179 Y(C_ray[p] ⊙ colour[p])` for every patch (sky colour, ground
    /// reflectance at patch 0): luminance per unit sky scalar.
    pub ray_sky: Vec<Vec<f64>>,
    /// Per ray: `179 Y(C_ray[p] − C_ray0[p])` (white sun): luminance per unit sun radiance
    /// reaching the ray after at least one reflection.
    pub ray_sun: Vec<Vec<f64>>,
    /// Eye sensor, per patch: `179 Y(C_eye[p] ⊙ colour[p])` (lx per unit scalar).
    pub eye_sky: Vec<f64>,
    /// Eye sensor, per patch: `179 Y(C_eye[p] − C_eye,d[p])`.
    pub eye_sun: Vec<f64>,
    /// Eye sensor direct-only, per patch: `179 Y(C_eye,d[p] ⊙ colour[p])` (dcglare's
    /// `DCdirect` times the sky colour).
    pub eye_direct_sky: Vec<f64>,
    /// Eye sensor direct-only, per patch: `179 Y(C_eye,d[p])` (white, for the sun).
    pub eye_direct_sun: Vec<f64>,
    /// Per weather step: `179 Y(C_sun,t)` = T cos θ Ω_sun (lx per unit sun radiance).
    pub sun_direct: Vec<f64>,
}

fn luminance(rgb: &[f64], colour: &[f64]) -> f64 {
    WHITE_EFFICACY
        * rgb
            .iter()
            .zip(colour)
            .zip(RGB_PHOTOPIC)
            .map(|((v, c), w)| v * c * w)
            .sum::<f64>()
}

/// The tracer runs of the module documentation. `base` carries the sampling (`-ab`, `-ad`,
/// `-lw`), the sky subdivision (a `Target::Sky`'s MF, else 1), seed and threads; `weather`
/// is the file whose steps place the suns; `eye_ad` the samples of the single eye sensor
/// (cheap: one record).
pub fn coefficients(
    base: &Config,
    scene: &Scene,
    rays: &ViewRays,
    weather: &str,
    eye_ad: usize,
    progress: &dyn Progress,
) -> Result<Coefficients> {
    if base.channels != Channels::rgb() {
        return Err(Error::Usage(
            "annual glare uses RGB sky matrices (gendaymtx colours): -cs/-cw are not supported"
                .into(),
        ));
    }
    let mf = match base.target {
        Target::Sky { mf, .. } => mf,
        _ => 1,
    };
    let sky = Config {
        target: Target::sky(mf),
        irradiance: false,
        ..base.clone()
    };
    let ray_list: Vec<SensorRay> = (0..rays.len())
        .map(|i| SensorRay::new(rays.org[i], rays.dir[i]))
        .collect();
    // One stage per tracer run, a unit per ray.
    let trace = |stage: &str, config: &Config, rays: &[SensorRay]| {
        let s = Stage::new(progress, stage, Some(rays.len() as u64), "rays");
        Tracer::new(config, scene)?.compute_reporting(rays, s.progress())
    };
    let total = trace("view-ray sky coefficients", &sky, &ray_list)?;
    let mut direct = sky.clone();
    direct.sampling.ab = 0;
    let straight = trace("view-ray direct coefficients (-ab 0)", &direct, &ray_list)?;
    let vdir = rays.camera.dir();
    let eye = [SensorRay::new(rays.camera.view().vp, vdir)];
    let mut eye_cfg = Config {
        irradiance: true,
        ..sky.clone()
    };
    eye_cfg.sampling.ad = eye_ad;
    // rdc starts a sensor path at weight 1/-ad; with -ad above 1/-lw its roulette runs
    // from the first hit and was measured biased low through glazing (sky coefficients of
    // the furnished office summed 0.83 at -ad 4096 -lw 2e-3 against rcontrib's 0.95, 0.97
    // at -lw 1e-5), so the eye sensor gets -lw at most 0.05/-ad.
    eye_cfg.sampling.lw = sky.sampling.lw.min(0.05 / eye_ad as f64);
    let eye_total = trace("eye sensor coefficients", &eye_cfg, &eye)?;
    eye_cfg.target = Target::Sky {
        mf,
        direct_only: true,
        below_horizon: false,
    };
    let eye_direct = trace("eye sensor direct coefficients", &eye_cfg, &eye)?;
    let mut sun_cfg = Config {
        target: Target::Suns {
            suns: SunSource::Weather(weather.to_string()),
            angle_deg: SUN_ANGLE_DEG,
            bounces: false,
        },
        irradiance: true,
        ..base.clone()
    };
    sun_cfg.sampling.ad = 1; // direct sun coefficients are deterministic
    let suns = trace("eye sensor sun coefficients", &sun_cfg, &eye)?;

    let npatch = SkyPatches::new(mf).len();
    let colour = |p: usize| -> [f64; 3] {
        if p == 0 {
            GENDAYMTX_GROUND_REFLECTANCE
        } else {
            GENDAYMTX_SKY_COLOUR
        }
    };
    const WHITE: [f64; 3] = [1.0; 3];
    let per_patch_sky = |v: &[f64]| -> Vec<f64> {
        (0..npatch)
            .map(|p| luminance(&v[p * 3..p * 3 + 3], &colour(p)))
            .collect()
    };
    let per_patch_diff = |a: &[f64], b: &[f64]| -> Vec<f64> {
        (0..npatch)
            .map(|p| {
                let d: Vec<f64> = (0..3).map(|c| a[p * 3 + c] - b[p * 3 + c]).collect();
                luminance(&d, &WHITE)
            })
            .collect()
    };
    let ray_sky = total.iter().map(|r| per_patch_sky(&r.values)).collect();
    let ray_sun = total
        .iter()
        .zip(&straight)
        .map(|(t, s)| per_patch_diff(&t.values, &s.values))
        .collect();
    let sun_direct = suns[0]
        .values
        .chunks(3)
        .map(|c| luminance(c, &WHITE))
        .collect();
    Ok(Coefficients {
        npatch,
        ray_sky,
        ray_sun,
        eye_sky: per_patch_sky(&eye_total[0].values),
        eye_direct_sky: per_patch_sky(&eye_direct[0].values),
        eye_direct_sun: (0..npatch)
            .map(|p| luminance(&eye_direct[0].values[p * 3..p * 3 + 3], &WHITE))
            .collect(),
        eye_sun: per_patch_diff(&eye_total[0].values, &eye_direct[0].values),
        sun_direct,
    })
}

/// The result of one time step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepResult {
    /// DGP (0 without light).
    pub dgp: f64,
    /// Vertical illuminance at the eye (lx).
    pub ev: f64,
    /// Its direct-sun part (lx).
    pub ev_sun: f64,
    /// Glare sources (merged ray groups plus the sun disc).
    pub nsources: usize,
    /// The sun disc is in view and not blocked.
    pub sun_in_view: bool,
    /// Largest ray luminance (cd/m²), the sun disc excluded.
    pub lmax: f64,
    /// Threshold used (cd/m²).
    pub threshold: f64,
    /// dcglare's enhanced simplified DGP for the same step ([`dcglare_edgps`]).
    pub dgp_dcglare: f64,
}

/// The sky of one step: per-patch scalars (sky and ground, before colour), the smeared sun
/// entries, and the sun disc (direction, radiance).
struct StepSky {
    scalar: Vec<f64>,
    sun: Vec<(usize, f64)>,
    disc: Option<(V3, f64)>,
}

fn step_sky(
    patches: &SkyPatches,
    step: &crate::sky::perez::TimeStep,
    site: &crate::formats::weather::Site,
    sun_angle: f64,
) -> StepSky {
    let v = perez_sky_vector(patches, step, site, &PerezOptions::default());
    let mut scalar = v.sky.clone();
    scalar[0] = v.ground;
    let omega = 2.0 * std::f64::consts::PI * (1.0 - (sun_angle.to_radians() / 2.0).cos());
    // the disc exists when rdc made a sun column (altitude > 0) and there is direct light
    let disc = v.state.and_then(|s| {
        (s.dir_illum > 1e-4 && v.sun_position.altitude > 0.0).then(|| {
            (
                v.sun_position.direction(),
                s.dir_illum / WHITE_EFFICACY / omega,
            )
        })
    });
    StepSky {
        scalar,
        sun: v.sun,
        disc,
    }
}

/// Evaluate one step.
fn evaluate_step(
    c: &Coefficients,
    rays: &ViewRays,
    sky: &StepSky,
    sun_direct: f64,
    o: &AnnualOptions,
) -> StepResult {
    let vdir = rays.camera.dir();
    let vup = rays.camera.view().vu;
    let mut ev: f64 = c.eye_sky.iter().zip(&sky.scalar).map(|(a, s)| a * s).sum();
    ev += sky.sun.iter().map(|&(p, r)| c.eye_sun[p] * r).sum::<f64>();
    let omega_sun = 2.0 * std::f64::consts::PI * (1.0 - (o.sun_angle.to_radians() / 2.0).cos());
    let mut sun_source = None;
    let mut ev_sun = 0.0;
    if let Some((d, r)) = sky.disc {
        ev_sun = sun_direct * r;
        let cos = dot(d, vdir);
        let vp = rays.camera.view().vp;
        let seen = rays
            .camera
            .view_loc([vp[0] + d[0], vp[1] + d[1], vp[2] + d[2]])
            .is_some_and(|l| l.visible());
        if ev_sun > 0.0 && cos > 0.0 && seen {
            sun_source = Some((d, ev_sun / (cos * omega_sun)));
        }
    }
    ev += ev_sun;
    let lum: Vec<f64> = (0..rays.len())
        .map(|i| {
            let mut l: f64 = c.ray_sky[i]
                .iter()
                .zip(&sky.scalar)
                .map(|(a, s)| a * s)
                .sum();
            l += sky
                .sun
                .iter()
                .map(|&(p, r)| c.ray_sun[i][p] * r)
                .sum::<f64>();
            l.max(0.0)
        })
        .collect();
    if o.ev_from_rays {
        ev = ev_sun
            + (0..rays.len())
                .map(|i| lum[i] * rays.omega[i] * dot(rays.dir[i], vdir).max(0.0))
                .sum::<f64>();
    }
    let threshold = if o.threshold > THRESHOLD_FACTOR_LIMIT {
        o.threshold
    } else {
        o.threshold * ev / metrics::PI_EG
    };
    let dgp_dcglare = dcglare_edgps(c, sky, vdir, vup, o.threshold);
    if ev <= 0.0 {
        return StepResult {
            threshold,
            ..StepResult::default()
        };
    }
    let lmax = lum.iter().copied().fold(0.0, f64::max);
    let mut terms = sources(rays, &lum, threshold, vdir, vup, o.model);
    if let Some((d, l)) = sun_source {
        if l > threshold {
            terms.push(SourceTerm {
                lum: l,
                omega: omega_sun,
                pos: posindex::posindex(vdir, vup, d, o.model),
                sigma: dot(vdir, d).clamp(-1.0, 1.0).acos(),
            });
        }
    }
    let raw = metrics::dgp(ev, &terms, &o.dgp);
    let dgp = if o.low_light {
        raw * metrics::low_light_factor(ev)
    } else {
        raw
    };
    StepResult {
        dgp,
        ev,
        ev_sun,
        nsources: terms.len(),
        sun_in_view: sun_source.is_some(),
        lmax,
        threshold,
        dgp_dcglare,
    }
}

/// dcglare's enhanced simplified DGP (`cm_glare` in `src/util/cmglare.c`; Jones 2019) from
/// the eye sensor alone, for comparison: E_v from the total coefficients with the
/// gendaymtx sky (sun spread over patches, no exact disc); every sky patch seen directly
/// (`DCdirect`) whose luminance `DCdirect·s/(ω cos θ)` reaches the threshold is a source
/// (ground: towards the centre of the visible ground, ω the visible ground's solid angle);
/// `5.87e-5 E_v + 0.0918 log10(1 + Σ L²ω/P²/E_v^1.87) + 0.16`, the low-light factor below
/// 1000 lx always, capped at 1; 0 without light.
fn dcglare_edgps(c: &Coefficients, sky: &StepSky, vdir: V3, vup: V3, thr: f64) -> f64 {
    let mut ev: f64 = c.eye_sky.iter().zip(&sky.scalar).map(|(a, s)| a * s).sum();
    let mut sun = vec![0.0; c.npatch];
    for &(p, r) in &sky.sun {
        ev += (c.eye_sun[p] + c.eye_direct_sun[p]) * r;
        sun[p] += r;
    }
    if ev <= 1e-6 {
        return 0.0;
    }
    let patches = patches_for(c.npatch);
    let min_lum = if thr < THRESHOLD_FACTOR_LIMIT {
        thr * ev / std::f64::consts::PI
    } else {
        thr
    };
    let mut sources = Vec::new();
    for (p, &sun_p) in sun.iter().enumerate() {
        let e = c.eye_direct_sky[p] * sky.scalar[p] + c.eye_direct_sun[p] * sun_p;
        if e <= 0.0 {
            continue;
        }
        let dir = if p == 0 {
            let g = [vdir[0], vdir[1], vdir[2] - 1.0];
            let l = dot(g, g).sqrt();
            if l == 0.0 {
                continue;
            }
            [g[0] / l, g[1] / l, g[2] / l]
        } else {
            patches.centre(p)
        };
        let cos = dot(vdir, dir);
        if cos <= 1e-9 {
            continue;
        }
        let omega = if p == 0 {
            2.0 * (std::f64::consts::PI - 2.0 * cos.acos())
        } else {
            patches.solid_angle(p)
        };
        let lum = e / (omega * cos);
        if lum < min_lum {
            continue;
        }
        sources.push(SourceTerm {
            lum,
            omega,
            pos: posindex::dcglare_posindex(dir, vdir, vup),
            sigma: cos.acos(),
        });
    }
    let mut d = metrics::dgp(ev, &sources, &DgpCoefficients::DCGLARE);
    if ev < 1000.0 {
        d *= metrics::low_light_factor(ev);
    }
    d.min(1.0)
}

/// The Reinhart sky with `npatch` patches (ground included).
fn patches_for(npatch: usize) -> SkyPatches {
    let mf = (1..=MAX_MF)
        .find(|&m| 144 * m * m + 2 == npatch)
        .unwrap_or(1);
    SkyPatches::new(mf)
}

/// Glare sources: rays above `threshold`, 8-connected groups merged (Σω, Σ Lω/Σω, the
/// ω-weighted centroid direction).
pub fn sources(
    rays: &ViewRays,
    lum: &[f64],
    threshold: f64,
    vdir: V3,
    vup: V3,
    model: PosModel,
) -> Vec<SourceTerm> {
    let mut seen = vec![false; rays.len()];
    let mut out = Vec::new();
    let mut stack = Vec::new();
    for start in 0..rays.len() {
        if seen[start] || lum[start] <= threshold {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        let (mut w, mut lw, mut d) = (0.0, 0.0, [0.0; 3]);
        while let Some(i) = stack.pop() {
            let om = rays.omega[i];
            w += om;
            lw += lum[i] * om;
            for (k, dk) in d.iter_mut().enumerate() {
                *dk += rays.dir[i][k] * om;
            }
            for j in rays.neighbours(i) {
                if !seen[j] && lum[j] > threshold {
                    seen[j] = true;
                    stack.push(j);
                }
            }
        }
        let len = dot(d, d).sqrt();
        let d = [d[0] / len, d[1] / len, d[2] / len];
        out.push(SourceTerm {
            lum: lw / w,
            omega: w,
            pos: posindex::posindex(vdir, vup, d, model),
            sigma: dot(vdir, d).clamp(-1.0, 1.0).acos(),
        });
    }
    out
}

/// DGP for every step of `weather` (in file order, night steps included with DGP 0).
pub fn evaluate(
    c: &Coefficients,
    rays: &ViewRays,
    weather: &Weather,
    o: &AnnualOptions,
    progress: &dyn Progress,
) -> Result<Vec<StepResult>> {
    let steps = time_steps(weather);
    if c.sun_direct.len() != steps.len() {
        return Err(Error::Mismatch(format!(
            "{} sun columns for {} weather steps",
            c.sun_direct.len(),
            steps.len()
        )));
    }
    let site = &weather.site;
    let patches = patches_for(c.npatch);
    if patches.len() != c.npatch {
        return Err(Error::Mismatch(format!(
            "{} patches: not a Reinhart sky",
            c.npatch
        )));
    }
    let stage = Stage::new(progress, "time steps", Some(steps.len() as u64), "steps");
    Ok(steps
        .par_iter()
        .enumerate()
        .map(|(t, s)| {
            let sky = step_sky(&patches, s, site, o.sun_angle);
            let r = evaluate_step(c, rays, &sky, c.sun_direct[t], o);
            stage.advance(1);
            r
        })
        .collect())
}

/// Occupied-hour statistics of a DGP series.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Occupied steps.
    pub occupied: usize,
    /// Share of occupied steps with DGP < the limit (dcglare's glare autonomy).
    pub autonomy: f64,
    /// The limit.
    pub limit: f64,
    /// Shares of occupied steps with DGP > 0.35, 0.40, 0.45.
    pub above: [f64; 3],
    /// EN 17037 glare-protection class: the strictest limit exceeded in at most 5 % of
    /// the occupied steps ("high", "medium", "minimum"), or "none".
    pub en17037: &'static str,
}

/// Summary over the occupied steps (`occupied[t]`).
pub fn summary(results: &[StepResult], occupied: &[bool], limit: f64) -> Summary {
    let occ: Vec<f64> = results
        .iter()
        .zip(occupied)
        .filter(|(_, o)| **o)
        .map(|(r, _)| r.dgp)
        .collect();
    let n = occ.len().max(1) as f64;
    let share = |f: &dyn Fn(f64) -> bool| occ.iter().filter(|&&d| f(d)).count() as f64 / n;
    let above = EN17037_LIMITS.map(|l| share(&|d| d > l));
    let en17037 = if above[0] <= 0.05 {
        "high"
    } else if above[1] <= 0.05 {
        "medium"
    } else if above[2] <= 0.05 {
        "minimum"
    } else {
        "none"
    };
    Summary {
        occupied: occ.len(),
        autonomy: if occ.is_empty() {
            1.0
        } else {
            share(&|d| d < limit)
        },
        limit,
        above,
        en17037,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::view::View;

    fn rays() -> ViewRays {
        let mut v = View::default();
        for a in [
            &["-vta"][..],
            &["-vh", "180"],
            &["-vv", "180"],
            &["-vd", "0", "-1", "0"],
        ] {
            v.apply_arg(a).unwrap();
        }
        ViewRays::new(&v, 32).unwrap()
    }

    #[test]
    fn connected_bright_rays_make_one_source_with_mean_luminance() {
        let r = rays();
        let mut lum = vec![100.0; r.len()];
        // a 3 × 2 block of bright cells near the centre, one far isolated cell
        let mut block = Vec::new();
        for row in 14..16 {
            for col in 14..17 {
                let i = r.index[row * 32 + col].unwrap();
                lum[i] = 5000.0 + 1000.0 * col as f64;
                block.push(i);
            }
        }
        let far = r.index[16 * 32 + 2].unwrap();
        lum[far] = 3000.0;
        let up = r.camera.view().vu;
        let s = sources(&r, &lum, 2000.0, r.camera.dir(), up, PosModel::GuthIwata);
        assert_eq!(s.len(), 2);
        let w: f64 = block.iter().map(|&i| r.omega[i]).sum();
        let lw: f64 = block.iter().map(|&i| r.omega[i] * lum[i]).sum();
        assert!((s[0].omega - w).abs() < 1e-12 && (s[0].lum - lw / w).abs() < 1e-9);
        assert!(s[0].sigma < 0.2 && s[1].sigma > 1.2);
        assert!(s[1].pos > s[0].pos);
    }

    #[test]
    fn dcglare_position_index_ahead_and_below() {
        let (f, up) = ([0.0, -1.0, 0.0], [0.0, 0.0, 1.0]);
        use posindex::dcglare_posindex;
        assert!((dcglare_posindex(f, f, up) - 1.0).abs() < 1e-9);
        // 20° straight below: θ = 0, r = |tan φ| = 0.364 ≤ 0.6, P = 1 + 0.8 r
        let a = 20f64.to_radians();
        let p = dcglare_posindex([0.0, -a.cos(), -a.sin()], f, up);
        assert!((p - (1.0 + 0.8 * a.tan())).abs() < 1e-9, "{p}");
        // far off-axis above: capped
        let b = 85f64.to_radians();
        assert_eq!(dcglare_posindex([0.0, -b.cos(), b.sin()], f, up), 16.0);
    }

    #[test]
    fn summary_counts_occupied_steps_only() {
        let r = |dgp| StepResult {
            dgp,
            ..StepResult::default()
        };
        let res = [r(0.2), r(0.38), r(0.42), r(0.5), r(0.9)];
        let s = summary(&res, &[true, true, true, true, false], 0.4);
        assert_eq!(s.occupied, 4);
        assert_eq!(s.autonomy, 0.5);
        assert_eq!(s.above, [0.75, 0.5, 0.25]);
        assert_eq!(s.en17037, "none");
        let s = summary(&res[..1], &[true], 0.4);
        assert_eq!((s.autonomy, s.en17037), (1.0, "high"));
    }
}
