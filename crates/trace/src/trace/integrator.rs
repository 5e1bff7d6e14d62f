//! Monte Carlo path tracing with Radiance's path-depth and source rules.
//!
//! Three entry points, all drawing every random number from the caller's `rand::Rng`:
//!
//! | entry | Radiance counterpart | estimate |
//! |---|---|---|
//! | [`Renderable::dc_sensor`] | `rcontrib -I+ -V- -aa 0 -as 0` with a sky binning (`rbin`) | sky coefficients per patch |
//! | [`Renderable::irradiance`] | `rtrace -I -aa 0 -as 0` | irradiance at a point (W/m^2 per channel) |
//! | [`Renderable::radiance`] | `rtrace` / `rpict` view rays | radiance along a ray (one path) |
//!
//! ## Sensor (`-I`)
//! Radiance evaluates a sensor as a white Lambertian surface ("Lamb") shaded at
//! `org + 1e-4 dir` with normal `dir` (`rcontrib.c:eval_irrad`, `rtrace.c:rtcompute`); the
//! reported value is `pi x` its radiance, i.e. irradiance. Its ambient hemisphere sampling
//! (`-ad N`) is the first diffuse bounce. Here: `N` cosine-distributed directions (jittered
//! stratification on a `floor(sqrt N)^2` grid, the rest independent), each continued as one
//! path; irradiance = `(pi/N) sum(path radiance)` plus, for `irradiance`, the direct term
//! `L omega cos` of every distant `light` (the sun) aimed at its centre (`-dj 0`).
//!
//! ## Path depth (`-ab`, `-lr`, `-lw`)
//! - `-ab`: the number of *diffuse* (ambient) bounces, the sensor's hemisphere sample
//!   counting as bounce 1. A surface reached after `ab` diffuse bounces still gets direct
//!   light (next-event estimation) and may continue through pure or Gaussian specular
//!   lobes (glass, mirrors, specular plastic: Radiance's ambient level only counts ambient
//!   rays), but its diffuse lobe returns the ambient value `-av` (default black). The
//!   material sampler picks one lobe per vertex in proportion to its coefficient, so
//!   stopping (or adding `-av`) when the diffuse lobe is picked past the limit is unbiased
//!   for that rule. `glass` is the exception: like Radiance's `glass.c` the path branches
//!   into both the transmitted and the reflected ray (no random choice, so no binomial
//!   noise on what is seen through a window).
//! - `-lw`: Radiance gives each ray a weight relative to the primary ray (an ambient sample
//!   of a sensor with `-ad N` has weight `1/N` times the path coefficient) and plays Russian
//!   roulette when it falls below `-lw` (`raytrace.c:rayorigin`: continue with probability
//!   `weight/lw`, then scale the coefficient by `lw/weight`). We use the same weight:
//!   `w0 x mean(path throughput)`, `w0 = 1/N` for sensor paths and 1 for view rays.
//!   Russian roulette leaves the expectation unchanged, so only noise depends on `-lw`.
//! - `-lr` (negative, -10 by default): a hard cap on the total number of reflections and
//!   transmissions, `max_depth`.
//!
//! ## Sources (`badcomponent`)
//! Once a path has taken a diffuse or Gaussian-specular sample it no longer sees direct
//! sources (the sun): next-event estimation counted them. Glow skies (`glow` on `source`)
//! are never direct sources and are seen by every escaping ray; a `glow` surface with
//! maxrad 0 is seen by every ray. Shadow rays pass `glass`, pure-specular `trans`, `BSDF`
//! with a thickness (a proxy), `aBSDF` (its straight-through peak) and nothing else (no caustics through mirrors: Radiance's virtual sources `-dr` are not
//! modelled, so sunlight reflected by a `mirror` is missing, as with `rtrace -dr 0`).
//!
//! ## Daylight coefficients (`dc_sensor`)
//! rcontrib `-V-` reports the *coefficient* of the tracked modifier: the path weight of
//! every ray that reaches it, not multiplied by its radiance. Here every ray that escapes
//! the scene into a distant `glow` (or into empty space when the scene has no distant
//! source at all) adds `pi/N x throughput` to bin `patches.bin_of(dir)`; escapes towards a
//! distant `light` (if the scene has one) count nothing, as in rcontrib where the sun's
//! modifier is not tracked; no next-event estimation is done.

use super::compile::Renderable;
use super::reweight::{Events, Tracking, scales_with_colour};
use crate::geometry::{Hit, Ray, Vec3};
use crate::material::sampling::{cosine_hemisphere, frame};
use crate::material::{Color, Material, SampleKind, Surface};
use crate::sky::SkyPatches;
use rand::Rng;
use std::f64::consts::PI;

/// Radiance's sensor offsets: shading point `org + 1e-4 dir` (`eval_irrad`).
pub const SENSOR_OFFSET: f64 = 1e-4;

/// Where a sink path starts: origin, first direction, whether it is an `-I` sensor's
/// hemisphere sample, and its initial weight (Radiance's ray weight, for `-lw`).
#[derive(Debug, Clone, Copy)]
struct PathStart {
    org: Vec3,
    dir: Vec3,
    from_sensor: bool,
    w0: f64,
}

/// Path limits (Radiance's `-ab`, `-lw`, `-lr`, `-av`) as the integrator applies them; the
/// driver derives them from `rdc::Sampling`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathLimits {
    /// Maximum number of diffuse bounces (`-ab`).
    pub ab: u32,
    /// Russian-roulette weight threshold (`-lw`); 0 disables roulette.
    pub lw: f64,
    /// Cap on reflections/transmissions per path (`|-lr|`, 10 by default).
    pub max_depth: u32,
    /// Ambient value `-av` returned by diffuse lobes past `-ab` (None = black).
    pub ambient_value: Option<Color>,
    /// Sample the scene's window panes at Lambertian vertices ([`super::portals`]): same
    /// expectation, less noise in side-lit rooms.
    pub portals: bool,
    /// Directions at the first diffuse (Lambertian) hit of a path that did not start at a
    /// sensor, each continuing with `1/split` of the weight, stratified over the
    /// hemisphere: Radiance's ambient divisions at the first ambient bounce, for
    /// `rfluxmtx`'s sender rays (`rdc --flux` with a sender file; 1: no splitting).
    pub split: u32,
}

impl PathLimits {
    /// rcontrib 6.0a defaults: `-ab 1 -lw 2e-3 -lr -10 -av 0 0 0`.
    pub const fn rcontrib() -> Self {
        PathLimits {
            ab: 1,
            lw: 2e-3,
            max_depth: 10,
            ambient_value: None,
            portals: true,
            split: 1,
        }
    }

    /// rtrace 6.0a defaults: `-ab 0 -lw 1e-4 -lr -10 -av 0 0 0`.
    pub const fn rtrace() -> Self {
        PathLimits {
            ab: 0,
            lw: 1e-4,
            max_depth: 10,
            ambient_value: None,
            portals: true,
            split: 1,
        }
    }
}

/// Per-sample statistics of one sensor evaluation, for the caller's standard errors.
///
/// `sum`/`sum_sq` are, per channel, the sum and sum of squares over the `n` hemisphere
/// samples of each sample's value (`pi x` path radiance, or `pi x` the path's escaping
/// coefficient summed over patches). `sqrt((sum_sq/n - (sum/n)^2)/(n-1))` is then the
/// standard error of the sensor total assuming independent samples; the first-bounce
/// stratification makes the true error smaller, so this is conservative.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleStats {
    pub n: usize,
    pub sum: Vec<f64>,
    pub sum_sq: Vec<f64>,
    /// Rays cast (closest-hit and shadow queries).
    pub rays: u64,
}

impl SampleStats {
    fn new(ncomp: usize, n: usize) -> Self {
        SampleStats {
            n,
            sum: vec![0.0; ncomp],
            sum_sq: vec![0.0; ncomp],
            rays: 0,
        }
    }

    fn add(&mut self, v: &[f64]) {
        for (c, &x) in v.iter().enumerate() {
            self.sum[c] += x;
            self.sum_sq[c] += x * x;
        }
    }

    /// Estimated standard error of the mean (the sensor value) in channel `c`.
    pub fn std_error(&self, c: usize) -> f64 {
        if self.n < 2 {
            return f64::INFINITY;
        }
        let n = self.n as f64;
        let m = self.sum[c] / n;
        ((self.sum_sq[c] / n - m * m).max(0.0) / (n - 1.0)).sqrt()
    }
}

/// What the path walker does at escapes and emitters.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// Coefficients: no next-event estimation, escapes binned.
    Coefficients,
    /// Values: next-event estimation and emission.
    Values,
    /// Sun coefficients with inter-reflection: next-event estimation towards every sun of
    /// the sink ([`PathSink::sun_at`]) at every surface vertex, nothing at escapes.
    Suns,
}

impl Mode {
    /// Coefficients or values.
    fn of(coefficients: bool) -> Mode {
        if coefficients {
            Mode::Coefficients
        } else {
            Mode::Values
        }
    }
}

/// Where a path's findings go: escapes into distant glows (coefficient mode) and, in sun
/// coefficient mode, the light of each sun scattered towards the path at a vertex.
/// [`Escapes`] makes an escape closure a sink.
pub trait PathSink {
    /// A coefficient-mode escape along `dir` with the path's throughput.
    fn escape(&mut self, dir: Vec3, beta: Color, events: &Events);
    /// A coefficient-mode escape along `dir` that reaches the distant `source` (`None`:
    /// none contains `dir`); `no_sources`: the scene has no distant source at all. By
    /// default, escapes into glows (or into an empty sky) go to [`PathSink::escape`]:
    /// rdc's sky coefficients; receivers (`rdc::flux`) look at which source it is.
    fn escape_to(
        &mut self,
        source: Option<&super::sources::DistantSource>,
        no_sources: bool,
        dir: Vec3,
        beta: Color,
        events: &Events,
    ) {
        let counts = no_sources
            || matches!(
                source.map(|s| s.kind),
                Some(super::DistantKind::Glow | super::DistantKind::DarkGlow)
            );
        if counts {
            self.escape(dir, beta, events);
        }
    }
    /// A coefficient-mode path that ends on an emitting surface (a `glow` on a polygon,
    /// say): the surface's scene index and the ray's direction, with the path's
    /// throughput. Nothing by default (rcontrib's untracked modifiers); rdc's surface
    /// receivers count it.
    fn emitter(&mut self, _scene_index: u32, _dir: Vec3, _beta: Color, _events: &Events) {}
    /// Number of suns (sun coefficient mode).
    fn nsuns(&self) -> usize {
        0
    }
    /// Unit direction to sun `i` and its solid angle.
    fn sun_at(&self, _i: usize) -> (Vec3, f64) {
        (Vec3::new(0.0, 0.0, 1.0), 0.0)
    }
    /// Sun `i` of unit radiance seen through the path: the radiance it sends back along
    /// the path (throughput x the vertex's direct coefficient x shadow transmission), with
    /// the tracked events of the path, the vertex and the shadow ray.
    fn sun(&mut self, _i: usize, _value: Color, _events: &Events) {}
}

/// A sink for escapes only: `escape(dir, throughput, events)`.
pub struct Escapes<'a>(pub &'a mut dyn FnMut(Vec3, Color, &Events));

impl PathSink for Escapes<'_> {
    fn escape(&mut self, dir: Vec3, beta: Color, events: &Events) {
        (self.0)(dir, beta, events)
    }
}

/// A surface vertex of a path.
struct Vertex<'a> {
    hit: &'a Hit,
    material: &'a Material,
    /// Index of `material` in the renderable (for tracking).
    index: u32,
}

/// Where one path is.
#[derive(Clone, Copy)]
struct PathState {
    beta: Color,
    sees_sources: bool,
    diffuse: u32,
    depth: u32,
    /// Tracked materials met (re-weighting records, [`super::reweight`]).
    events: Events,
    /// Set while the path goes straight on from a vertex whose light through the windows
    /// was also sampled by the portals: the two strategies' densities for its direction.
    mis: Option<Mis>,
}

impl PathState {
    /// A path's state at its start: one started by a sensor's (or a sender's) first
    /// sample counts as past its first diffuse bounce and does not see sources directly.
    fn new(nc: usize, from_sensor: bool) -> PathState {
        PathState {
            beta: Color::splat(nc, 1.0),
            sees_sources: !from_sensor,
            diffuse: u32::from(from_sensor),
            depth: u32::from(from_sensor),
            events: Events::default(),
            mis: None,
        }
    }
}

/// Densities of the last vertex's two strategies for the path's direction (solid angle):
/// the material's cosine sample and the portal sample. An escape reached straight through
/// glass from that vertex counts with the balance heuristic `pb / (pb + pn)`.
#[derive(Clone, Copy)]
struct Mis {
    pb: f64,
    pn: f64,
}

impl Mis {
    fn weight(self) -> f64 {
        self.pb / (self.pb + self.pn)
    }
}

/// The material of a vertex where the portals are sampled: Lambertian (`plastic`/`metal`
/// without specularity), its reflectance.
fn lambertian(m: &Material) -> Option<Color> {
    match m {
        Material::Ward(w) if w.spec == 0.0 && w.trans == 0.0 && w.color.mean() > 0.0 => {
            Some(w.color)
        }
        _ => None,
    }
}

/// Jittered-stratified cosine samples: index `k` of `n`.
fn strat_uv(k: usize, n: usize, m: usize, rng: &mut impl Rng) -> (f64, f64) {
    let (a, b): (f64, f64) = (rng.random(), rng.random());
    if k < m * m {
        let (i, j) = (k / m, k % m);
        ((i as f64 + a) / m as f64, (j as f64 + b) / m as f64)
    } else {
        let _ = n;
        (a, b)
    }
}

/// [`Material::sample`] with a shortcut for the commonest material of daylight scenes, a
/// Lambertian `plastic`/`metal` (specularity 0): there `normal.c`'s split gives
/// `rspec = 0`, `rdiff = 1`, one lobe chosen with probability 1, so the sample is a
/// cosine-weighted direction about the normal turned toward the viewer with weight `rho`.
/// The numbers are bit for bit those of [`crate::material::ward::Ward::sample`] (same
/// uniforms, same direction formula, `rho x 1 / 1`), without building its lobe table
/// (a quarter of the run time in the furnished office).
#[inline]
fn sample_material(
    m: &Material,
    wo: Vec3,
    s: &Surface,
    u1: f64,
    u2: f64,
    u3: f64,
) -> Option<crate::material::Sample> {
    if let Material::Ward(w) = m {
        if w.spec == 0.0 && w.trans == 0.0 {
            if w.color.mean() <= 0.0 {
                return None;
            }
            let n = if wo.dot(Vec3::from(s.normal)) < 0.0 {
                -Vec3::from(s.normal)
            } else {
                Vec3::from(s.normal)
            };
            return Some(crate::material::Sample {
                wi: cosine_hemisphere(n.to_array(), u2, u3),
                weight: w.color,
                kind: SampleKind::DiffuseReflect,
            });
        }
    }
    m.sample(wo.to_array(), s, u1, u2, u3)
}

/// The two rays of a `glass` pane (`glass.c`): transmitted straight on with weight `T`,
/// reflected in the mirror direction with weight `R` (see [`crate::material::glass`]);
/// `None` for a black one.
fn glass_branches(
    g: &crate::material::glass::Glass,
    wo: Vec3,
    s: &Surface,
) -> (
    Option<crate::material::Sample>,
    Option<crate::material::Sample>,
) {
    let n0 = Vec3::from(s.normal);
    let d = wo.dot(n0);
    let (n, pdot) = if d < 0.0 { (-n0, -d) } else { (n0, d) };
    let (t, r) = g.coefficients(pdot);
    let t = (t.max() > 0.0).then(|| crate::material::Sample {
        wi: (-wo).to_array(),
        weight: t,
        kind: SampleKind::PureTransmit,
    });
    let r = (r.max() > 0.0).then(|| crate::material::Sample {
        wi: (n * (2.0 * pdot) - wo).normalize().to_array(),
        weight: r,
        kind: SampleKind::PureReflect,
    });
    (t, r)
}

impl Renderable {
    /// Closest hit (counting the ray).
    #[inline]
    fn cast(&self, ray: &Ray, rays: &mut u64) -> Option<Hit> {
        *rays += 1;
        self.bvh.intersect(ray, 0.0, f64::INFINITY)
    }

    /// Transmission of a shadow ray from `org` towards the distant direction `dir`:
    /// product of what each crossed surface passes; `None` when blocked.
    fn shadow(&self, org: Vec3, dir: Vec3, rays: &mut u64) -> Option<Color> {
        self.shadow_tracked(org, dir, rays, None).map(|(t, _)| t)
    }

    /// [`Renderable::shadow`] that also records the tracked panes crossed (each crossing's
    /// coefficient, glass `T` or trans `rho tspec`, scales with the pane's colour).
    fn shadow_tracked(
        &self,
        org: Vec3,
        dir: Vec3,
        rays: &mut u64,
        track: Option<&Tracking>,
    ) -> Option<(Color, Events)> {
        let mut events = Events::default();
        let mut t = Color::splat(self.ncomp, 1.0);
        let mut ray = Ray { org, dir };
        // A bounded number of crossings (double panes, furniture glass...).
        for _ in 0..32 {
            let Some(h) = self.cast(&ray, rays) else {
                return Some((t, events));
            };
            let info = self.surfaces[h.object as usize];
            let m_at = self.material_at(info.material, dir, &h);
            let m = &*m_at;
            let s = Surface {
                normal: h.normal.to_array(),
                flat: info.flat,
            };
            t = t * m.shadow_transmission((-dir).to_array(), &s)?;
            if let Some(tr) = track {
                if scales_with_colour(m, crate::material::SampleKind::PureTransmit) {
                    events.push(tr.of_at(info.material, dir.dot(h.normal)));
                }
            }
            if t.max() <= 0.0 {
                return None;
            }
            ray = h.spawn(dir);
        }
        None
    }

    /// A ray from `org` along `dir` that passes only `glass` panes and escapes: the panes'
    /// transmission (each `glass.c`'s transmitted coefficient, as the path's own crossing
    /// weighs it), how many it crossed and, with `track`, the tracked crossings. `None` when
    /// anything else is in the way. This is exactly the set of paths a material's sample
    /// reaches the sky by straight through glass, which the portal strategy also samples
    /// ([`super::portals`]).
    fn through_glass(
        &self,
        org: Vec3,
        dir: Vec3,
        rays: &mut u64,
        track: Option<&Tracking>,
    ) -> Option<(Color, u32, Events)> {
        let mut events = Events::default();
        let mut t = Color::splat(self.ncomp, 1.0);
        let mut ray = Ray { org, dir };
        for k in 0..32u32 {
            let Some(h) = self.cast(&ray, rays) else {
                return Some((t, k, events));
            };
            let info = self.surfaces[h.object as usize];
            let m_at = self.material_at(info.material, dir, &h);
            let Material::Glass(g) = &*m_at else {
                return None;
            };
            let (tg, _) = g.coefficients(dir.dot(h.normal).abs());
            if let Some(tr) = track {
                if scales_with_colour(&m_at, SampleKind::PureTransmit) {
                    events.push(tr.of_at(info.material, dir.dot(h.normal)));
                }
            }
            t = t * tg;
            if t.max() <= 0.0 {
                return None;
            }
            ray = h.spawn(dir);
        }
        None
    }

    /// Decide which candidate panes are portals and on which side the room is (see
    /// [`super::portals`]: probes from the pane's centroid on both sides, traced through
    /// glass; the side whose probes escape is outside).
    pub(super) fn find_portals(
        &self,
        panes: Vec<super::portals::Portal>,
    ) -> super::portals::Portals {
        use super::portals::{MAX_PORTALS, MIN_OUTSIDE, PROBE_RAYS, probe_rays};
        if panes.is_empty() || panes.len() > MAX_PORTALS {
            return Default::default();
        }
        let mut out = Vec::new();
        for mut p in panes {
            let (n, c) = p.frame();
            let eps = 1e-6 * (1.0 + c.max_abs());
            // Per side: the share of probes that escape, and of the falling probes (those
            // heading below the horizon) how many there were and how many escaped.
            let probe = |side: f64| {
                let mut rays = 0;
                let org = c + n * (side * eps);
                let (mut esc, mut fall, mut fall_esc) = (0usize, 0usize, 0usize);
                for r in probe_rays(org, n * side) {
                    let through = self.through_glass(r.org, r.dir, &mut rays, None).is_some();
                    esc += usize::from(through);
                    if r.dir.z < 0.0 {
                        fall += 1;
                        fall_esc += usize::from(through);
                    }
                }
                (esc as f64 / PROBE_RAYS as f64, fall, fall_esc)
            };
            let (front, back) = (probe(1.0), probe(-1.0));
            let (outside, inside, sign) = if front.0 >= back.0 {
                (front, back, -1.0)
            } else {
                (back, front, 1.0)
            };
            if outside.0 >= MIN_OUTSIDE && inside.0 <= 0.5 * outside.0 {
                p.set_inside(sign);
                // Modelled ground outside: falling directions almost never reach the sky.
                let (fall, fall_esc) = (outside.1, outside.2);
                p.set_rising_only(fall >= PROBE_RAYS / 8 && 10 * fall_esc < fall);
                out.push(p);
            }
        }
        super::portals::Portals::new(out)
    }

    /// Portal next-event estimation at a Lambertian vertex (reflectance `rho`, normal `n`
    /// turned toward the viewer): one direction through a window pane, counted with the
    /// balance heuristic against the vertex's continuation, the cosine sample mixed with
    /// share `alpha` of falling portal samples ([`super::portals`]). Its
    /// value goes where an escape of the path would: the sink (coefficients) or `out`
    /// (values). `depth` is the vertex's path depth: the path's own crossings of the panes
    /// would be cut at `-lr` (`max_depth`), so are these.
    #[allow(clippy::too_many_arguments)]
    fn portal_nee(
        &self,
        at: &super::portals::At,
        x: &Hit,
        n: Vec3,
        rho: Color,
        alpha: f64,
        vertex_event: Option<u32>,
        st: &PathState,
        depth: u32,
        params: &PathLimits,
        mode: Mode,
        (u, a, b): (f64, f64, f64),
        rays: &mut u64,
        track: Option<&Tracking>,
        sink: &mut dyn PathSink,
        out: &mut Color,
    ) {
        let Some((dir, pn)) = at.sample(u, a, b) else {
            return;
        };
        let cos = n.dot(dir);
        if cos <= 0.0 {
            return;
        }
        let org = x.spawn_origin(dir);
        let Some((t, k, shadow_ev)) = self.through_glass(org, dir, rays, track) else {
            return;
        };
        if depth + k >= params.max_depth {
            return;
        }
        // The continuation's density for `dir`: the mixture of the cosine sample and, with
        // share `alpha`, the falling portal sample.
        let m = (1.0 - alpha) * cos / PI
            + if alpha > 0.0 {
                alpha * at.fall_pdf(dir)
            } else {
                0.0
            };
        let beta = st.beta * rho * t;
        // f cos / pn x the balance weight pn / (m + pn), f = rho / pi.
        let beta = beta.scale(cos / (PI * (m + pn)));
        match mode {
            Mode::Coefficients => {
                let mut ev = st.events;
                if let (Some(tr), Some(k)) = (track, vertex_event) {
                    ev.push(tr.of_at(k, dir.dot(x.normal)));
                }
                ev.extend(&shadow_ev);
                sink.escape_to(
                    self.sources.hit(dir),
                    self.sources.is_empty(),
                    dir,
                    beta,
                    &ev,
                );
            }
            Mode::Values => {
                if let Some(l) = self.sources.escape(dir, false) {
                    *out += beta * l;
                }
            }
            Mode::Suns => {}
        }
    }

    /// Direct light from distant `light` sources at a surface hit (`wo` towards the viewer).
    fn direct(&self, h: &Hit, m: &Material, s: &Surface, wo: Vec3, rays: &mut u64) -> Color {
        let mut out = Color::black(self.ncomp);
        for src in self.sources.lights() {
            let Some(coef) = m.eval_direct(wo.to_array(), src.dir.to_array(), s, src.omega) else {
                return out;
            };
            if coef.max() <= 0.0 {
                continue;
            }
            if let Some(t) = self.shadow(h.spawn_origin(src.dir), src.dir, rays) {
                out += coef * t * src.color;
            }
        }
        out
    }

    /// Sun coefficient mode at a vertex: each sun of the sink as a unit-radiance disc aimed
    /// at its centre, as [`Renderable::direct`] treats a `light` source (Radiance `-dj 0`).
    /// The vertex counts as a scattering at its material for re-weighting when the
    /// material's diffuse lobe scales with its colour (a plastic's uncoloured specular
    /// part is then re-weighted with it: exact for the matte surfaces of rooms).
    #[allow(clippy::too_many_arguments)]
    fn sun_nee(
        &self,
        h: &Hit,
        m: &Material,
        index: u32,
        s: &Surface,
        wo: Vec3,
        st: &PathState,
        rays: &mut u64,
        track: Option<&Tracking>,
        sink: &mut dyn PathSink,
    ) {
        for i in 0..sink.nsuns() {
            let (dir, omega) = sink.sun_at(i);
            let Some(coef) = m.eval_direct(wo.to_array(), dir.to_array(), s, omega) else {
                return;
            };
            if coef.max() <= 0.0 {
                continue;
            }
            if let Some((t, shadow_ev)) = self.shadow_tracked(h.spawn_origin(dir), dir, rays, track)
            {
                let mut ev = st.events;
                if let Some(tr) = track {
                    if scales_with_colour(m, SampleKind::DiffuseReflect) {
                        ev.push(tr.of(index));
                    }
                    ev.extend(&shadow_ev);
                }
                sink.sun(i, st.beta * coef * t, &ev);
            }
        }
    }

    /// Walk one path from `ray`, adding radiance (values mode) to the return value and
    /// calling `escape(dir, throughput)` for escapes in coefficients mode.
    #[allow(clippy::too_many_arguments)]
    fn walk(
        &self,
        mut ray: Ray,
        mut st: PathState,
        w0: f64,
        params: &PathLimits,
        mode: Mode,
        rng: &mut impl Rng,
        rays: &mut u64,
        track: Option<&Tracking>,
        sink: &mut dyn PathSink,
    ) -> Color {
        let mut out = Color::black(self.ncomp);
        loop {
            let Some(h) = self.cast(&ray, rays) else {
                match mode {
                    // Suns were counted by next-event estimation at the vertices.
                    Mode::Suns => {}
                    Mode::Values => {
                        if let Some(l) = self.sources.escape(ray.dir, st.sees_sources) {
                            out += st.beta.scale(st.mis.map_or(1.0, Mis::weight)) * l;
                        }
                    }
                    Mode::Coefficients => {
                        sink.escape_to(
                            self.sources.hit(ray.dir),
                            self.sources.is_empty(),
                            ray.dir,
                            st.beta.scale(st.mis.map_or(1.0, Mis::weight)),
                            &st.events,
                        );
                    }
                }
                return out;
            };
            let info = self.surfaces[h.object as usize];
            let m_at = self.material_at(info.material, ray.dir, &h);
            let m = &*m_at;
            let wo = -ray.dir;
            let s = Surface {
                normal: h.normal.to_array(),
                flat: info.flat,
            };
            // A BSDF with thickness is a proxy: view rays and rays from its hidden side pass
            // (m_bsdf.c `raytrans`), staying the same ray.
            if let Material::Bsdf(b) = m {
                if b.passes(wo.to_array(), &s, st.depth == 0) {
                    // Not a path the portals sample (they pass glass only): full weight.
                    st.mis = None;
                    ray = h.spawn(ray.dir);
                    continue;
                }
            }
            if let Material::Emitter(e) = m {
                if mode == Mode::Coefficients {
                    sink.emitter(info.scene_index, ray.dir, st.beta, &st.events);
                }
                if mode == Mode::Values && (st.sees_sources || e.counts_for_indirect(h.t)) {
                    out += st.beta * e.emission(wo.to_array(), &s);
                }
                return out;
            }
            if mode == Mode::Values && self.sources.lights().next().is_some() {
                out += st.beta * self.direct(&h, m, &s, wo, rays);
            }
            if mode == Mode::Suns {
                self.sun_nee(&h, m, info.material, &s, wo, &st, rays, track, sink);
            }
            if st.depth >= params.max_depth {
                return out;
            }
            let v = Vertex {
                hit: &h,
                material: m,
                index: info.material,
            };
            if let Material::Glass(g) = m {
                // Both of the pane's rays, as Radiance's glass.c traces them: the reflected
                // one as a branch, the transmitted one continuing this loop. Choosing one
                // at random (probability ~ T : R) would add binomial noise to every
                // coefficient seen through a window.
                let (t, r) = glass_branches(g, wo, &s);
                if let Some(r) = r {
                    if let Some((ray_r, mut st_r)) =
                        self.advance(&v, st, r, w0, params, mode, rng, track, &mut out)
                    {
                        // The reflected ray turns: no longer a straight pass.
                        st_r.mis = None;
                        out += self.walk(ray_r, st_r, w0, params, mode, rng, rays, track, sink);
                    }
                }
                let Some(t) = t else {
                    return out;
                };
                match self.advance(&v, st, t, w0, params, mode, rng, track, &mut out) {
                    Some((r, next)) => {
                        ray = r;
                        st = next;
                    }
                    None => return out,
                }
                continue;
            }
            // The path scatters here: whatever it finds next is its own sample's alone.
            st.mis = None;
            // A sender ray's first diffuse hit: `split` stratified directions (rfluxmtx's
            // ambient divisions), each a path of its own with 1/split of the weight.
            if params.split > 1 && st.diffuse == 0 && st.diffuse < params.ab {
                if let Some(rho) = lambertian(m) {
                    let k = params.split as usize;
                    let grid = (k as f64).sqrt().floor() as usize;
                    let n = if wo.dot(h.normal) < 0.0 {
                        -h.normal
                    } else {
                        h.normal
                    };
                    let weight = rho.scale(1.0 / k as f64);
                    for j in 0..k {
                        let (u, w) = strat_uv(j, k, grid, rng);
                        let smp = crate::material::Sample {
                            wi: cosine_hemisphere(n.to_array(), u, w),
                            weight,
                            kind: SampleKind::DiffuseReflect,
                        };
                        if let Some((r, next)) =
                            self.advance(&v, st, smp, w0, params, mode, rng, track, &mut out)
                        {
                            out += self.walk(r, next, w0, params, mode, rng, rays, track, sink);
                        }
                    }
                    return out;
                }
            }
            // Portals at a Lambertian vertex whose diffuse sample may still go on (`-ab`).
            let nee = match lambertian(m) {
                Some(rho)
                    if params.portals
                        && mode != Mode::Suns
                        && st.diffuse < params.ab
                        && !self.portals.is_empty() =>
                {
                    let n = if wo.dot(h.normal) < 0.0 {
                        -h.normal
                    } else {
                        h.normal
                    };
                    self.portals.at(h.point, n).map(|at| (at, n, rho))
                }
                _ => None,
            };
            let smp = match &nee {
                Some((at, n, rho)) => {
                    let event = (track.is_some()
                        && scales_with_colour(m, SampleKind::DiffuseReflect))
                    .then_some(info.material);
                    let alpha = at.fall_share();
                    let u = (rng.random(), rng.random(), rng.random());
                    self.portal_nee(
                        at, &h, *n, *rho, alpha, event, &st, st.depth, params, mode, u, rays,
                        track, sink, &mut out,
                    );
                    // The continuation: with share `alpha` through the panes below the
                    // vertex, else cosine-distributed; weighed by the mixture's density.
                    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
                    let wi = if u1 < alpha {
                        match at.sample_fall(u1 / alpha, u2, u3) {
                            Some(d) => d,
                            None => return out,
                        }
                    } else {
                        Vec3::from(cosine_hemisphere(n.to_array(), u2, u3))
                    };
                    let cos = n.dot(wi);
                    if cos <= 0.0 {
                        return out;
                    }
                    let mix = (1.0 - alpha) * cos / PI
                        + if alpha > 0.0 {
                            alpha * at.fall_pdf(wi)
                        } else {
                            0.0
                        };
                    Some((
                        crate::material::Sample {
                            wi: wi.to_array(),
                            weight: rho.scale(cos / (PI * mix)),
                            kind: SampleKind::DiffuseReflect,
                        },
                        mix,
                        at.pdf(wi),
                    ))
                }
                None => {
                    let (u1, u2, u3) = (rng.random(), rng.random(), rng.random());
                    sample_material(m, wo, &s, u1, u2, u3).map(|smp| (smp, 0.0, 0.0))
                }
            };
            let Some((smp, mix, pn)) = smp else {
                return out;
            };
            match self.advance(&v, st, smp, w0, params, mode, rng, track, &mut out) {
                Some((r, mut next)) => {
                    next.mis = (pn > 0.0).then_some(Mis { pb: mix, pn });
                    ray = r;
                    st = next;
                }
                None => return out,
            }
        }
    }

    /// Continue from vertex `v` along the sampled `smp` under the path rules (`-ab`, `-av`,
    /// source visibility, tracked events, `-lw` roulette). `None` ends the path (an `-av`
    /// contribution goes to `out` first).
    #[allow(clippy::too_many_arguments)]
    fn advance(
        &self,
        v: &Vertex,
        mut st: PathState,
        smp: crate::material::Sample,
        w0: f64,
        params: &PathLimits,
        mode: Mode,
        rng: &mut impl Rng,
        track: Option<&Tracking>,
        out: &mut Color,
    ) -> Option<(Ray, PathState)> {
        let diffuse = matches!(
            smp.kind,
            SampleKind::DiffuseReflect | SampleKind::DiffuseTransmit
        );
        if diffuse {
            if st.diffuse >= params.ab {
                if let (Mode::Values, Some(av)) = (mode, params.ambient_value) {
                    *out += st.beta * smp.weight * av;
                }
                return None;
            }
            st.diffuse += 1;
        }
        if !smp.kind.sees_sources() {
            st.sees_sources = false;
        }
        if let Some(tr) = track {
            if scales_with_colour(v.material, smp.kind) {
                // The incidence cosine bins glass crossings (a straight pass: `wi` is the
                // incoming direction continued).
                let cos = Vec3::from(smp.wi).dot(v.hit.normal);
                st.events.push(tr.of_at(v.index, cos));
            }
        }
        st.beta = st.beta * smp.weight;
        let w = w0 * st.beta.mean();
        if w.is_nan() || w <= 0.0 {
            return None;
        }
        if w < params.lw {
            let p = w / params.lw;
            if rng.random::<f64>() >= p {
                return None;
            }
            st.beta = st.beta.scale(1.0 / p);
        }
        st.depth += 1;
        let mut next = v.hit.spawn(Vec3::from(smp.wi));
        // A BSDF's thickness moves transmitted samples behind it (m_bsdf.c: `-thick` along
        // the surface normal), past the geometry it stands for.
        if let Material::Bsdf(b) = v.material {
            if smp.kind.is_transmission() {
                let s = Surface::flat(v.hit.normal.to_array());
                if let Some(off) = b.transmit_offset(&s) {
                    next.org += Vec3::from(off);
                }
            }
        }
        Some((next, st))
    }

    /// Daylight coefficients of one sensor, rcontrib `-I+ -V-` style (see the module
    /// documentation): `out[bin * ncomp + c] += pi/N x throughput` for every path of the
    /// `nsamples` (`-ad`) hemisphere samples that escapes into patch `bin`
    /// (`patches.bin_of(dir)`, ground = 0). `out` must hold `patches.len() * ncomp` values;
    /// it is **added to** (zero it first), so callers may accumulate several calls.
    /// `org`/`normal`: the sensor point and its (unit) normal.
    #[allow(clippy::too_many_arguments)]
    pub fn dc_sensor(
        &self,
        org: Vec3,
        normal: Vec3,
        nsamples: usize,
        params: &PathLimits,
        patches: &SkyPatches,
        rng: &mut impl Rng,
        out: &mut [f64],
    ) -> SampleStats {
        let nc = self.ncomp;
        let n = nsamples.max(1);
        let mut stats = SampleStats::new(nc, n);
        let normal = normal.normalize();
        if out.len() < patches.len() * nc || params.ab == 0 || normal.length() == 0.0 {
            // -ab 0: the sensor sees no glow (radiance-notes 12.8).
            return stats;
        }
        let p = org + normal * SENSOR_OFFSET;
        let m = (n as f64).sqrt().floor() as usize;
        let scale = PI / n as f64;
        let mut sample_total = vec![0.0; nc];
        for k in 0..n {
            let (u, v) = strat_uv(k, n, m, rng);
            let dir = Vec3::from(cosine_hemisphere(normal.to_array(), u, v));
            let ray = Ray { org: p, dir };
            let st = PathState::new(nc, true);
            sample_total.iter_mut().for_each(|x| *x = 0.0);
            let mut rays = 0;
            self.walk(
                ray,
                st,
                1.0 / n as f64,
                params,
                Mode::Coefficients,
                rng,
                &mut rays,
                None,
                &mut Escapes(&mut |d, beta, _| {
                    let bin = patches.bin_of(d.to_array());
                    let row = &mut out[bin * nc..(bin + 1) * nc];
                    for (c, (o, &b)) in row.iter_mut().zip(beta.as_slice()).enumerate() {
                        *o += scale * b as f64;
                        sample_total[c] += PI * b as f64;
                    }
                }),
            );
            stats.rays += rays;
            stats.add(&sample_total);
        }
        stats
    }

    /// Irradiance at a sensor, rtrace `-I -aa 0 -as 0` style (see the module documentation):
    /// direct `L omega cos` from each distant `light` (shadow-tested, through glass) plus
    /// `(pi/N) sum` over `nsamples` cosine-distributed paths (`-ad`, none when `ab == 0`).
    pub fn irradiance(
        &self,
        org: Vec3,
        normal: Vec3,
        nsamples: usize,
        params: &PathLimits,
        rng: &mut impl Rng,
    ) -> (Color, SampleStats) {
        let nc = self.ncomp;
        let n = nsamples.max(1);
        let mut stats = SampleStats::new(nc, n);
        let normal = normal.normalize();
        let mut e = Color::black(nc);
        if normal.length() == 0.0 {
            return (e, stats);
        }
        let p = org + normal * SENSOR_OFFSET;
        let mut rays = 0;
        for src in self.sources.lights() {
            let c = normal.dot(src.dir);
            if c <= 0.0 {
                continue;
            }
            if let Some(t) = self.shadow(p, src.dir, &mut rays) {
                e += src.color.scale(src.omega * c) * t;
            }
        }
        if params.ab == 0 {
            if let Some(av) = params.ambient_value {
                e += av.scale(PI);
            }
            stats.rays = rays;
            return (e, stats);
        }
        let m = (n as f64).sqrt().floor() as usize;
        let mut ind = Color::black(nc);
        let mut v = vec![0.0; nc];
        for k in 0..n {
            let (u, w) = strat_uv(k, n, m, rng);
            let dir = Vec3::from(cosine_hemisphere(normal.to_array(), u, w));
            let st = PathState::new(nc, true);
            let l = self.walk(
                Ray { org: p, dir },
                st,
                1.0 / n as f64,
                params,
                Mode::Values,
                rng,
                &mut rays,
                None,
                &mut Escapes(&mut |_, _, _| {}),
            );
            for (x, &y) in v.iter_mut().zip(l.as_slice()) {
                *x = PI * y as f64;
            }
            stats.add(&v);
            ind += l;
        }
        stats.rays = rays;
        (e + ind.scale(PI / n as f64), stats)
    }

    /// Radiance along a view ray (one path sample; average many per pixel). The primary
    /// ray sees distant `light` sources, glow skies and glow surfaces directly; further
    /// vertices follow the same rules as [`Renderable::irradiance`]. Returns the value and
    /// the number of rays cast.
    pub fn radiance(
        &self,
        org: Vec3,
        dir: Vec3,
        params: &PathLimits,
        rng: &mut impl Rng,
    ) -> (Color, u64) {
        let dir = dir.normalize();
        let nc = self.ncomp;
        if dir.length() == 0.0 {
            return (Color::black(nc), 0);
        }
        let st = PathState::new(nc, false);
        let mut rays = 0;
        let l = self.walk(
            Ray { org, dir },
            st,
            1.0,
            params,
            Mode::Values,
            rng,
            &mut rays,
            None,
            &mut Escapes(&mut |_, _, _| {}),
        );
        (l, rays)
    }
}

impl Renderable {
    /// One path sample for drivers that loop over samples themselves (`rdc`'s estimator):
    /// a path from `org` along unit `dir`, either leaving a sensor (`from_sensor`: the first
    /// sample counts as diffuse bounce 1 and does not see sources, as an ambient sample of
    /// rcontrib/rtrace) or a primary view ray. `w0` is the path's starting weight for `-lw`
    /// roulette (Radiance: 1/`-ad` for ambient samples, 1 for view rays). In coefficient mode
    /// `escape(dir, throughput)` is called for every escape into a distant glow; in value
    /// mode the radiance found is returned. Returns the value and the rays cast.
    /// With `track`, `escape` also receives the tracked materials the path met
    /// ([`super::reweight`]); without, the events are empty.
    #[allow(clippy::too_many_arguments)]
    pub fn path_sample(
        &self,
        org: Vec3,
        dir: Vec3,
        from_sensor: bool,
        coefficients: bool,
        w0: f64,
        params: &PathLimits,
        rng: &mut impl Rng,
        track: Option<&Tracking>,
        escape: &mut dyn FnMut(Vec3, Color, &Events),
    ) -> (Color, u64) {
        let nc = self.ncomp;
        let st = PathState::new(nc, from_sensor);
        let mode = Mode::of(coefficients);
        let mut rays = 0;
        let l = self.walk(
            Ray { org, dir },
            st,
            w0,
            params,
            mode,
            rng,
            &mut rays,
            track,
            &mut Escapes(escape),
        );
        (l, rays)
    }

    /// One sample of an `-I` sensor at `p` (already offset from its surface) with unit
    /// normal `normal`: the cosine-distributed path along `dir` (diffuse bounce 1, as in
    /// [`Renderable::path_sample`] with `from_sensor`) and, when the scene has portals and
    /// `params.portals`, a portal sample through the window panes from `nee = (u, a, b)`,
    /// the two combined by the balance heuristic ([`super::portals`]): the sensor is a
    /// white Lambertian surface, the first vertex of both strategies. Escapes (coefficient
    /// mode) go to `escape` with the throughput the caller scales by pi; in value mode the
    /// radiance found (sky light through the windows included) is returned, to be scaled
    /// by pi likewise. Returns the value and the rays cast.
    #[allow(clippy::too_many_arguments)]
    pub fn sensor_sample(
        &self,
        p: Vec3,
        normal: Vec3,
        dir: Vec3,
        nee: (f64, f64, f64),
        coefficients: bool,
        w0: f64,
        params: &PathLimits,
        rng: &mut impl Rng,
        track: Option<&Tracking>,
        escape: &mut dyn FnMut(Vec3, Color, &Events),
    ) -> (Color, u64) {
        let nc = self.ncomp;
        let mut st = PathState::new(nc, true);
        let mode = Mode::of(coefficients);
        let mut rays = 0;
        let mut out = Color::black(nc);
        let mut sink = Escapes(escape);
        if params.portals && params.ab > 0 && !self.portals.is_empty() {
            if let Some(at) = self.portals.at(p, normal) {
                let x = Hit {
                    t: 0.0,
                    point: p,
                    normal,
                    object: u32::MAX,
                    front: true,
                };
                let start = PathState {
                    diffuse: 0,
                    depth: 0,
                    ..st
                };
                self.portal_nee(
                    &at,
                    &x,
                    normal,
                    Color::splat(nc, 1.0),
                    0.0,
                    None,
                    &start,
                    0,
                    params,
                    mode,
                    nee,
                    &mut rays,
                    track,
                    &mut sink,
                    &mut out,
                );
                let pn = at.pdf(dir);
                st.mis = (pn > 0.0).then_some(Mis {
                    pb: normal.dot(dir).max(0.0) / PI,
                    pn,
                });
            }
        }
        let l = self.walk(
            Ray { org: p, dir },
            st,
            w0,
            params,
            mode,
            rng,
            &mut rays,
            track,
            &mut sink,
        );
        (out + l, rays)
    }

    /// One coefficient path from `org` along `dir` whose escapes and emitter hits go to
    /// `sink` ([`PathSink::escape_to`], [`PathSink::emitter`]): rdc's sender/receiver
    /// mode. `from_sensor`: the first direction was an `-I` sensor's hemisphere sample
    /// (diffuse bounce 1). Returns the rays cast.
    #[allow(clippy::too_many_arguments)]
    pub fn sink_path_sample(
        &self,
        org: Vec3,
        dir: Vec3,
        from_sensor: bool,
        w0: f64,
        params: &PathLimits,
        rng: &mut impl Rng,
        sink: &mut dyn PathSink,
    ) -> u64 {
        let start = PathStart {
            org,
            dir,
            from_sensor,
            w0,
        };
        self.sink_walk(start, params, Mode::Coefficients, rng, None, sink)
    }

    /// One sun-coefficient path sample from a sensor (`-I`, the first sample counting as
    /// diffuse bounce 1) or along a view ray: at every surface vertex, next-event
    /// estimation towards each of `sink`'s suns ([`PathSink::sun`]); escapes count nothing.
    /// The five-phase method's sun coefficients with inter-reflection (rcontrib `-ab N`
    /// with the suns as `light` sources), for every sun from the same paths. The sensor's
    /// own direct view of the suns is the caller's. Returns the rays cast.
    #[allow(clippy::too_many_arguments)]
    pub fn sun_path_sample(
        &self,
        org: Vec3,
        dir: Vec3,
        from_sensor: bool,
        w0: f64,
        params: &PathLimits,
        rng: &mut impl Rng,
        track: Option<&Tracking>,
        sink: &mut dyn PathSink,
    ) -> u64 {
        let start = PathStart {
            org,
            dir,
            from_sensor,
            w0,
        };
        self.sink_walk(start, params, Mode::Suns, rng, track, sink)
    }

    /// One path into `sink` from `start` (an `-I` sensor's first sample counting as
    /// diffuse bounce 1, so it no longer sees sources directly). Returns the rays cast.
    fn sink_walk(
        &self,
        start: PathStart,
        params: &PathLimits,
        mode: Mode,
        rng: &mut impl Rng,
        track: Option<&Tracking>,
        sink: &mut dyn PathSink,
    ) -> u64 {
        let st = PathState::new(self.ncomp, start.from_sensor);
        let mut rays = 0;
        self.walk(
            Ray {
                org: start.org,
                dir: start.dir,
            },
            st,
            start.w0,
            params,
            mode,
            rng,
            &mut rays,
            track,
            sink,
        );
        rays
    }

    /// Transmission from `org` towards the distant direction `dir` through everything in
    /// the way (glass passes, opaque surfaces block: `None`), for sun coefficients.
    pub fn transmission_towards(&self, org: Vec3, dir: Vec3) -> Option<Color> {
        let mut rays = 0;
        self.shadow(org, dir.normalize(), &mut rays)
    }

    /// [`Renderable::transmission_towards`] with the tracked panes crossed.
    pub fn transmission_towards_tracked(
        &self,
        org: Vec3,
        dir: Vec3,
        track: Option<&Tracking>,
    ) -> Option<(Color, Events)> {
        let mut rays = 0;
        self.shadow_tracked(org, dir.normalize(), &mut rays, track)
    }

    /// The direct part of [`Renderable::irradiance`]: `L omega cos` from every distant
    /// `light` source, shadow-tested, at a sensor point already offset from its surface.
    pub fn direct_irradiance(&self, p: Vec3, normal: Vec3) -> Color {
        let mut e = Color::black(self.ncomp);
        let mut rays = 0;
        for src in self.sources.lights() {
            let c = normal.dot(src.dir);
            if c > 0.0 {
                if let Some(t) = self.shadow(p, src.dir, &mut rays) {
                    e += src.color.scale(src.omega * c) * t;
                }
            }
        }
        e
    }
}

/// An orthonormal frame around a unit normal (re-exported helper for drivers that jitter
/// sensor directions).
pub fn sensor_frame(normal: Vec3) -> (Vec3, Vec3) {
    let (u, v) = frame(normal.normalize().to_array());
    (Vec3::from(u), Vec3::from(v))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::ward::{Ward, WardKind};
    use crate::material::{Color, ShadingOptions};

    #[test]
    fn lambertian_shortcut_is_ward_sample_bit_for_bit() {
        let mut rng = rand_pcg::Pcg64::new(7, 9);
        for kind in [WardKind::Plastic, WardKind::Metal] {
            let w = Ward::new(
                kind,
                Color::from_slice(&[0.55, 0.42, 0.3]),
                0.0,
                0.1,
                0.0,
                0.0,
                ShadingOptions::rcontrib(),
            );
            let m = Material::Ward(w.clone());
            for _ in 0..1000 {
                let r = |rng: &mut rand_pcg::Pcg64| -> f64 { rng.random::<f64>() * 2.0 - 1.0 };
                let n = Vec3::new(r(&mut rng), r(&mut rng), r(&mut rng)).normalize();
                let wo = Vec3::new(r(&mut rng), r(&mut rng), r(&mut rng)).normalize();
                let s = Surface {
                    normal: n.to_array(),
                    flat: true,
                };
                let (u1, u2, u3) = (rng.random(), rng.random(), rng.random());
                assert_eq!(
                    sample_material(&m, wo, &s, u1, u2, u3),
                    w.sample(wo.to_array(), &s, u1, u2, u3)
                );
            }
        }
        // Black: no sample either way.
        let b = Ward::new(
            WardKind::Plastic,
            Color::black(3),
            0.0,
            0.0,
            0.0,
            0.0,
            ShadingOptions::rcontrib(),
        );
        let s = Surface::flat([0.0, 0.0, 1.0]);
        let wo = Vec3::new(0.0, 0.0, 1.0);
        assert_eq!(
            sample_material(&Material::Ward(b.clone()), wo, &s, 0.5, 0.5, 0.5),
            None
        );
        assert_eq!(b.sample(wo.to_array(), &s, 0.5, 0.5, 0.5), None);
    }
}
