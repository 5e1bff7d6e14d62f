//! The path-traced estimator: `rdc`'s [`Estimator`] over a compiled scene
//! ([`crate::trace::Renderable`]), one Monte Carlo sample per call.
//!
//! | mode | query | one sample is |
//! |---|---|---|
//! | sky coefficients (`-m`) | `-I` sensor | a cosine-distributed hemisphere path (rcontrib `-I+ -V-`: the sample's value is `pi x` the throughput of the path that escapes into patch `bin_of(dir)`) |
//! | sky coefficients (`-m`) | view ray | the throughput of the primary ray's path into its escape patch |
//! | direct-only (`-m --direct`) | as above | the same with `-ab 1` (rcontrib's C_dcd: patches seen directly or through specular transmission, no inter-reflection) |
//! | sun coefficients (`--suns`) | `-I` sensor | `cos x omega x` transmission towards each sun (glass passes, opaque blocks): `-ab 0` sun coefficients, as honeybee's direct-sunlight pass |
//! | values | `-I` sensor | direct sun (`L omega cos`, shadow-tested) + `pi x` one ambient path (rtrace `-I -aa 0 -as 0`) |
//! | values | view ray | one path's radiance (sees sun, sky and glows directly) |
//!
//! Paths start with weight `1/-ad` for `-lw` roulette as Radiance's ambient samples do, so
//! `-lw` has its Radiance meaning. Sensor points are offset `1e-4` along their normal
//! (`eval_irrad`).

use super::config::Sampling;
use super::tracer::SunDisc;
use super::tracer::{Estimator, Mode, Quantity, Query, Rng, Stratum, Tally};
use crate::geometry::Vec3;
use crate::material::Color;
use crate::material::sampling::cosine_hemisphere;
use crate::radiometry::MAX_SAMPLES;
use crate::trace::integrator::{PathSink, SENSOR_OFFSET};
use crate::trace::reweight::{Events, Tracking};
use crate::trace::{PathLimits, Renderable};
use rand::Rng as _;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicU64, Ordering};

pub struct Traced {
    scene: Renderable,
    params: PathLimits,
    direct_params: PathLimits,
    /// Starting path weight for `-lw` roulette (1/`-ad`).
    w0: f64,
    /// Materials whose re-weighting terms are recorded (`--reweight`).
    track: Option<Tracking>,
    /// Rays cast by paths so far (closest-hit queries, `--stats`).
    rays: AtomicU64,
}

impl Traced {
    pub fn new(scene: Renderable, p: &Sampling, ad: usize) -> Traced {
        // `-lr N`: at most |N| reflections (Radiance caps the depth for negative N too;
        // 0 means no cap, where 10 guards against endless mirror pairs).
        let max_depth = if p.lr == 0 { 10 } else { p.lr.unsigned_abs() };
        let params = PathLimits {
            ab: p.ab,
            lw: p.lw,
            max_depth,
            ambient_value: None,
            portals: p.portals,
            split: 1,
        };
        Traced {
            scene,
            params,
            direct_params: PathLimits {
                ab: p.ab.min(1),
                ..params
            },
            w0: 1.0 / ad.max(1) as f64,
            track: None,
            rays: AtomicU64::new(0),
        }
    }

    /// Split a sender ray's path at its first diffuse hit into `k` directions
    /// ([`PathLimits::split`]; `rdc --flux` with a sender file, `k` = `-ad`).
    pub fn set_first_bounce_split(&mut self, k: u32) {
        self.params.split = k.max(1);
    }

    /// Rays cast by paths so far (closest-hit and shadow queries of path samples; the
    /// shadow rays of `--suns` and of the direct sun term are not counted).
    pub fn rays(&self) -> u64 {
        self.rays.load(Ordering::Relaxed)
    }

    /// Record re-weighting terms for the materials of `track` (coefficient modes; the
    /// tally must keep terms, [`super::tracer::Tally::with_terms`]).
    pub fn with_tracking(mut self, track: Tracking) -> Traced {
        self.track = Some(track);
        self
    }
}

/// A stack buffer for one contribution (no allocation per sample).
type Buf = [f64; MAX_SAMPLES];

/// `c x scale` as f64 in `buf`, returned as the used slice.
fn scaled<'a>(c: &Color, scale: f64, buf: &'a mut Buf) -> &'a [f64] {
    let n = c.ncomp();
    for (b, &v) in buf.iter_mut().zip(c.as_slice()) {
        *b = v as f64 * scale;
    }
    &buf[..n]
}

fn add_color(tally: &mut Tally, col: usize, c: &Color, scale: f64, buf: &mut Buf) {
    tally.add(col, scaled(c, scale, buf));
}

/// [`add_color`] with the contribution's tracked events (re-weighting runs).
fn add_term(tally: &mut Tally, col: usize, c: &Color, scale: f64, ev: Events, buf: &mut Buf) {
    tally.add_term(col, ev.signature(), scaled(c, scale, buf));
}

/// Where a `--suns-ab` path's sun contributions go: column `i` of the tally, times `scale`
/// (pi for a sensor's cosine-sampled path, 1 for a view ray).
struct SunSink<'a> {
    suns: &'a [SunDisc],
    tally: &'a mut Tally,
    scale: f64,
    buf: Buf,
}

impl PathSink for SunSink<'_> {
    fn escape(&mut self, _dir: Vec3, _beta: Color, _events: &Events) {}
    fn nsuns(&self) -> usize {
        self.suns.len()
    }
    fn sun_at(&self, i: usize) -> (Vec3, f64) {
        (Vec3::from(self.suns[i].dir), self.suns[i].solid_angle)
    }
    fn sun(&mut self, i: usize, value: Color, events: &Events) {
        add_term(self.tally, i, &value, self.scale, *events, &mut self.buf);
    }
}

/// Where a `--flux` path's arrivals go: the receiver column of the surface or source it
/// ends on, times `scale` (pi for a sensor's cosine-sampled path, 1 for a ray).
struct FluxSink<'a> {
    receivers: &'a crate::rdc::flux::Receivers,
    tally: &'a mut Tally,
    scale: f64,
    buf: Buf,
}

impl PathSink for FluxSink<'_> {
    fn escape(&mut self, _dir: Vec3, _beta: Color, _events: &Events) {}
    fn escape_to(
        &mut self,
        source: Option<&crate::trace::sources::DistantSource>,
        _no_sources: bool,
        dir: Vec3,
        beta: Color,
        _events: &Events,
    ) {
        if let Some(col) = source.and_then(|s| self.receivers.column(s.scene_index, dir.to_array()))
        {
            add_color(self.tally, col, &beta, self.scale, &mut self.buf);
        }
    }
    fn emitter(&mut self, scene_index: u32, dir: Vec3, beta: Color, _events: &Events) {
        if let Some(col) = self.receivers.column(scene_index as usize, dir.to_array()) {
            add_color(self.tally, col, &beta, self.scale, &mut self.buf);
        }
    }
}

impl Traced {
    /// `--suns-ab`: one path sample (a stratified cosine direction from a sensor, or the
    /// view ray) whose every surface vertex looks at every sun.
    #[allow(clippy::too_many_arguments)]
    fn sun_bounces(
        &self,
        org: Vec3,
        dir: Vec3,
        from_sensor: bool,
        suns: &[SunDisc],
        rng: &mut Rng,
        tally: &mut Tally,
    ) {
        let (w0, scale) = if from_sensor {
            (self.w0, PI)
        } else {
            (1.0, 1.0)
        };
        let mut sink = SunSink {
            suns,
            tally,
            scale,
            buf: [0.0; MAX_SAMPLES],
        };
        let rays = self.scene.sun_path_sample(
            org,
            dir,
            from_sensor,
            w0,
            &self.params,
            rng,
            self.track.as_ref(),
            &mut sink,
        );
        sink.tally.add_rays(rays);
    }
}

impl Traced {
    /// An `-I` sensor sample's start: the offset point, unit normal, stratified cosine
    /// direction and the portal sample's three numbers (its point on the pane stratified
    /// like the direction, so a batch's portal samples cover the panes evenly).
    fn sensor_start(
        &self,
        q: &Query,
        stratum: Stratum,
        rng: &mut Rng,
    ) -> (Vec3, Vec3, Vec3, (f64, f64, f64)) {
        let nn = Vec3::from(q.dir).normalize();
        let (u, v) = stratum.unit_square(rng);
        let d = Vec3::from(cosine_hemisphere(nn.to_array(), u, v));
        let p = Vec3::from(q.org) + nn * SENSOR_OFFSET;
        let nee = if self.params.portals && self.scene.portal_count() > 0 {
            let (a, b) = stratum.unit_square(rng);
            (rng.random(), a, b)
        } else {
            (0.0, 0.0, 0.0)
        };
        (p, nn, d, nee)
    }
}

impl Estimator for Traced {
    fn add_rays(&self, n: u64) {
        self.rays.fetch_add(n, Ordering::Relaxed);
    }

    fn sample(&self, q: &Query, mode: &Mode, stratum: Stratum, rng: &mut Rng, tally: &mut Tally) {
        let mut buf: Buf = [0.0; MAX_SAMPLES];
        let n = Vec3::from(q.dir);
        match (q.quantity, mode) {
            (
                quantity,
                Mode::Sky {
                    patches,
                    direct_only,
                    below_horizon,
                },
            ) => {
                let params = if *direct_only {
                    &self.direct_params
                } else {
                    &self.params
                };
                // Escapes go straight into the tally (no per-sample allocation).
                let track = self.track.as_ref();
                let scale = match quantity {
                    Quantity::Irradiance => PI,
                    Quantity::Radiance => 1.0,
                };
                let mut escape = |e: Vec3, beta: Color, events: &Events| {
                    let d = e.to_array();
                    let bin = if *below_horizon && d[2] < 0.0 {
                        patches.len() + patches.bin_of([d[0], d[1], -d[2]])
                    } else {
                        patches.bin_of(d)
                    };
                    if track.is_some() {
                        add_term(tally, bin, &beta, scale, *events, &mut buf);
                    } else {
                        add_color(tally, bin, &beta, scale, &mut buf);
                    }
                };
                let rays = match quantity {
                    // A sensor sample leaves along a stratified cosine direction with weight
                    // 1/-ad (and samples the windows' portals) and counts pi x throughput.
                    Quantity::Irradiance => {
                        if params.ab == 0 {
                            return; // -ab 0: a sensor sees no glow (radiance-notes 12.8).
                        }
                        let (p, nn, d, nee) = self.sensor_start(q, stratum, rng);
                        self.scene
                            .sensor_sample(
                                p,
                                nn,
                                d,
                                nee,
                                true,
                                self.w0,
                                params,
                                rng,
                                track,
                                &mut escape,
                            )
                            .1
                    }
                    // A view ray is the primary ray itself.
                    Quantity::Radiance => {
                        self.scene
                            .path_sample(
                                Vec3::from(q.org),
                                n,
                                false,
                                true,
                                1.0,
                                params,
                                rng,
                                track,
                                &mut escape,
                            )
                            .1
                    }
                };
                tally.add_rays(rays);
            }
            (quantity, Mode::Flux { receivers }) => {
                // As sky coefficients: a sensor's stratified cosine sample with weight
                // 1/-ad counting pi x throughput, or the ray itself (a sender's ray, a
                // view ray) counting its throughput.
                let (org, dir, from_sensor, w0, scale) = match quantity {
                    Quantity::Irradiance => {
                        if self.params.ab == 0 {
                            return;
                        }
                        let (u, v) = stratum.unit_square(rng);
                        let d = cosine_hemisphere(n.normalize().to_array(), u, v);
                        let org = Vec3::from(q.org) + n.normalize() * SENSOR_OFFSET;
                        (org, Vec3::from(d), true, self.w0, PI)
                    }
                    Quantity::Radiance => (Vec3::from(q.org), n.normalize(), false, 1.0, 1.0),
                };
                let mut sink = FluxSink {
                    receivers,
                    tally,
                    scale,
                    buf,
                };
                let rays = self.scene.sink_path_sample(
                    org,
                    dir,
                    from_sensor,
                    w0,
                    &self.params,
                    rng,
                    &mut sink,
                );
                tally.add_rays(rays);
            }
            (Quantity::Irradiance, Mode::Suns { suns, bounces }) => {
                let org = Vec3::from(q.org) + n.normalize() * SENSOR_OFFSET;
                if *bounces && self.params.ab > 0 {
                    let (u, v) = stratum.unit_square(rng);
                    let d = cosine_hemisphere(n.normalize().to_array(), u, v);
                    self.sun_bounces(org, Vec3::from(d), true, suns, rng, tally);
                }
                for (i, s) in suns.iter().enumerate() {
                    let c = n.normalize().dot(Vec3::from(s.dir));
                    if c <= 0.0 {
                        continue;
                    }
                    if let Some((t, ev)) = self.scene.transmission_towards_tracked(
                        org,
                        Vec3::from(s.dir),
                        self.track.as_ref(),
                    ) {
                        add_term(tally, i, &t, c * s.solid_angle, ev, &mut buf);
                    }
                }
            }
            (Quantity::Radiance, Mode::Suns { suns, bounces }) => {
                if *bounces {
                    self.sun_bounces(Vec3::from(q.org), n.normalize(), false, suns, rng, tally);
                }
                // A view ray's sun coefficient: 1 when it looks into the disc unobstructed.
                if let Some(i) = suns
                    .iter()
                    .position(|s| n.normalize().dot(Vec3::from(s.dir)) >= s.cos_half)
                {
                    if let Some((t, ev)) = self.scene.transmission_towards_tracked(
                        Vec3::from(q.org),
                        n,
                        self.track.as_ref(),
                    ) {
                        add_term(tally, i, &t, 1.0, ev, &mut buf);
                    }
                }
            }
            (Quantity::Irradiance, Mode::Values) => {
                let nn = n.normalize();
                let org = Vec3::from(q.org) + nn * SENSOR_OFFSET;
                let mut e = self.scene.direct_irradiance(org, nn);
                if self.params.ab > 0 {
                    let (p, nn, d, nee) = self.sensor_start(q, stratum, rng);
                    let (l, rays) = self.scene.sensor_sample(
                        p,
                        nn,
                        d,
                        nee,
                        false,
                        self.w0,
                        &self.params,
                        rng,
                        None,
                        &mut |_, _, _| {},
                    );
                    tally.add_rays(rays);
                    e += l.scale(PI);
                }
                add_color(tally, 0, &e, 1.0, &mut buf);
            }
            (Quantity::Radiance, Mode::Values) => {
                let (l, rays) = self.scene.path_sample(
                    Vec3::from(q.org),
                    n,
                    false,
                    false,
                    1.0,
                    &self.params,
                    rng,
                    None,
                    &mut |_, _, _| {},
                );
                tally.add_rays(rays);
                add_color(tally, 0, &l, 1.0, &mut buf);
            }
        }
    }
}
