//! # Exterior obstruction as a skyline profile
//!
//! A real skyline is not one flat-topped sector: a building has ends, a height and a
//! distance, and sensors metres apart see it with parallax (issue 22). The profile is the
//! altitude `h_k` of the obstruction's top in azimuth sectors `[start + k step, start +
//! (k + 1) step)` (degrees east of north, `step` = [`STEP`], over the azimuths the windows
//! face +-90 degrees), 0 outside, as seen from the windows' centre `c` at its height; the
//! obstruction stands on the vertical cylinder of radius `distance` around `c` (what
//! `rcalib apply` writes: one facet per sector, top `z_c + distance tan h`). Flat sectors
//! rather than a smooth curve: a building's end is a step, which a curve through 5-10
//! degree nodes blurs over a whole node spacing (tried: linear between 10-degree nodes
//! lost to the one flat-topped sector on the skyline cases).
//!
//! What it hides is computed on the cells of [`Horizon`]:
//! - light entering the windows (every sensor's inter-reflected light): a cell of
//!   direction `d` seen from `c` is hidden by the share of its altitude range below the
//!   profile at its azimuth;
//! - each sensor's direct view of the sky and the direct sun: the ray from the *sensor*
//!   meets the cylinder at some azimuth and height, hidden when that height is below the
//!   profile there (parallax: a deep sensor sees the building's end at another azimuth
//!   than one at the window);
//! - the sun entering the windows (inter-reflected sun): the same test from each window's
//!   centre, weighted by its projected area towards the sun;
//! - light that met the exterior ground on its way in (the ground class's share of every
//!   coefficient, from the re-weighting records: [`Model::ground_part`]): hidden by the
//!   share of the ground points the windows see that no longer see the patch or the sun
//!   (a building stands higher seen from the ground before it, and shades it), or that
//!   lie behind the facets ([`GroundView`]); each sensor weighs those points by how its
//!   ground light reaches it ([`GroundWeights`]: the back of a side-lit room is lit by
//!   light entering at shallow angles, from the far ground a building shades first).
//!
//! In place of the hidden sky the facade sends back its own light as in
//! [`super::obstruction`] ([`facade_luminance`]), facing the room from the patch's azimuth.
//!
//! ## Fit
//! Penalised maximum likelihood: minimise `Q(h) = -2 ln L(h) + lambda |D2 h|^2` with `D2`
//! the second differences of the sector altitudes (a smoothness prior: Green & Silverman
//! 1994, penalised regression splines), `0 <= h_k <= MAX_ALT`, by Levenberg-Marquardt on
//! the log residuals with the random-intercept weights of [`crate::score`] (per sensor
//! `W_s = (I - g_s 11^T) / sigma_n^2`, `g_s = sigma_c^2 / (sigma_n^2 + T_s sigma_c^2)`), started
//! from the best flat-topped sector. The distance is chosen on a grid ([`DISTANCES`]) and
//! `lambda` on a grid ([`LAMBDAS`]), each by the BIC with the profile's effective number of
//! parameters `edf = tr((A + lambda P)^-1 A)` (the trace of the hat matrix, Hastie &
//! Tibshirani 1990, section 3.5; `A = J^T W J`, `P = D2^T D2`), plus one for the
//! distance. The same `edf + 1` is the effect's parameter count in explain's BIC, so a
//! rough profile chasing noise pays for every degree of freedom it uses. Sector
//! uncertainties are the posterior standard deviations `sqrt(diag((A + lambda P)^-1))`.
//! The facade's reflectance is fitted with the sectors (a golden-section search before and
//! after each solve; the facade's light is linear in it) and counts as one more parameter:
//! a fixed dark facade made a near building's light too low to reach with any profile
//! (docs/rcalib-effects.md). In the refinement ([`crate::explain::refine`]) the distance stays
//! where the fit put it, as the correction is made for the facets there.

use super::obstruction::{
    CELLS, FacadeLight, Horizon, facade_light, sky_luminance, window_azimuths, wrap_deg,
};
use super::{Effect, golden, smooth_step};
use crate::fit::{Fitter, without};
use crate::model::{Fill, Model, Weights};
use crate::room::dot;
use crate::stats::MIN_MEASURED;
use nalgebra::{DMatrix, DVector};

/// Width of the profile's sectors (degrees of azimuth).
pub const STEP: f64 = 5.0;
/// Highest altitude a sector may take (degrees).
pub const MAX_ALT: f64 = 75.0;
/// Distances of the obstruction from the windows' centre tried by the fit (m); those
/// closer than [`NEAREST`] times the farthest sensor are skipped.
pub const DISTANCES: [f64; 7] = [8.0, 12.0, 20.0, 35.0, 60.0, 120.0, 300.0];
/// Nearest distance the fit tries, in multiples of the farthest sensor's distance from
/// the windows' centre. Before the ground in front of the room was modelled
/// ([`GroundView`]) this was 5: on the studio skyline case the coefficient model's
/// prediction of a near building's profile against the re-simulation of what apply writes
/// differed by 24.7 % RMS at 12 m; with the ground's shade, the true building's own
/// profile at 14 m differs by 13.5 % (33.9 % without), as little as at 20-60 m (12.9-16.0
/// %), so nearer distances are as trustworthy as far ones.
pub const NEAREST: f64 = 2.0;
/// Smoothness weights tried (per squared degree of second difference), smooth to rough.
pub const LAMBDAS: [f64; 7] = [100.0, 10.0, 1.0, 0.1, 0.01, 1e-3, 1e-4];

/// Range of the facade reflectance the fit searches (and a spec may give): from a dark
/// facade to a white one. What the facade sends back is linear in it.
pub const RHO_MIN: f64 = 0.02;
pub const RHO_MAX: f64 = 0.9;

/// The facade reflectance a fit starts from: a mid-grey urban facade (0.2-0.35 for brick,
/// concrete and glazed facades; CIBSE LG10 (2014), Table 5.1 gives 0.2-0.4 for exterior
/// surfaces).
const RHO_START: f64 = 0.3;

/// The smoothness under which the distances are compared.
const SCREEN_LAMBDA: f64 = 0.01;

/// Azimuth bins of the facade luminance cache (degrees).
const FACADE_BIN: f64 = 5.0;

/// The profile's top (degrees) at azimuth `az`: the altitude of the sector `az` falls in,
/// 0 outside the sectors.
pub fn top(start: f64, step: f64, alts: &[f64], az: f64) -> f64 {
    let x = (az - start).rem_euclid(360.0) / step;
    alts.get(x.floor() as usize).copied().unwrap_or(0.0)
}

/// Share of the sun hidden behind a top at `top` degrees when its ray meets the cylinder
/// at elevation `el`: its edge smoothed over half a degree (as the sector's), and nothing
/// where the profile is 0.
fn sun_hidden(top: f64, el: f64) -> f64 {
    if top <= 0.0 {
        return 0.0;
    }
    smooth_step(top - el, 0.5) * (top / 0.5).min(1.0)
}

/// Where the ray from `org` along `d` meets the vertical cylinder of radius `dist` around
/// `c`: azimuth of the hit seen from `c` (degrees east of north) and its elevation above
/// `c` (degrees). `None` for a vertical ray or a ray starting outside.
pub fn hit(c: [f64; 3], dist: f64, org: [f64; 3], d: [f64; 3]) -> Option<(f64, f64)> {
    let (rx, ry) = (org[0] - c[0], org[1] - c[1]);
    let a = d[0] * d[0] + d[1] * d[1];
    let cc = rx * rx + ry * ry - dist * dist;
    if a < 1e-12 || cc >= 0.0 {
        return None;
    }
    let b = 2.0 * (rx * d[0] + ry * d[1]);
    let t = (-b + (b * b - 4.0 * a * cc).sqrt()) / (2.0 * a);
    let (hx, hy) = (rx + t * d[0], ry + t * d[1]);
    let hz = org[2] - c[2] + t * d[2];
    Some((
        hx.atan2(hy).to_degrees().rem_euclid(360.0),
        (hz / dist).atan().to_degrees(),
    ))
}

/// A sky cell a sensor sees directly: (weight, hit azimuth, hit elevation, the cell's
/// altitude range), degrees.
type SeenCell = (f64, f64, f64, f64);

/// The profile's view from the sensors and windows at one distance.
#[derive(Debug, Clone)]
pub struct Geometry {
    pub distance: f64,
    /// The windows' centre the profile is seen from.
    centre: [f64; 3],
    /// `[s][p]`: (cell, weight, hit azimuth, hit elevation, cell altitude range) of the
    /// cells sensor `s` sees directly ([`Horizon`]'s direct weights).
    dir: Vec<Vec<Vec<SeenCell>>>,
    /// `[t][s]`: the sun's hit seen from sensor `s`.
    sun_dir: Vec<Vec<Option<(f64, f64)>>>,
    /// `[t]`: per window (area x cosine towards the sun, hit azimuth, hit elevation).
    sun_win: Vec<Vec<(f64, f64, f64)>>,
    /// The sky's ground glow as the windows see it (the downward directions that miss the
    /// modelled ground): (area x cosine x solid angle, hit azimuth, hit height).
    glow_win: Vec<GlowCell>,
    /// `[s]`: the same for each sensor's direct view through the windows.
    glow_dir: Vec<Vec<GlowCell>>,
    /// The exterior ground in front of the room and what the profile hides from it.
    ground: GroundView,
}

/// Depression bands (degrees) and azimuth step of the directions in which the windows'
/// centroids look at the modelled ground ([`GroundView`]).
const GROUND_BANDS: [f64; 11] = [
    0.0, 4.0, 8.0, 13.0, 19.0, 26.0, 34.0, 43.0, 53.0, 65.0, 90.0,
];
const GROUND_AZ_STEP: f64 = 6.0;
/// Azimuth width (degrees) of the groups of ground cells a sensor's weights are kept
/// for ([`GroundWeights`]): with the depression bands, fine enough that a group's cells
/// land in the same part of the room.
const GROUND_GROUP_AZ: f64 = 30.0;
/// The nearest a landing point counts as being to a sensor (m^2): a ceiling point right
/// above a sensor lights it as a patch, not a point.
const LANDING_R2_MIN: f64 = 0.25;

/// One direction in which a window sees the modelled ground.
#[derive(Debug, Clone, Copy)]
struct GroundCell {
    /// Window area x cosine x the cell's solid angle.
    wt: f64,
    /// Where the ray from the window's centroid meets the ground.
    q: [f64; 3],
    /// The cell's group: (window, depression band, [`GROUND_GROUP_AZ`] sector).
    group: usize,
    /// The window's index and the cell's direction (downwards, out of the window).
    window: usize,
    d: [f64; 3],
}

/// The windows' view of the modelled ground (cells of [`GROUND_BANDS`] x
/// [`GROUND_AZ_STEP`] from each window's centroid that meet it) and the number of groups.
fn ground_cells(room: &crate::room::Room) -> (Vec<GroundCell>, usize) {
    let naz = (360.0 / GROUND_AZ_STEP) as usize;
    let nsec = (360.0 / GROUND_GROUP_AZ) as usize;
    let nb = GROUND_BANDS.len() - 1;
    let cells = window_cells(
        room,
        &downward_cells(&GROUND_BANDS, GROUND_AZ_STEP),
        &|o, d| room.ground_hit(o, d),
        &|wi, i| (wi * nb + i / naz) * nsec + (i % naz) * nsec / naz,
    );
    (cells, room.windows.len() * nb * nsec)
}

/// Each window's view of the downward directions `dirs` ((direction, solid angle), as
/// [`downward_cells`] makes them) weighted by area x cosine x solid angle: the cells for
/// which `point(centroid, direction)` gives a point (where the ray meets what it looks
/// for), in group `group(window index, cell index)`.
fn window_cells(
    room: &crate::room::Room,
    dirs: &[([f64; 3], f64)],
    point: &dyn Fn([f64; 3], [f64; 3]) -> Option<[f64; 3]>,
    group: &dyn Fn(usize, usize) -> usize,
) -> Vec<GroundCell> {
    let mut out = Vec::new();
    for (wi, w) in room.windows.iter().enumerate() {
        for (i, &(d, omega)) in dirs.iter().enumerate() {
            let wt = w.area * dot(d, w.outward).max(0.0) * omega;
            if wt <= 0.0 {
                continue;
            }
            let Some(q) = point(w.centroid, d) else {
                continue;
            };
            out.push(GroundCell {
                wt,
                q,
                group: group(wi, i),
                window: wi,
                d,
            });
        }
    }
    out
}

/// How much each sensor depends on each group of ground cells, relative to the windows
/// (1 for every group: as the windows see the ground). The light that met the ground
/// reaches a sensor in three ways ([`Model::ground_bounces`] gives each sensor's shares):
/// seen directly through a window (the sensor's own cosine-weighted view of the cell's
/// direction), after one bounce in the room (light entering upwards at the cell's
/// depression lands on the ceiling or a wall, nearer the window the steeper it comes, and
/// lights the sensor by the point-to-point form factor `cos cos / r^2` from where it
/// lands: a side-lit room's back is lit by the far, shallow ground a building shades first),
/// or after more bounces (spread through the room: as the windows see it). Without
/// re-weighting records every sensor weighs the ground as the windows do.
#[derive(Debug, Clone, Default)]
struct GroundWeights {
    ngroups: usize,
    /// `[s][g]` for the sky's ground light and for the sun's.
    sky: Vec<f64>,
    sun: Vec<f64>,
}

impl GroundWeights {
    /// From the windows' `cells` in `ngroups` groups, the `sensors` and their shares
    /// `bounces` (sky, sun; `None`: all after many bounces).
    fn new(
        room: &crate::room::Room,
        sensors: &[crate::formats::sensors::Sensor],
        bounces: Option<[Vec<[f64; 3]>; 2]>,
        cells: &[GroundCell],
        ngroups: usize,
    ) -> GroundWeights {
        let ns = sensors.len();
        let nc = cells.len();
        // Per cell and sensor: the direct and first-bounce kernels.
        let mut k0 = vec![0.0; nc * ns];
        let mut k1 = vec![0.0; nc * ns];
        // Entry points over each window's face, just inside it.
        let third = [1.0 / 6.0, 0.5, 5.0 / 6.0];
        let entries: Vec<Vec<[f64; 3]>> = room
            .windows
            .iter()
            .map(|w| {
                let u0 = dot(w.centroid, w.tangent);
                third
                    .iter()
                    .flat_map(|&fu| {
                        third.map(|fz| {
                            let u = w.span.0 + fu * (w.span.1 - w.span.0) - u0;
                            [
                                w.centroid[0] + u * w.tangent[0] - 1e-3 * w.outward[0],
                                w.centroid[1] + u * w.tangent[1] - 1e-3 * w.outward[1],
                                w.sill + fz * (w.head - w.sill),
                            ]
                        })
                    })
                    .collect()
            })
            .collect();
        for (k, c) in cells.iter().enumerate() {
            let (w, d) = (&room.windows[c.window], c.d);
            let cw = dot(d, w.outward);
            let up = [-d[0], -d[1], -d[2]];
            let ents = &entries[c.window];
            let lands: Vec<([f64; 3], [f64; 3])> =
                ents.iter().filter_map(|e| room.landing(*e, up)).collect();
            for (s, sensor) in sensors.iter().enumerate() {
                let (org, n) = (sensor.ray.org, sensor.ray.dir);
                if super::obstruction::window_hit(w, org, d) {
                    k0[k * ns + s] = dot(d, n).max(0.0) / (w.area * cw);
                }
                let mut sum = 0.0;
                for (l, nl) in &lands {
                    let v = [org[0] - l[0], org[1] - l[1], org[2] - l[2]];
                    let r2 = dot(v, v);
                    let r = r2.sqrt();
                    if r < 1e-9 {
                        continue;
                    }
                    let (cl, cs) = (dot(*nl, v) / r, -dot(n, v) / r);
                    if cl > 0.0 && cs > 0.0 {
                        sum += cl * cs / r2.max(LANDING_R2_MIN);
                    }
                }
                k1[k * ns + s] = sum / ents.len() as f64;
            }
        }
        let total: f64 = cells.iter().map(|c| c.wt).sum();
        let mut gw = vec![0.0; ngroups];
        for c in cells {
            gw[c.group] += c.wt;
        }
        let weights = |which: usize| -> Vec<f64> {
            let mut out = vec![0.0; ns * ngroups];
            for s in 0..ns {
                let [mut b0, mut b1, mut br] =
                    bounces.as_ref().map_or([0.0, 0.0, 1.0], |b| b[which][s]);
                // Each kernel's mean over the windows' view, to make it relative.
                let mean = |kk: &[f64]| {
                    cells
                        .iter()
                        .enumerate()
                        .map(|(i, c)| c.wt * kk[i * ns + s])
                        .sum::<f64>()
                        / total
                };
                let (m0, m1) = (mean(&k0), mean(&k1));
                if m0 <= 0.0 {
                    (br, b0) = (br + b0, 0.0);
                }
                if m1 <= 0.0 {
                    (br, b1) = (br + b1, 0.0);
                }
                let row = &mut out[s * ngroups..(s + 1) * ngroups];
                for (i, c) in cells.iter().enumerate() {
                    let mut kappa = br;
                    if b0 > 0.0 {
                        kappa += b0 * k0[i * ns + s] / m0;
                    }
                    if b1 > 0.0 {
                        kappa += b1 * k1[i * ns + s] / m1;
                    }
                    row[c.group] += c.wt * kappa;
                }
                for (r, g) in row.iter_mut().zip(&gw) {
                    if *g > 0.0 {
                        *r /= g;
                    }
                }
            }
            out
        };
        GroundWeights {
            ngroups,
            sky: weights(0),
            sun: weights(1),
        }
    }
}

/// The modelled exterior ground as the windows see it, and the sky and sun the profile
/// hides from it. A near building shades the ground in front of the room: seen from a
/// point of that ground (lower and nearer the building than the windows) its top stands
/// higher, and its shadow falls on the ground before it reaches the facade. Most of the
/// ground light entering a vertical window comes from its first few metres (half of the
/// window's downward view lies within one sill-height-and-a-half of the wall). Light that
/// met the ground on its way in ([`Model::ground_part`]) is hidden by the share of these
/// points that no longer see the patch (or the sun), and by the share of the ground
/// behind the facets, which the windows no longer see at all; each sensor weighs the
/// points by [`GroundWeights`].
#[derive(Debug, Clone, Default)]
struct GroundView {
    /// Sum of the points' weights.
    total: f64,
    /// Points beyond the cylinder: (group, weight, azimuth seen from the windows' centre).
    behind: Vec<(usize, f64, f64)>,
    /// `[p]`: (group, weight, hit azimuth, hit elevation) of the ray from each point inside
    /// the cylinder towards the patch's centre.
    sky: Vec<Vec<(usize, f64, f64, f64)>>,
    /// `[p]`: the patch's altitude range (degrees; 0 where the profile cannot reach it).
    span: Vec<f64>,
    /// `[t]`: the same rays towards the sun.
    sun: Vec<Vec<(usize, f64, f64, f64)>>,
}

/// The ground cells split by the cylinder of radius `dist` around `c`: the sum of the
/// weights, the cells beyond it as (group, weight, azimuth seen from `c`), and those
/// inside it as (group, weight, point).
type GroundPoints = (f64, Vec<(usize, f64, f64)>, Vec<(usize, f64, [f64; 3])>);

fn ground_points(cells: &[GroundCell], c: [f64; 3], dist: f64) -> GroundPoints {
    let mut total = 0.0;
    let mut behind = Vec::new();
    let mut points = Vec::new();
    for gc in cells {
        total += gc.wt;
        let (dx, dy) = (gc.q[0] - c[0], gc.q[1] - c[1]);
        if dx * dx + dy * dy >= dist * dist {
            let az = dx.atan2(dy).to_degrees().rem_euclid(360.0);
            behind.push((gc.group, gc.wt, az));
        } else {
            points.push((gc.group, gc.wt, gc.q));
        }
    }
    (total, behind, points)
}

impl GroundView {
    fn new(m: &Model, hz: &Horizon, c: [f64; 3], dist: f64, cells: &[GroundCell]) -> GroundView {
        let (total, behind, points) = ground_points(cells, c, dist);
        let rays = |d: [f64; 3]| -> Vec<(usize, f64, f64, f64)> {
            points
                .iter()
                .filter_map(|&(g, wt, q)| hit(c, dist, q, d).map(|(az, el)| (g, wt, az, el)))
                .collect()
        };
        let np = m.comps.npatch;
        let mut sky = vec![Vec::new(); np];
        let mut span = vec![0.0; np];
        for (p, pc) in hz.cells.iter().enumerate().take(np) {
            let Some(pc) = pc else { continue };
            let (lo, hi) = (pc.alt[0], pc.alt[CELLS]);
            let alt = (0.5 * (lo + hi)).to_radians();
            let az = (pc.az0 + 0.5 * CELLS as f64 * pc.daz).to_radians();
            sky[p] = rays([alt.cos() * az.sin(), alt.cos() * az.cos(), alt.sin()]);
            span[p] = hi - lo;
        }
        let sun = m
            .skies
            .iter()
            .map(|sk| {
                if sk.sun_altitude_deg > 0.0 {
                    rays(sk.sun_dir)
                } else {
                    Vec::new()
                }
            })
            .collect();
        GroundView {
            total,
            behind,
            sky,
            span,
            sun,
        }
    }

    /// Per group, the weight of the ground behind the facets of profile `tp`.
    fn behind(&self, tp: &dyn Fn(f64) -> f64, ngroups: usize) -> Vec<f64> {
        let mut out = vec![0.0; ngroups];
        for &(g, wt, az) in &self.behind {
            if tp(az) > 0.0 {
                out[g] += wt;
            }
        }
        out
    }
}

/// Per sensor, the share of the ground light hidden: `(behind[s] + sum over groups of
/// weights[s][g] hidden[g]) / total`, capped at 1; `hidden` lists the groups with some
/// weight hidden.
fn hidden_share(
    weights: &[f64],
    ngroups: usize,
    behind: &[f64],
    hidden: &[(usize, f64)],
    total: f64,
    s: usize,
) -> f64 {
    let row = &weights[s * ngroups..(s + 1) * ngroups];
    let hid: f64 = hidden.iter().map(|&(g, h)| row[g] * h).sum();
    ((behind[s] + hid) / total).min(1.0)
}

/// Downward directions of [`glow_cells`]: depression bands (degrees) fine near the
/// horizon, where the glow beyond a modelled ground is seen, and azimuth steps.
const GLOW_BANDS: [f64; 14] = [
    0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0, 12.0, 20.0, 35.0, 55.0, 90.0,
];
const GLOW_AZ_STEP: f64 = 2.0;

/// Downward directions in cells of depression `bands` (degrees) by `az_step` degrees of
/// azimuth: (unit direction through the cell's middle, the cell's solid angle
/// `(sin d1 - sin d0) x azimuth step`).
fn downward_cells(bands: &[f64], az_step: f64) -> Vec<([f64; 3], f64)> {
    let naz = (360.0 / az_step) as usize;
    let mut out = Vec::with_capacity(naz * bands.len());
    for b in bands.windows(2) {
        let (d0, d1) = (b[0].to_radians(), b[1].to_radians());
        let dm = 0.5 * (d0 + d1);
        let omega = (d1.sin() - d0.sin()) * az_step.to_radians();
        for k in 0..naz {
            let az = ((k as f64 + 0.5) * az_step).to_radians();
            out.push(([dm.cos() * az.sin(), dm.cos() * az.cos(), -dm.sin()], omega));
        }
    }
    out
}

/// The ground-glow directions seen from `org` (cells of [`GLOW_BANDS`] x
/// [`GLOW_AZ_STEP`]) that `weight` accepts and that miss the modelled ground, each with
/// `weight x solid angle`, the azimuth (seen from `c`) and the height at which it meets
/// the cylinder of radius `dist` around `c`. A skyline's facets stand from
/// [`crate::apply::SKYLINE_BOTTOM`] up: the glow behind them is hidden where the ray meets
/// the cylinder above that (a near obstruction hides the bright band just below the
/// horizon that lights the back of a side-lit room; one 300 m away, a sliver).
fn glow_cells(
    m: &Model,
    c: [f64; 3],
    dist: f64,
    org: [f64; 3],
    weight: &dyn Fn([f64; 3]) -> f64,
) -> Vec<GlowCell> {
    let mut out = Vec::new();
    for (i, (d, omega)) in downward_cells(&GLOW_BANDS, GLOW_AZ_STEP)
        .into_iter()
        .enumerate()
    {
        let w = weight(d);
        if w <= 0.0 || m.room.meets_ground(org, d) {
            continue;
        }
        if let Some((haz, el)) = hit(c, dist, org, d) {
            out.push((w * omega, haz, c[2] + dist * el.to_radians().tan(), i));
        }
    }
    out
}

/// A glow cell of [`glow_cells`]: (weight x solid angle, azimuth and height where it meets
/// the cylinder, the cell's index among the downward cells).
type GlowCell = (f64, f64, f64, usize);

/// Share of the glow cells `cells` the profile `tp` hides, each weighted besides by
/// `extra` of its index.
fn glow_hidden(
    cells: &[GlowCell],
    tp: &dyn Fn(f64) -> f64,
    extra: &dyn Fn(usize) -> f64,
) -> Option<f64> {
    let (mut b, mut t) = (0.0, 0.0);
    for &(w, az, z, i) in cells {
        let w = w * extra(i);
        t += w;
        if tp(az) > 0.0 && z > crate::apply::SKYLINE_BOTTOM {
            b += w;
        }
    }
    (t > 0.0).then(|| b / t)
}

/// The glow's directions from each window (cells of [`GLOW_BANDS`] x [`GLOW_AZ_STEP`]
/// that miss the modelled ground) as [`GroundCell`]s, grouped one a cell (window index x
/// cells a window + the cell's index), and the number of groups.
fn glow_window_cells(room: &crate::room::Room) -> (Vec<GroundCell>, usize) {
    let dirs = downward_cells(&GLOW_BANDS, GLOW_AZ_STEP);
    let n = dirs.len();
    let cells = window_cells(
        room,
        &dirs,
        &|o, d| (!room.meets_ground(o, d)).then_some(o),
        &|wi, i| wi * n + i,
    );
    (cells, room.windows.len() * n)
}

impl Geometry {
    /// At `distance`, from the windows' ground `cells` and glow cells `glow`.
    fn new(m: &Model, distance: f64, cells: &[GroundCell], glow: &[GroundCell]) -> Geometry {
        let hz = m.horizon();
        let (c, _) = crate::apply::window_centre(&m.room, &m.sensors);
        let never = (0.0, 90.0);
        let dir = m
            .sensors
            .iter()
            .enumerate()
            .map(|(s, sensor)| {
                (0..hz.cells.len())
                    .map(|p| {
                        let (Some(pc), Some(ws)) = (hz.cells[p].as_ref(), hz.dir[s].get(p)) else {
                            return Vec::new();
                        };
                        let mut v = Vec::new();
                        for (cell, &w) in ws.iter().enumerate() {
                            if w <= 0.0 {
                                continue;
                            }
                            let (a, b) = (cell / CELLS, cell % CELLS);
                            let (az, el) =
                                hit(c, distance, sensor.ray.org, pc.centre(a, b)).unwrap_or(never);
                            v.push((w, az, el, pc.alt[a + 1] - pc.alt[a]));
                        }
                        v
                    })
                    .collect()
            })
            .collect();
        let mut sun_dir = Vec::new();
        let mut sun_win = Vec::new();
        for sk in &m.skies {
            if sk.sun_altitude_deg <= 0.0 {
                sun_dir.push(Vec::new());
                sun_win.push(Vec::new());
                continue;
            }
            sun_dir.push(
                m.sensors
                    .iter()
                    .map(|s| hit(c, distance, s.ray.org, sk.sun_dir))
                    .collect(),
            );
            sun_win.push(
                m.room
                    .windows
                    .iter()
                    .filter_map(|w| {
                        let wt = w.area * dot(sk.sun_dir, w.outward).max(0.0);
                        let (az, el) = hit(c, distance, w.centroid, sk.sun_dir)?;
                        (wt > 0.0).then_some((wt, az, el))
                    })
                    .collect(),
            );
        }
        let glow_win = glow
            .iter()
            .filter_map(|g| {
                let (haz, el) = hit(c, distance, g.q, g.d)?;
                Some((g.wt, haz, c[2] + distance * el.to_radians().tan(), g.group))
            })
            .collect();
        let glow_dir = m
            .sensors
            .iter()
            .map(|s| {
                glow_cells(m, c, distance, s.ray.org, &|d| {
                    let cos = dot(d, s.ray.dir);
                    if cos > 0.0
                        && m.room
                            .windows
                            .iter()
                            .any(|w| super::obstruction::window_hit(w, s.ray.org, d))
                    {
                        cos
                    } else {
                        0.0
                    }
                })
            })
            .collect();
        let ground = GroundView::new(m, hz, c, distance, cells);
        Geometry {
            distance,
            centre: c,
            dir,
            sun_dir,
            sun_win,
            glow_win,
            glow_dir,
            ground,
        }
    }
}

/// The luminance of a facade of outward normal `n_f` at step `t` (reflectance
/// `apply::OBSTRUCTION_REFLECTANCE`, Lambertian) in three parts: lit by the sky patches and
/// the sun; by the ground the sky lights; by the ground the sun lights. The ground fills
/// the lower quarter sphere (pi/2 of cosine-weighted solid angle) at luminance
/// `rho_g E / pi`, `rho_g` the modelled ground's reflectance (without one, the sky's ground
/// patch's). [`apply`] weighs the two ground parts by how much of the sky and the sun the
/// profile leaves the ground before the facade: a building shades the street in front of it.
fn facade_parts(f: &FacadeLight, m: &Model, t: usize) -> [f64; 3] {
    let e = f.e_sky + f.e_sun;
    let rho_g = if m.room.ground_reflectance > 0.0 {
        m.room.ground_reflectance
    } else if e > 0.0 {
        sky_luminance(m, t, 0) * std::f64::consts::PI / e
    } else {
        0.0
    };
    let g = |e: f64| f.rho * rho_g * e / (2.0 * std::f64::consts::PI);
    [
        f.rho * f.e_direct / std::f64::consts::PI,
        g(f.e_sky),
        g(f.e_sun),
    ]
}

/// Share of the sky's light (a uniform sky) that a long wall of height `h` takes from the
/// street before it, as a point of the wall at height `z = u h` sees that street. Ground at
/// distance `x` from the wall sees the sky only above the wall's top, at elevation
/// `beta = atan(h / x)`: the wall takes `(1 - cos beta) / 2` of its irradiance (the view
/// factor from a long strip to a long wall, in 2-D). The wall's point sees ground at
/// depression `delta` (distance `x = z / tan delta`) with weight `(4 / pi) cos^2 delta`
/// per radian (a vertical plane's cosine-weighted view of the ground, over every azimuth):
/// the wall's foot sees the darkest street (1/2), its top a street half as dark.
fn street_sky_shade(u: f64) -> f64 {
    const N: usize = 64;
    static TABLE: std::sync::OnceLock<Vec<f64>> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        let cum = |d: f64| (d + d.sin() * d.cos()) * std::f64::consts::FRAC_2_PI;
        (0..=N)
            .map(|i| {
                let u = (i as f64 / N as f64).max(1e-6);
                let bands = 256;
                (0..bands)
                    .map(|j| {
                        let step = std::f64::consts::FRAC_PI_2 / bands as f64;
                        let (d0, d1) = (j as f64 * step, (j + 1) as f64 * step);
                        let t = (0.5 * (d0 + d1)).tan();
                        let cos_beta = u / (u * u + t * t).sqrt();
                        (cum(d1) - cum(d0)) * 0.5 * (1.0 - cos_beta)
                    })
                    .sum()
            })
            .collect()
    });
    let x = u.clamp(0.0, 1.0) * N as f64;
    let i = (x as usize).min(N - 1);
    table[i] + (x - i as f64) * (table[i + 1] - table[i])
}

/// Share of the street before a wall of height `h` (outward normal `n_f`, horizontal) that
/// a point of the wall at height `z` sees in the wall's own shadow, the sun along `sun`
/// (unit, towards it): none with the sun before the wall; behind it, the shadow reaches
/// `x_s = h cos(dazimuth) / tan(altitude)` from the wall, seen below the depression
/// `atan(z / x_s)`, a share `1 - (2 / pi) (delta_s + sin delta_s cos delta_s)` of the wall's
/// ground view (the weights of [`street_sky_shade`]).
fn street_sun_shade(z: f64, h: f64, n_f: [f64; 3], sun: [f64; 3]) -> f64 {
    let horizontal = (sun[0] * sun[0] + sun[1] * sun[1]).sqrt();
    let behind = -(sun[0] * n_f[0] + sun[1] * n_f[1]);
    if behind <= 0.0 || sun[2] <= 0.0 || horizontal <= 0.0 {
        return 0.0;
    }
    let x_s = h * behind / sun[2];
    let d = (z / x_s).atan();
    1.0 - (d + d.sin() * d.cos()) * std::f64::consts::FRAC_2_PI
}

/// Per model: the geometries at [`DISTANCES`] and the facade's luminance over each sky
/// patch's, `[t][p]` (see [`Model::skyline`]).
#[derive(Debug, Clone)]
pub struct Cache {
    geoms: Vec<Geometry>,
    /// `[t][p]`: the facade's luminance over the patch's as the flat obstruction's
    /// ([`facade_luminance`]), used where no modelled ground lies before the facets.
    ratio: Vec<f64>,
    /// `[t][p]`: its parts ([`facade_parts`]) over the patch's luminance: the facade lit by
    /// the sky and the sun, by the ground the sky lights, by the ground the sun lights.
    parts: [Vec<f64>; 3],

    cells: Vec<GroundCell>,
    weights: GroundWeights,
    /// The glow's cells from the windows ([`glow_window_cells`]) and each sensor's
    /// weights of them, one a group.
    glow_cells: Vec<GroundCell>,
    glow_weights: GroundWeights,
    /// The lowest point of the modelled ground, where the street before a facade lies
    /// (`None` without a modelled ground).
    ground_level: Option<f64>,
}

impl Cache {
    pub fn new(m: &Model) -> Cache {
        let (cells, ngroups) = ground_cells(&m.room);
        let bounces = m.ground_bounces();
        let weights = GroundWeights::new(&m.room, &m.sensors, bounces.clone(), &cells, ngroups);
        // The glow's light entering the windows (its direct view is the sensors' own):
        // the ground's shares of one and more bounces, made whole.
        let indirect = bounces.map(|b| {
            b.map(|v| {
                v.into_iter()
                    .map(|[d, one, more]| {
                        let r = one + more;
                        if d < 1.0 && r > 0.0 {
                            [0.0, one / r, more / r]
                        } else {
                            [0.0, 0.0, 1.0]
                        }
                    })
                    .collect()
            })
        });
        let (glow_cells, gn) = glow_window_cells(&m.room);
        let glow_weights = GroundWeights::new(&m.room, &m.sensors, indirect, &glow_cells, gn);
        let geoms = distances(m)
            .into_iter()
            .map(|d| Geometry::new(m, d, &cells, &glow_cells))
            .collect();
        let ground_level = m
            .room
            .ground_polygons
            .iter()
            .flatten()
            .map(|v| v[2])
            .reduce(f64::min);
        let (nt, np) = (m.nsteps(), m.comps.npatch);
        let nbin = (360.0 / FACADE_BIN) as usize;
        let mut ratio = vec![0.0; nt * np];
        let mut parts = [vec![0.0; nt * np], vec![0.0; nt * np], vec![0.0; nt * np]];
        let wa = window_azimuths(m)[0].to_radians();
        for t in 0..nt {
            // Per bin: the facade's luminance as the flat obstruction's, and its parts.
            let bins: Vec<(f64, [f64; 3])> = (0..=nbin)
                .map(|b| {
                    // The last one is the glow's stand-in: the facade's lower part, facing
                    // the room from the windows' outward azimuth.
                    let az = if b == nbin {
                        wa
                    } else {
                        ((b as f64 + 0.5) * FACADE_BIN).to_radians()
                    };
                    let n = [-az.sin(), -az.cos(), 0.0];
                    let f = facade_light(m, t, n);
                    (f.luminance(m, t), facade_parts(&f, m, t))
                })
                .collect();
            let mut put = |p: usize, b: usize, l: f64| {
                if l > 0.0 {
                    ratio[t * np + p] = bins[b].0 / l;
                    for (k, v) in parts.iter_mut().enumerate() {
                        v[t * np + p] = bins[b].1[k] / l;
                    }
                }
            };
            put(0, nbin, sky_luminance(m, t, 0));
            for p in 1..np {
                let az = m.patches.centre_angles(p).1.to_degrees().rem_euclid(360.0);
                let b = ((az / FACADE_BIN) as usize).min(nbin - 1);
                put(p, b, sky_luminance(m, t, p));
            }
        }
        Cache {
            geoms,
            ratio,
            parts,
            cells,
            weights,
            glow_cells,
            glow_weights,
            ground_level,
        }
    }

    fn geometry(&self, distance: f64) -> Option<&Geometry> {
        self.geoms
            .iter()
            .find(|g| (g.distance - distance).abs() < 1e-9)
    }
}

/// The farthest sensor's (or window's) horizontal distance from the windows' centre, at
/// least 1 m.
fn farthest(m: &Model) -> f64 {
    let (c, _) = crate::apply::window_centre(&m.room, &m.sensors);
    m.sensors
        .iter()
        .map(|s| s.ray.org)
        .chain(m.room.windows.iter().map(|w| w.centroid))
        .map(|p| ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt())
        .fold(1.0, f64::max)
}

/// The distances of [`DISTANCES`] at least [`NEAREST`] times the farthest sensor's (or
/// window's) distance from the windows' centre (the farthest one at least): those the
/// coefficient model's fit chooses among.
pub fn distances(m: &Model) -> Vec<f64> {
    let far = farthest(m);
    let v: Vec<f64> = DISTANCES
        .iter()
        .copied()
        .filter(|d| *d >= NEAREST * far)
        .collect();
    if v.is_empty() {
        vec![DISTANCES[DISTANCES.len() - 1].max(NEAREST * far)]
    } else {
        v
    }
}

/// Multiply the window weights and the sun's window weights by what the profile leaves
/// visible, and set what its facade sends back ([`Fill`]).
pub fn apply(e: &Effect, m: &Model, w: &mut Weights) {
    let Effect::Skyline {
        distance,
        start,
        step,
        alts,
        reflectance,
        ..
    } = e
    else {
        return;
    };
    let (start, step) = (*start, *step);
    // The cached facade luminances are for apply's default reflectance; the facade's
    // light is linear in it.
    let k = reflectance / crate::apply::OBSTRUCTION_REFLECTANCE;
    let tp = |az: f64| top(start, step, alts, az);
    let highest = alts.iter().copied().fold(0.0, f64::max);
    let cache = m.skyline();
    let owned;
    let g = match cache.geometry(*distance) {
        Some(g) => g,
        None => {
            owned = Geometry::new(m, *distance, &cache.cells, &cache.glow_cells);
            &owned
        }
    };
    let hz: &Horizon = m.horizon();
    let (ns, np, nt) = (m.nsens(), m.comps.npatch, m.nsteps());
    let mut wd = w.win_dir.take().unwrap_or_else(|| vec![1.0; ns * np]);
    let mut fill = Fill {
        ind: vec![0.0; np],
        dir: vec![0.0; ns * np],
        ratio: cache.ratio.iter().map(|r| r * k).collect(),
        gnd: None,
        glow: None,
    };
    // The ground's part starts from the other effects' window weights (see
    // [`GroundView`]).
    let gnd = w.gnd.take().unwrap_or_else(|| w.win_ind.clone());
    let sun_gnd = w.sun_gnd.take().unwrap_or_else(|| w.sun_win_ind.clone());
    for i in 1..np.min(hz.cells.len()) {
        let Some(pc) = hz.cells[i].as_ref() else {
            continue;
        };
        if pc.alt[0] >= highest {
            continue;
        }
        let tops: Vec<f64> = (0..CELLS)
            .map(|b| tp(pc.az0 + pc.daz * (b as f64 + 0.5)))
            .collect();
        let (mut blk, mut tot) = (0.0, 0.0);
        for a in 0..CELLS {
            let (lo, hi) = (pc.alt[a], pc.alt[a + 1]);
            for (b, t) in tops.iter().enumerate() {
                let wt = hz.ind[i][a * CELLS + b];
                if wt > 0.0 {
                    tot += wt;
                    blk += wt * ((t - lo) / (hi - lo)).clamp(0.0, 1.0);
                }
            }
        }
        let f_ind = if tot > 0.0 { blk / tot } else { 0.0 };
        fill.ind[i] = f_ind * w.win_ind[i];
        w.win_ind[i] *= 1.0 - f_ind;
        for s in 0..ns {
            let cells = &g.dir[s][i];
            let f = if cells.is_empty() {
                f_ind
            } else {
                let (mut b, mut t) = (0.0, 0.0);
                for &(wt, az, el, h) in cells {
                    t += wt;
                    // A sector at 0 has no facet (apply writes none): it hides nothing,
                    // not even below the centre's horizon.
                    let t = tp(az);
                    if t > 0.0 {
                        b += wt * ((t - el) / h + 0.5).clamp(0.0, 1.0);
                    }
                }
                b / t
            };
            fill.dir[s * np + i] = f * wd[s * np + i];
            wd[s * np + i] *= 1.0 - f;
        }
    }
    // The ground glow (patch 0): hidden where the facets stand in front of it.
    // Its light entering the windows reaches each sensor from its own directions (the
    // back of the room from those nearest the windows' normal: [`GroundWeights`]).
    if let Some(f0) = glow_hidden(&g.glow_win, &tp, &|_| 1.0) {
        let gw = &cache.glow_weights;
        let win0 = w.win_ind[0];
        let mut left = w.glow_ind.take().unwrap_or_else(|| vec![win0; ns]);
        let mut fg = vec![0.0; ns];
        for s in 0..ns {
            let row = &gw.sky[s * gw.ngroups..(s + 1) * gw.ngroups];
            let f = glow_hidden(&g.glow_win, &tp, &|i| row[i]).unwrap_or(f0);
            fg[s] = f * left[s];
            left[s] *= 1.0 - f;
        }
        w.glow_ind = Some(left);
        fill.glow = Some(fg);
        fill.ind[0] = f0 * win0;
        w.win_ind[0] *= 1.0 - f0;
        for s in 0..ns {
            let f = glow_hidden(&g.glow_dir[s], &tp, &|_| 1.0).unwrap_or(f0);
            fill.dir[s * np] = f * wd[s * np];
            wd[s * np] *= 1.0 - f;
        }
    }
    w.win_dir = Some(wd);
    let gv = &g.ground;
    if gv.total > 0.0 {
        let gwt = &cache.weights;
        let ng = gwt.ngroups;
        let behind = gv.behind(&tp, ng);
        let per_sensor = |weights: &[f64]| -> Vec<f64> {
            (0..ns)
                .map(|s| {
                    let row = &weights[s * ng..(s + 1) * ng];
                    row.iter().zip(&behind).map(|(a, b)| a * b).sum()
                })
                .collect()
        };
        let (behind_sky, behind_sun) = (per_sensor(&gwt.sky), per_sensor(&gwt.sun));
        let mut seen = w.gnd_seen.take().unwrap_or_else(|| vec![1.0; ns * np]);
        let mut fg = vec![0.0; ns * np];
        let mut hidden: Vec<(usize, f64)> = Vec::new();
        let mut acc = vec![0.0; ng];
        // Sum the hidden weight per group, listing the groups touched.
        let mut gather = |rays: &[(usize, f64, f64, f64)],
                          amount: &dyn Fn(f64, f64, f64) -> f64,
                          hidden: &mut Vec<(usize, f64)>| {
            hidden.clear();
            for &(grp, wt, az, el) in rays {
                let h = amount(tp(az), el, wt);
                if h > 0.0 {
                    if acc[grp] == 0.0 {
                        hidden.push((grp, 0.0));
                    }
                    acc[grp] += h;
                }
            }
            for x in hidden.iter_mut() {
                x.1 = acc[x.0];
                acc[x.0] = 0.0;
            }
        };
        let any_behind = behind.iter().any(|b| *b > 0.0);
        for p in 0..np {
            hidden.clear();
            if let Some(v) = gv.sky.get(p).filter(|_| gv.span[p] > 0.0) {
                let span = gv.span[p];
                gather(
                    v,
                    &|t, el, wt| {
                        if t > 0.0 {
                            wt * ((t - el) / span + 0.5).clamp(0.0, 1.0)
                        } else {
                            0.0
                        }
                    },
                    &mut hidden,
                );
            }
            if hidden.is_empty() && !any_behind {
                continue;
            }
            for s in 0..ns {
                let f = hidden_share(&gwt.sky, ng, &behind_sky, &hidden, gv.total, s);
                fg[s * np + p] = f * gnd[p] * seen[s * np + p];
                seen[s * np + p] *= 1.0 - f;
            }
        }
        let mut sun_seen = w.sun_gnd_seen.take().unwrap_or_else(|| vec![1.0; ns * nt]);
        for (t, v) in gv.sun.iter().enumerate().take(nt) {
            gather(v, &|top, el, wt| wt * sun_hidden(top, el), &mut hidden);
            for s in 0..ns {
                let f = hidden_share(&gwt.sun, ng, &behind_sun, &hidden, gv.total, s);
                sun_seen[s * nt + t] *= 1.0 - f;
            }
        }
        fill.gnd = Some(fg);
        w.gnd_seen = Some(seen);
        w.sun_gnd_seen = Some(sun_seen);
    }
    w.gnd = Some(gnd);
    w.sun_gnd = Some(sun_gnd);
    // The facade's light from the street before it, as much as the sky and the sun still
    // light that street: a point of the facade at the height the hidden patch is seen at,
    // in front of a long wall as high as the profile there ([`facade_parts`]).
    if let Some(zg) = cache.ground_level {
        // The ground's reflectance as fitted so far (a ground-albedo effect applied first).
        let kg = m.ground_scale(&w.refl);
        let c = g.centre;
        let wa = window_azimuths(m)[0];
        let dist = *distance;
        for p in 0..np {
            let (alt, az) = if p == 0 {
                (0.0, wa)
            } else {
                let (a, z) = m.patches.centre_angles(p);
                (a.to_degrees(), z.to_degrees().rem_euclid(360.0))
            };
            let top_p = tp(az);
            if top_p <= 0.0 {
                continue;
            }
            let h = c[2] + dist * top_p.to_radians().tan() - zg;
            let z = (c[2] + dist * alt.min(top_p).to_radians().tan() - zg).clamp(0.1, h.max(0.1));
            if h <= 0.0 {
                continue;
            }
            let sky_lit = 1.0 - street_sky_shade(z / h);
            let a = az.to_radians();
            let n_f = [-a.sin(), -a.cos(), 0.0];
            for (t, sk) in m.skies.iter().enumerate().take(nt) {
                let i = t * np + p;
                let sun_lit = if sk.sun_altitude_deg > 0.0 {
                    1.0 - street_sun_shade(z, h, n_f, sk.sun_dir)
                } else {
                    1.0
                };
                fill.ratio[i] = k
                    * (cache.parts[0][i]
                        + kg * (cache.parts[1][i] * sky_lit + cache.parts[2][i] * sun_lit));
            }
        }
    }
    w.fill = Some(fill);
    let mut swd = w.sun_win_dir.take().unwrap_or_else(|| vec![1.0; ns * nt]);
    for t in 0..nt.min(g.sun_dir.len()) {
        let (mut b, mut tw) = (0.0, 0.0);
        for &(wt, az, el) in &g.sun_win[t] {
            tw += wt;
            b += wt * sun_hidden(tp(az), el);
        }
        if tw > 0.0 {
            w.sun_win_ind[t] *= 1.0 - b / tw;
        }
        for (s, h) in g.sun_dir[t].iter().enumerate() {
            if let Some((az, el)) = h {
                swd[s * nt + t] *= 1.0 - sun_hidden(tp(*az), *el);
            }
        }
    }
    w.sun_win_dir = Some(swd);
}

/// Sectors over the azimuths the windows face, +-90 degrees: (start, count).
pub fn sectors(m: &Model) -> (f64, usize) {
    let wa = window_azimuths(m);
    let a0 = wa[0];
    let offs: Vec<f64> = wa.iter().map(|a| wrap_deg(a - a0)).collect();
    let lo = offs.iter().copied().fold(f64::INFINITY, f64::min) - 90.0;
    let hi = offs.iter().copied().fold(f64::NEG_INFINITY, f64::max) + 90.0;
    let start = ((a0 + lo) / STEP).floor() * STEP;
    let width = (a0 + hi - start).min(360.0);
    (start.rem_euclid(360.0), (width / STEP).ceil() as usize)
}

/// One profile fit: the weights of the other effects, the distance, sectors and smoothness.
struct Problem<'a> {
    f: &'a Fitter<'a>,
    w0: &'a Weights,
    distance: f64,
    /// The facade's reflectance (held while the sectors move; see [`Problem::best_rho`]).
    rho: f64,
    start: f64,
    lambda: f64,
    /// `D2^T D2`.
    pen: DMatrix<f64>,
}

impl Problem<'_> {
    fn effect(&self, alts: &[f64]) -> Effect {
        Effect::Skyline {
            distance: self.distance,
            start: self.start,
            step: STEP,
            alts: alts.to_vec(),
            sd: Vec::new(),
            edf: alts.len() as f64 + 2.0,
            reflectance: self.rho,
        }
    }

    /// The facade reflectance minimising `-2 ln L` for the sectors `alts` (golden-section
    /// search over [`RHO_MIN`, `RHO_MAX`]; the likelihood is smooth and one-humped in it: the
    /// facade's light is linear in the reflectance).
    fn best_rho(&mut self, alts: &[f64]) {
        let mut at = |rho: f64| {
            self.rho = rho;
            self.objective(alts).1
        };
        self.rho = golden(&mut at, RHO_MIN, RHO_MAX, 24).0;
    }

    fn sim(&self, alts: &[f64]) -> Vec<f64> {
        let mut w = self.w0.clone();
        self.f.m.add_effect(&self.effect(alts), &mut w);
        self.f.finish(&self.f.m.parts(&w), &w)
    }

    fn penalty(&self, alts: &[f64]) -> f64 {
        let a = DVector::from_column_slice(alts);
        self.lambda * a.dot(&(&self.pen * &a))
    }

    fn objective(&self, alts: &[f64]) -> (f64, f64) {
        let m2ll = self.f.score_sim(&self.sim(alts)).m2ll;
        (m2ll + self.penalty(alts), m2ll)
    }

    /// `A = J^T W J` and `b = J^T W r` at `alts` (finite differences of 1 degree).
    fn normal(&self, alts: &[f64]) -> (DMatrix<f64>, DVector<f64>) {
        let k = alts.len();
        let f = self.f;
        let sim0 = self.sim(alts);
        let sc = f.score_sim(&sim0);
        let sn2 = sc.sigma_reading.powi(2).max(1e-6);
        let sc2 = f.sigma_sensor * f.sigma_sensor;
        let used: Vec<usize> = (0..sim0.len())
            .filter(|&i| f.meas[i] >= MIN_MEASURED)
            .collect();
        let ln = |y: f64| y.max(0.01 * MIN_MEASURED).ln();
        let r: Vec<f64> = used.iter().map(|&i| ln(sim0[i]) - f.meas[i].ln()).collect();
        let mut jac = DMatrix::<f64>::zeros(used.len(), k);
        for j in 0..k {
            let h = if alts[j] + 1.0 <= MAX_ALT { 1.0 } else { -1.0 };
            let mut a = alts.to_vec();
            a[j] += h;
            let s1 = self.sim(&a);
            for (row, &i) in used.iter().enumerate() {
                jac[(row, j)] = (ln(s1[i]) - ln(sim0[i])) / h;
            }
        }
        let ns = f.m.nsens();
        let mut cnt = vec![0.0; ns];
        let mut sr = vec![0.0; ns];
        let mut sj = DMatrix::<f64>::zeros(ns, k);
        for (row, &i) in used.iter().enumerate() {
            let s = f.sensor[i];
            cnt[s] += 1.0;
            sr[s] += r[row];
            for j in 0..k {
                sj[(s, j)] += jac[(row, j)];
            }
        }
        let mut a = jac.transpose() * &jac;
        let mut b = jac.transpose() * DVector::from_vec(r);
        for s in 0..ns {
            if cnt[s] == 0.0 {
                continue;
            }
            let g = sc2 / (sn2 + cnt[s] * sc2);
            let row = sj.row(s).transpose();
            a -= g * &row * row.transpose();
            b -= g * sr[s] * &row;
        }
        (a / sn2, b / sn2)
    }

    /// Levenberg-Marquardt on `Q` from `alts`, at most `iters` Jacobians.
    fn solve(&self, alts: &mut [f64], iters: usize) {
        let k = alts.len();
        let (mut q, _) = self.objective(alts);
        let mut mu = 1e-2;
        for _ in 0..iters {
            let (a, b) = self.normal(alts);
            let x = DVector::from_column_slice(alts);
            let grad = &b + self.lambda * (&self.pen * &x);
            let mut improved = false;
            while mu < 1e6 {
                let mut h = &a + self.lambda * &self.pen;
                for i in 0..k {
                    h[(i, i)] += mu * (a[(i, i)] + 1e-6);
                }
                let Some(ch) = h.cholesky() else {
                    mu *= 4.0;
                    continue;
                };
                let d = ch.solve(&(-&grad));
                let trial: Vec<f64> = (0..k)
                    .map(|i| (alts[i] + d[i]).clamp(0.0, MAX_ALT))
                    .collect();
                let (qt, _) = self.objective(&trial);
                if qt < q - 1e-6 {
                    let gain = q - qt;
                    alts.copy_from_slice(&trial);
                    q = qt;
                    mu = (mu / 3.0).max(1e-6);
                    improved = gain > 0.01;
                    break;
                }
                mu *= 4.0;
            }
            if !improved {
                break;
            }
        }
        // Suns switch on and off within half a degree, which a 1-degree Jacobian may
        // miss: one coordinate pass of small moves.
        for i in 0..k {
            for dv in [3.0, -3.0, 1.0, -1.0] {
                let mut trial = alts.to_vec();
                trial[i] = (trial[i] + dv).clamp(0.0, MAX_ALT);
                let (qt, _) = self.objective(&trial);
                if qt < q - 1e-6 {
                    alts.copy_from_slice(&trial);
                    q = qt;
                }
            }
        }
    }

    /// Effective parameters `tr((A + lambda P)^-1 A)` over the sectors off their bounds, and
    /// the sectors' posterior standard deviations.
    fn edf(&self, alts: &[f64]) -> (f64, Vec<f64>) {
        let k = alts.len();
        let (a, b) = self.normal(alts);
        let x = DVector::from_column_slice(alts);
        let grad = &b + self.lambda * (&self.pen * &x);
        // A sector held at 0 by the bound (the likelihood pushes it lower) is no parameter.
        let free: Vec<usize> = (0..k)
            .filter(|&i| !(alts[i] <= 1e-9 && grad[i] > 0.0) && alts[i] < MAX_ALT - 1e-9)
            .collect();
        let ridge = 1e-9 * (a.trace().abs() + 1.0);
        let mut h = &a + self.lambda * &self.pen;
        for i in 0..k {
            h[(i, i)] += ridge;
        }
        let sd = h
            .clone()
            .try_inverse()
            .map(|inv| (0..k).map(|i| inv[(i, i)].max(0.0).sqrt()).collect())
            .unwrap_or_else(|| vec![f64::NAN; k]);
        if free.is_empty() {
            return (0.0, sd);
        }
        let sub = |m: &DMatrix<f64>| {
            DMatrix::from_fn(free.len(), free.len(), |i, j| m[(free[i], free[j])])
        };
        let (af, hf) = (sub(&a), sub(&h));
        let edf = hf
            .try_inverse()
            .map(|inv| (inv * af).trace())
            .unwrap_or(free.len() as f64);
        (edf.clamp(0.0, free.len() as f64), sd)
    }
}

/// `D2^T D2` for `k` sectors (second differences of their altitudes).
fn second_differences(k: usize) -> DMatrix<f64> {
    let mut d = DMatrix::<f64>::zeros(k.saturating_sub(2), k);
    for i in 0..k.saturating_sub(2) {
        d[(i, i)] = 1.0;
        d[(i, i + 1)] = -2.0;
        d[(i, i + 2)] = 1.0;
    }
    d.transpose() * d
}

/// The profile given the other effects, started from the flat-topped `sector`
/// ([`Effect::Obstruction`]); see the module documentation.
pub fn fit(f: &Fitter, base: &[Effect], sector: &Effect) -> Option<Effect> {
    let (start, k) = sectors(f.m);
    let init: Vec<f64> = (0..k)
        .map(|i| {
            let az = start + STEP * (i as f64 + 0.5);
            match *sector {
                Effect::Obstruction {
                    azimuth,
                    half_width,
                    altitude,
                } if wrap_deg(az - azimuth).abs() <= half_width => altitude,
                _ => 0.0,
            }
        })
        .collect();
    fit_from(f, base, init)
}

/// [`fit`] from the sector altitudes `init` (one per sector of [`sectors`]).
fn fit_from(f: &Fitter, base: &[Effect], init: Vec<f64>) -> Option<Effect> {
    let base = without(base, "obstruction");
    let w0 = f.m.weights(&base);
    let (start, k) = sectors(f.m);
    let pen = second_differences(k);
    let n = f.score(&base).n.max(1) as f64;
    let problem = |distance: f64, lambda: f64, rho: f64| Problem {
        f,
        w0: &w0,
        distance,
        rho,
        start,
        lambda,
        pen: pen.clone(),
    };
    // The distance: a short fit at a weak smoothness from the start at each, the facade's
    // reflectance searched before and after.
    let mut best_d: Option<(f64, f64, Vec<f64>, f64)> = None;
    let ds = f
        .skyline_distance
        .map_or_else(|| distances(f.m), |d| vec![d]);
    for d in ds {
        let mut p = problem(d, SCREEN_LAMBDA, RHO_START);
        let mut a = init.clone();
        p.best_rho(&a);
        p.solve(&mut a, 4);
        p.best_rho(&a);
        let (q, _) = p.objective(&a);
        if best_d.as_ref().is_none_or(|b| q < b.0) {
            best_d = Some((q, d, a, p.rho));
        }
    }
    let (_, distance, mut alts, mut rho) = best_d?;
    // The smoothness: by BIC with the effective parameters, smooth to rough, each fit
    // started from the previous one (the reflectance re-searched after each).
    // (BIC, sector altitudes, their standard deviations, edf, reflectance).
    type Best = (f64, Vec<f64>, Vec<f64>, f64, f64);
    let mut best: Option<Best> = None;
    for lambda in LAMBDAS {
        let mut p = problem(distance, lambda, rho);
        p.solve(&mut alts, 8);
        p.best_rho(&alts);
        rho = p.rho;
        let (_, m2ll) = p.objective(&alts);
        let (edf, sd) = p.edf(&alts);
        // The distance and the reflectance besides the sectors.
        let bic = m2ll + (edf + 2.0) * n.ln();
        if best.as_ref().is_none_or(|b| bic < b.0) {
            best = Some((bic, alts.clone(), sd, edf, rho));
        }
    }
    let (_, alts, sd, edf, reflectance) = best?;
    Some(Effect::Skyline {
        distance,
        start,
        step: STEP,
        alts,
        sd,
        edf: edf + 2.0,
        reflectance,
    })
}

/// The obstruction family's fit: the best flat-topped sector, then the profile from it;
/// whichever has the lower BIC (the sector's 3 parameters against the profile's effective
/// ones plus its distance).
pub fn fit_obstruction(f: &Fitter, base: &[Effect]) -> Option<Effect> {
    let sector = super::obstruction::fit(f, base)?;
    let Some(profile) = fit(f, base, &sector) else {
        return Some(sector);
    };
    let others = without(base, "obstruction");
    let bic = |e: &Effect| {
        let mut all = others.clone();
        all.push(e.clone());
        f.bic(&all)
    };
    Some(if bic(&profile) < bic(&sector) {
        profile
    } else {
        sector
    })
}

/// `skyline:DISTANCE,START,STEP,ALT,ALT,...` (see [`Effect::spec`]).
pub fn spec(distance: f64, start: f64, step: f64, alts: &[f64], reflectance: f64) -> String {
    format!(
        "skyline:{distance:.1},{start:.1},{step:.1},{}/{reflectance:.2}",
        alts.iter()
            .map(|a| format!("{a:.1}"))
            .collect::<Vec<_>>()
            .join(",")
    )
}

/// Parse the numbers of a `skyline:` spec.
pub fn parse(v: &[f64], reflectance: Option<f64>) -> std::result::Result<Effect, String> {
    let reflectance = reflectance.unwrap_or(crate::apply::OBSTRUCTION_REFLECTANCE);
    if !(0.0..=RHO_MAX).contains(&reflectance) {
        return Err(format!(
            "the facade's REFLECTANCE must be in [0, {RHO_MAX}]"
        ));
    }
    let [distance, start, step, alts @ ..] = v else {
        return Err("expected DISTANCE,START,STEP,ALT,ALT,...".into());
    };
    if !(*distance > 0.0 && distance.is_finite()) {
        return Err("distance must be > 0 m".into());
    }
    if !(*step > 0.0 && *step <= 90.0) {
        return Err("STEP must be in (0, 90] degrees".into());
    }
    if alts.is_empty() || alts.len() as f64 * step > 360.0 + 1e-9 {
        return Err("one altitude per sector, the sectors spanning at most 360 degrees".into());
    }
    if alts.iter().any(|a| !(0.0..90.0).contains(a)) {
        return Err("altitudes must be in [0, 90) degrees".into());
    }
    Ok(Effect::Skyline {
        distance: *distance,
        start: start.rem_euclid(360.0),
        step: *step,
        alts: alts.to_vec(),
        sd: Vec::new(),
        edf: alts.len() as f64 + 2.0,
        reflectance,
    })
}

/// The sectors worth naming: from the first to the last one above 0.5 degrees.
pub fn shown(alts: &[f64]) -> std::ops::Range<usize> {
    let first = alts.iter().position(|a| *a > 0.5).unwrap_or(0);
    let last = alts.iter().rposition(|a| *a > 0.5).map_or(0, |i| i + 1);
    first..last.max(first)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profile_is_flat_per_sector_and_zero_outside() {
        let alts = [0.0, 20.0, 30.0];
        assert_eq!(top(350.0, 10.0, &alts, 355.0), 0.0);
        assert_eq!(top(350.0, 10.0, &alts, 5.0), 20.0);
        assert_eq!(top(350.0, 10.0, &alts, 19.9), 30.0);
        assert_eq!(top(350.0, 10.0, &alts, 20.1), 0.0);
        assert_eq!(top(350.0, 10.0, &alts, 340.0), 0.0);
    }

    #[test]
    fn cylinder_hit_has_the_parallax_of_the_sensor() {
        // From the centre: the direction's own azimuth and altitude.
        let d = [0.0, -(30f64.to_radians().cos()), 30f64.to_radians().sin()];
        let (az, el) = hit([0.0; 3], 20.0, [0.0; 3], d).unwrap();
        assert!((az - 180.0).abs() < 1e-9 && (el - 30.0).abs() < 1e-9);
        // From 5 m behind the centre (north, the ray going south) it travels 25 m
        // horizontally to the cylinder and rises 25 tan 30 there.
        let (az, el) = hit([0.0; 3], 20.0, [0.0, 5.0, 0.0], d).unwrap();
        let want = (25.0 * 30f64.to_radians().tan() / 20.0).atan().to_degrees();
        assert!(
            (az - 180.0).abs() < 1e-9 && (el - want).abs() < 1e-9,
            "{el} {want}"
        );
        // A sideways offset moves the hit's azimuth (the building's end seen elsewhere).
        let (az, _) = hit([0.0; 3], 20.0, [3.0, 0.0, 0.0], d).unwrap();
        let want = 180.0 - (3.0f64 / 20.0).asin().to_degrees();
        assert!((az - want).abs() < 1e-9, "{az} {want}");
    }

    #[test]
    fn spec_round_trips() {
        let e = parse(&[35.0, 90.0, 10.0, 0.0, 12.5, 30.0, 0.0], Some(0.25)).unwrap();
        let Effect::Skyline {
            distance,
            start,
            step,
            alts,
            reflectance,
            ..
        } = &e
        else {
            panic!()
        };
        assert_eq!(
            spec(*distance, *start, *step, alts, *reflectance),
            "skyline:35.0,90.0,10.0,0.0,12.5,30.0,0.0/0.25"
        );
        // Without a reflectance: apply's default.
        let Ok(Effect::Skyline { reflectance, .. }) = parse(&[35.0, 90.0, 10.0, 5.0], None) else {
            panic!()
        };
        assert_eq!(reflectance, crate::apply::OBSTRUCTION_REFLECTANCE);
        assert!(parse(&[35.0, 90.0, 10.0, 5.0], Some(1.5)).is_err());
        assert!(parse(&[35.0, 90.0, 10.0, 95.0, 0.0], None).is_err());
        assert!(parse(&[0.0, 90.0, 10.0, 5.0, 0.0], None).is_err());
        assert!(parse(&[35.0, 90.0, 10.0], None).is_err());
        assert!(parse(&[35.0, 90.0, 90.0, 1.0, 1.0, 1.0, 1.0, 1.0], None).is_err());
    }

    /// Where a ray meets a planar convex polygon (vertices in order): distance along it.
    fn ray_polygon(org: [f64; 3], d: [f64; 3], v: &[[f64; 3]]) -> Option<f64> {
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let n = cross(sub(v[1], v[0]), sub(v[2], v[0]));
        let den = dot(n, d);
        if den.abs() < 1e-12 {
            return None;
        }
        let t = dot(n, sub(v[0], org)) / den;
        if t <= 1e-9 {
            return None;
        }
        let p = [org[0] + t * d[0], org[1] + t * d[1], org[2] + t * d[2]];
        let sides: Vec<f64> = (0..v.len())
            .map(|i| dot(n, cross(sub(v[(i + 1) % v.len()], v[i]), sub(p, v[i]))))
            .collect();
        (sides.iter().all(|x| *x >= 0.0) || sides.iter().all(|x| *x <= 0.0)).then_some(t)
    }

    /// The committed studio case (`radiance-fixtures/calib-cases/skyline-studio`: a south
    /// window, sensors 1-6 m deep), its room, and the facets `rcalib apply` writes for the
    /// profile.
    fn studio_facets(
        distance: f64,
        start: f64,
        step: f64,
        alts: &[f64],
    ) -> (crate::cases::Case, crate::room::Room, Vec<Vec<[f64; 3]>>) {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../radiance-fixtures/calib-cases/skyline-studio");
        let case = crate::cases::Case::from_dir(&dir).unwrap();
        let scene = crate::cases::scene_of(&case.model_text).unwrap();
        let room = crate::cases::room_of(&scene, &case.sensors);
        let e = parse(&[&[distance, start, step][..], alts].concat(), None).unwrap();
        let text = crate::apply::apply(&scene, &room, &case.sensors, &[e], "test").unwrap();
        let applied = crate::cases::scene_of(&text).unwrap();
        let facets = applied
            .objects
            .iter()
            .filter(|o| o.id.starts_with("rcalib_skyline_"))
            .filter_map(|o| match &o.kind {
                crate::scene::Primitive::Polygon { vertices } => Some(vertices.clone()),
                _ => None,
            })
            .collect();
        (case, room, facets)
    }

    /// What the profile hides, as the model computes it from each sensor ([`hit`] on the
    /// cylinder, the sector's altitude seen from the windows' centre), against rays traced
    /// through the facets `rcalib apply` writes for it, on the committed studio case
    /// (`radiance-fixtures/calib-cases/skyline-studio`: a south window, sensors 1-6 m
    /// deep): a building 20 m away with ends, seen with parallax. The two agree on at least
    /// 99 % of the rays (the rest graze an edge: chords against the cylinder), and the
    /// deep sensors see the building's end at other azimuths than the window's sensors.
    #[test]
    fn applied_facets_hide_what_the_profile_hides_from_every_sensor() {
        let (distance, start, step) = (20.0, 130.0, 5.0);
        let alts = vec![
            0.0, 22.0, 30.0, 34.0, 35.0, 35.0, 34.0, 31.0, 28.0, 12.0, 0.0, 0.0,
        ];
        let (case, room, facets) = studio_facets(distance, start, step, &alts);
        assert_eq!(facets.len(), alts.iter().filter(|a| **a > 0.0).count());
        let (c, _) = crate::apply::window_centre(&room, &case.sensors);
        let (mut agree, mut total) = (0usize, 0usize);
        let mut hidden_by_sensor = Vec::new();
        for s in &case.sensors {
            let org = s.ray.org;
            let mut hidden = Vec::new();
            for i in 0..120 {
                let az = 110.0 + 100.0 * (i as f64 + 0.5) / 120.0;
                for j in 0..50 {
                    let el = 50.0 * (j as f64 + 0.5) / 50.0;
                    let (a, h) = (az.to_radians(), el.to_radians());
                    let d = [h.cos() * a.sin(), h.cos() * a.cos(), h.sin()];
                    let model = hit(c, distance, org, d).is_some_and(|(haz, hel)| {
                        let t = top(start, step, &alts, haz);
                        t > 0.0 && t > hel
                    });
                    let traced = facets.iter().any(|f| ray_polygon(org, d, f).is_some());
                    total += 1;
                    agree += usize::from(model == traced);
                    hidden.push(model);
                }
            }
            hidden_by_sensor.push(hidden);
        }
        let share = agree as f64 / total as f64;
        assert!(
            share >= 0.99,
            "model and applied facets agree on {share:.4} of the rays"
        );
        // Parallax: some sensor pair differs on at least 2 % of the directions.
        let most = hidden_by_sensor
            .iter()
            .flat_map(|a| {
                hidden_by_sensor
                    .iter()
                    .map(move |b| a.iter().zip(b).filter(|(x, y)| x != y).count())
            })
            .max()
            .unwrap_or(0);
        assert!(
            most as f64 >= 0.02 * hidden_by_sensor[0].len() as f64,
            "no parallax between the sensors ({most} directions)"
        );
    }

    /// The ground in front of the room as the model sees it ([`ground_points`], [`hit`]
    /// from each ground point), against rays traced through the facets `rcalib apply`
    /// writes, on the committed studio case with a building 14 m away: from the points
    /// before the facets, the directions the profile hides agree with the facets on at
    /// least 99 % of the rays, and much more of the sky is hidden from the ground than
    /// from the windows' centre (the building stands higher seen from below); the points
    /// the model counts as behind the facets are those the windows' centroids no longer
    /// see.
    #[test]
    fn the_ground_before_the_facets_sees_what_they_hide() {
        let (distance, start, step) = (14.0, 130.0, 5.0);
        let alts = vec![
            0.0, 30.0, 35.0, 37.0, 38.0, 39.0, 39.0, 38.0, 37.0, 35.0, 13.0, 0.0,
        ];
        let (case, room, facets) = studio_facets(distance, start, step, &alts);
        let (c, _) = crate::apply::window_centre(&room, &case.sensors);
        let (cells, _) = ground_cells(&room);
        let (total, behind, points) = ground_points(&cells, c, distance);
        assert!(total > 0.0 && !points.is_empty() && !behind.is_empty());
        let tp = |az: f64| top(start, step, &alts, az);
        let (mut agree, mut rays) = (0usize, 0usize);
        let (mut from_ground, mut from_centre) = (0usize, 0usize);
        for &(_, _, q) in points.iter().step_by(3) {
            for i in 0..60 {
                let az = 110.0 + 100.0 * (i as f64 + 0.5) / 60.0;
                for j in 0..30 {
                    let el = 60.0 * (j as f64 + 0.5) / 30.0;
                    let (a, h) = (az.to_radians(), el.to_radians());
                    let d = [h.cos() * a.sin(), h.cos() * a.cos(), h.sin()];
                    let model = hit(c, distance, q, d).is_some_and(|(haz, hel)| {
                        let t = tp(haz);
                        t > 0.0 && t > hel
                    });
                    let traced = facets.iter().any(|f| ray_polygon(q, d, f).is_some());
                    rays += 1;
                    agree += usize::from(model == traced);
                    from_ground += usize::from(model);
                    from_centre += usize::from(
                        hit(c, distance, c, d)
                            .is_some_and(|(haz, hel)| tp(haz) > 0.0 && tp(haz) > hel),
                    );
                }
            }
        }
        let share = agree as f64 / rays as f64;
        assert!(
            share >= 0.99,
            "ground rays: model and facets agree on {share:.4}"
        );
        assert!(
            from_ground as f64 > 1.1 * from_centre as f64,
            "hidden from the ground {from_ground}, from the centre {from_centre}"
        );
        // Behind the facets: hidden from every window's centroid exactly where the model
        // says (a sector with a facet at the point's azimuth).
        let w = &room.windows[0];
        let towards = |q: [f64; 3]| {
            let v = [
                q[0] - w.centroid[0],
                q[1] - w.centroid[1],
                q[2] - w.centroid[2],
            ];
            let n = dot(v, v).sqrt();
            [v[0] / n, v[1] / n, v[2] / n]
        };
        let mut checked = 0;
        for &(_, _, az) in &behind {
            let a = az.to_radians();
            // The point on the ground 25 m from the centre at that azimuth.
            let q = [c[0] + 25.0 * a.sin(), c[1] + 25.0 * a.cos(), 0.0];
            let d = towards(q);
            if !room.meets_ground(w.centroid, d) {
                continue;
            }
            let traced = facets
                .iter()
                .any(|f| ray_polygon(w.centroid, d, f).is_some());
            assert_eq!(traced, tp(az) > 0.0, "behind the facets at azimuth {az:.1}");
            checked += 1;
        }
        assert!(checked > 10, "{checked} points behind checked");
    }

    /// Each sensor's weights of the ground cells on the committed studio case: they keep
    /// the windows' total (a ground no profile hides stays unhidden at every sensor);
    /// without records every sensor weighs the ground as the windows do; lit after one
    /// bounce, the deepest work-plane sensor leans on shallower (farther) ground than the
    /// one nearest the window, whose light lands on the ceiling near the window.
    #[test]
    fn a_deep_sensor_leans_on_the_far_ground() {
        let (case, room, _) = studio_facets(14.0, 130.0, 5.0, &[10.0; 12]);
        let (cells, ng) = ground_cells(&room);
        let total: f64 = cells.iter().map(|c| c.wt).sum();
        let mut gw = vec![0.0; ng];
        for c in &cells {
            gw[c.group] += c.wt;
        }
        let ns = case.sensors.len();
        let flat = GroundWeights::new(&room, &case.sensors, None, &cells, ng);
        for s in 0..ns {
            for (g, wg) in gw.iter().enumerate() {
                if *wg > 0.0 {
                    assert!((flat.sky[s * ng + g] - 1.0).abs() < 1e-12);
                }
            }
        }
        let once = vec![[0.0, 1.0, 0.0]; ns];
        let w = GroundWeights::new(&room, &case.sensors, Some([once.clone(), once]), &cells, ng);
        let nsec = (360.0 / GROUND_GROUP_AZ) as usize;
        let nb = GROUND_BANDS.len() - 1;
        let mean_band = |s: usize| {
            let (mut a, mut b) = (0.0, 0.0);
            for (g, wg) in gw.iter().enumerate() {
                let x = w.sky[s * ng + g] * wg;
                a += x * ((g / nsec) % nb) as f64;
                b += x;
            }
            assert!(
                (b - total).abs() < 1e-9 * total,
                "sensor {s}: {b} vs {total}"
            );
            a / b
        };
        // Work-plane sensors (facing up), nearest and farthest from the window.
        let depth = |s: usize| room.depth(case.sensors[s].ray.org);
        let up: Vec<usize> = (0..ns)
            .filter(|&s| case.sensors[s].ray.dir[2] > 0.9)
            .collect();
        let near = *up
            .iter()
            .min_by(|a, b| depth(**a).total_cmp(&depth(**b)))
            .unwrap();
        let far = *up
            .iter()
            .max_by(|a, b| depth(**a).total_cmp(&depth(**b)))
            .unwrap();
        let (bn, bf) = (mean_band(near), mean_band(far));
        assert!(
            bf + 1.0 < bn,
            "mean depression band: near sensor {bn:.2}, deep sensor {bf:.2}"
        );
    }

    /// The street before a long wall: its foot sees half the sky gone (the view factor of
    /// a long wall from the ground at its foot, (1 - cos 90) / 2), its top less, by the
    /// integral checked here against a direct sum over ground strips; the wall's own
    /// shadow covers none of its view with the sun in front, and from a point at height z
    /// with the shadow reaching x_s the share below the depression atan(z / x_s).
    #[test]
    fn a_wall_shades_the_street_it_looks_at() {
        assert!((street_sky_shade(0.0) - 0.5).abs() < 0.01);
        let mut last = 0.5;
        for i in 1..=10 {
            let u = i as f64 / 10.0;
            let v = street_sky_shade(u);
            assert!(v < last && v > 0.0, "u {u}: {v}");
            last = v;
        }
        // Direct sum over ground strips at distance x (view weight of a strip from a
        // vertical point at height z: (1/2) (sin of the angle to its far edge - ...), 2-D).
        let (z, h) = (1.0, 1.0);
        let (mut num, mut den) = (0.0, 0.0);
        let n = 200_000;
        for k in 0..n {
            let (x0, x1) = (k as f64 * 0.001, (k + 1) as f64 * 0.001);
            // Angle from the wall's normal (horizontal) to the ground point, 2-D.
            let f = 0.5 * ((z / x0.max(1e-12)).atan().sin() - (z / x1).atan().sin());
            let x = 0.5 * (x0 + x1);
            let beta = (h / x).atan();
            num += f * 0.5 * (1.0 - beta.cos());
            den += f;
        }
        // The strip weights above are the 2-D (cosine) view; the wall's view of the ground
        // over every azimuth weighs depression by cos^2: compare both within 0.05.
        assert!(
            (num / den - street_sky_shade(1.0)).abs() < 0.05,
            "{} {}",
            num / den,
            street_sky_shade(1.0)
        );
        let n_f = [0.0, 1.0, 0.0];
        let sun_front = [0.0, 0.8, 0.6];
        assert_eq!(street_sun_shade(2.0, 10.0, n_f, sun_front), 0.0);
        // Sun straight behind at 45 degrees: the shadow reaches x_s = h.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let behind = [0.0, -s, s];
        let d = (2.0f64 / 10.0).atan();
        let want = 1.0 - (d + d.sin() * d.cos()) * std::f64::consts::FRAC_2_PI;
        assert!((street_sun_shade(2.0, 10.0, n_f, behind) - want).abs() < 1e-9);
        assert!(
            street_sun_shade(2.0, 10.0, n_f, behind) > street_sun_shade(8.0, 10.0, n_f, behind)
        );
    }
}
