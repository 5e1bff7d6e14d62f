//! # Local obstruction: furniture, a partition, a shelf near some sensors
//!
//! Furniture between a few sensors and a window takes away the sky and the sun those
//! sensors see through it, and hides part of the room from them. It is fitted as what it
//! physically is: a vertical opaque panel ([`Slab`]) standing on the floor along a plan
//! segment, with a thickness and a top height, either parallel to a window wall (a shelf,
//! a screen) or across the room (a partition running away from the facade). Per sensor:
//!
//! - the direct view: every sky cell the sensor sees through a window
//!   ([`super::obstruction::Horizon`], 0.75-degree cells) and the sun are blocked when the
//!   ray from the sensor crosses the panel's footprint below its top (smoothed over 1 cm),
//!   so a 2 m shelf can hide a view window from a sensor behind it and leave the
//!   clerestory above visible;
//! - the inter-reflected light: the panel hides the projected solid angle `F` of the
//!   sensor's hemisphere it fills (Lambert's contour integral for a polygon, clipped to the
//!   sensor's plane) and sends back its own face's light, so the sensor keeps
//!   `1 - F (W - κ)` of it, with `W` the luminance of what the panel hides and `κ` that of
//!   its face, both over the mean luminance the sensor sees. In a side-lit room the
//!   surfaces towards the windows (the ceiling and walls near them) are the bright ones: a
//!   sensor behind a panel loses that bright part ([`HIDDEN_BACK`]) and sees the face in
//!   the panel's own shadow instead ([`KAPPA_BACK`]); a sensor in front of it loses the
//!   dimmer back of the room and sees a face the windows light. These are first-order
//!   estimates: the panel's shadow on the floor and what it absorbs for the room as a
//!   whole are left to the refinement against re-simulation
//!   ([`crate::explain::refine`]), which also corrects the estimates.
//!
//! Signature: deficits at a few neighbouring sensors that change with the sun's position
//! and the sky (a fixed set of directions is blocked), unlike a sensor fault's constant
//! ratio. The `local-obstruction:FRACTION,ID+ID` spec of earlier versions (a fraction of
//! the window's elevation span hidden in front of a sensor group) still reads and applies:
//! it becomes the panel [`crate::apply::local_panel`] builds.

use super::{Effect, golden, smooth_step};
use crate::apply::local_panel;
use crate::fit::{Fitter, without};
use crate::model::{Model, Weights};
use crate::room::{Window, dot};

/// Thickness of a fitted panel (m): a partition or a shelf's back; the blocking hardly
/// depends on it.
pub const THICK: f64 = 0.1;
/// Reflectance of the panel `rcalib apply` writes (light furniture).
pub const REFLECTANCE: f64 = 0.5;
/// Luminance of a panel face turned away from the windows over the mean luminance a
/// sensor behind it sees: the face is lit by the back of the room only and reflects
/// [`REFLECTANCE`] of that.
pub const KAPPA_BACK: f64 = 0.25;
/// Luminance of the window side of a room, which a panel hides from a sensor behind it,
/// over the mean luminance the sensor sees (the ceiling and walls near the windows are the
/// brightest surfaces of a side-lit room; the back of the room, `1 / HIDDEN_BACK` of the
/// mean, is what a panel hides from a sensor in front of it).
pub const HIDDEN_BACK: f64 = 2.0;

/// Tallest a fitted panel stands above the floor (m): free-standing furniture (shelves,
/// wardrobes, office partitions) stays below about 2.2 m; anything taller is a wall, which
/// the model would have. Without the cap, the fit answered the room-wide shadow of a 2 m
/// shelf, which the coefficient model only partly sees, with a panel up to the ceiling.
pub const MAX_TOP: f64 = 2.2;
/// Least plan distance between a fitted panel's faces and any sensor (m): a sensor inside
/// the box `rcalib apply` writes reads nothing.
pub const CLEARANCE: f64 = 0.1;

/// Group radii tried (metres, horizontal).
pub const RADII: [f64; 4] = [0.0, 0.8, 1.3, 2.0];

/// A vertical box standing on the floor: plan segment `a`-`b` (its centre line), `thick`
/// across, from `floor` up to `top` (heights in the model's coordinates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slab {
    pub a: [f64; 2],
    pub b: [f64; 2],
    pub thick: f64,
    pub floor: f64,
    pub top: f64,
}

impl Slab {
    /// Plan distance from `p` to the box's footprint (0 inside it).
    pub fn plan_distance(&self, p: [f64; 3]) -> f64 {
        let (t, n, len) = self.frame();
        let rel = [p[0] - self.a[0], p[1] - self.a[1]];
        let s = rel[0] * t[0] + rel[1] * t[1];
        let q = rel[0] * n[0] + rel[1] * n[1];
        let ds = (-s).max(s - len).max(0.0);
        let dq = (q.abs() - 0.5 * self.thick).max(0.0);
        ds.hypot(dq)
    }

    /// Unit vector along the segment, unit normal, length.
    fn frame(&self) -> ([f64; 2], [f64; 2], f64) {
        let (dx, dy) = (self.b[0] - self.a[0], self.b[1] - self.a[1]);
        let len = (dx * dx + dy * dy).sqrt().max(1e-9);
        let t = [dx / len, dy / len];
        ([t[0], t[1]], [-t[1], t[0]], len)
    }

    /// The lowest height at which the ray from `org` along `dir` is inside the footprint
    /// (the box reaches the floor, so the ray is blocked when this is below `top`); `None`
    /// when it misses the footprint.
    pub fn lowest_crossing(&self, org: [f64; 3], dir: [f64; 3]) -> Option<f64> {
        let (t, n, len) = self.frame();
        let rel = [org[0] - self.a[0], org[1] - self.a[1]];
        let (s0, q0) = (rel[0] * t[0] + rel[1] * t[1], rel[0] * n[0] + rel[1] * n[1]);
        let (ks, kq) = (dir[0] * t[0] + dir[1] * t[1], dir[0] * n[0] + dir[1] * n[1]);
        let slab = |x0: f64, rate: f64, lo: f64, hi: f64| -> Option<(f64, f64)> {
            if rate.abs() < 1e-12 {
                return (lo..=hi).contains(&x0).then_some((0.0, f64::INFINITY));
            }
            let (t1, t2) = ((lo - x0) / rate, (hi - x0) / rate);
            Some((t1.min(t2), t1.max(t2)))
        };
        let h = 0.5 * self.thick;
        let (a0, a1) = slab(s0, ks, 0.0, len)?;
        let (b0, b1) = slab(q0, kq, -h, h)?;
        let (t0, t1) = (a0.max(b0).max(0.0), a1.min(b1));
        if t1 < t0 {
            return None;
        }
        let z = |s: f64| org[2] + dir[2] * s;
        Some(if dir[2] >= 0.0 { z(t0) } else { z(t1) })
    }

    /// The face of the box turned towards `p` (its plan normal points at `p`'s side).
    fn face_towards(&self, p: [f64; 3]) -> (Vec<[f64; 3]>, [f64; 2]) {
        let (_, n, _) = self.frame();
        let q = (p[0] - self.a[0]) * n[0] + (p[1] - self.a[1]) * n[1];
        let sgn = if q >= 0.0 { 1.0 } else { -1.0 };
        let off = [n[0] * sgn * 0.5 * self.thick, n[1] * sgn * 0.5 * self.thick];
        let v = |c: [f64; 2], z: f64| [c[0] + off[0], c[1] + off[1], z];
        (
            vec![
                v(self.a, self.floor),
                v(self.b, self.floor),
                v(self.b, self.top),
                v(self.a, self.top),
            ],
            [n[0] * sgn, n[1] * sgn],
        )
    }

    /// Share of the cosine-weighted hemisphere around `nrm` at `p` that the panel's face
    /// towards `p` fills (the view factor from a small surface to the polygon): Lambert's
    /// contour integral `F = |sum_i g_i (r_i x r_i+1) . n / |r_i x r_i+1|| / 2 pi` with `g_i`
    /// the angle between the edge's end points as seen from `p` (Modest, *Radiative Heat
    /// Transfer*, 2013, eq. 4.42), on the polygon clipped to the half space the sensor faces.
    pub fn view_factor(&self, p: [f64; 3], nrm: [f64; 3]) -> f64 {
        let (face, _) = self.face_towards(p);
        let h = |v: [f64; 3]| dot([v[0] - p[0], v[1] - p[1], v[2] - p[2]], nrm) - 1e-6;
        // Sutherland-Hodgman against the sensor's plane.
        let mut poly = Vec::new();
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            let (ha, hb) = (h(a), h(b));
            if ha >= 0.0 {
                poly.push(a);
            }
            if (ha >= 0.0) != (hb >= 0.0) {
                let s = ha / (ha - hb);
                poly.push([
                    a[0] + s * (b[0] - a[0]),
                    a[1] + s * (b[1] - a[1]),
                    a[2] + s * (b[2] - a[2]),
                ]);
            }
        }
        if poly.len() < 3 {
            return 0.0;
        }
        let mut sum = 0.0;
        for k in 0..poly.len() {
            let r1 = sub3(poly[k], p);
            let r2 = sub3(poly[(k + 1) % poly.len()], p);
            let c = cross(r1, r2);
            let cn = dot(c, c).sqrt();
            if cn < 1e-12 {
                continue;
            }
            let g = (dot(r1, r2) / (dot(r1, r1).sqrt() * dot(r2, r2).sqrt()))
                .clamp(-1.0, 1.0)
                .acos();
            sum += g * dot(c, nrm) / cn;
        }
        (sum.abs() / (2.0 * std::f64::consts::PI)).min(1.0)
    }

    /// The five faces (four sides and the top) `rcalib apply` writes, each wound so its
    /// normal points out of the box.
    pub fn faces(&self) -> Vec<Vec<[f64; 3]>> {
        let (_, n, _) = self.frame();
        let h = 0.5 * self.thick;
        let c = |p: [f64; 2], s: f64, z: f64| [p[0] + n[0] * s * h, p[1] + n[1] * s * h, z];
        let (a, b, z0, z1) = (self.a, self.b, self.floor, self.top);
        let (a0, a1, b0, b1) = (c(a, -1.0, z0), c(a, 1.0, z0), c(b, -1.0, z0), c(b, 1.0, z0));
        let up = |v: [f64; 3]| [v[0], v[1], z1];
        vec![
            // The +n side, the -n side, the two ends, the top.
            vec![a1, b1, up(b1), up(a1)],
            vec![b0, a0, up(a0), up(b0)],
            vec![a0, a1, up(a1), up(a0)],
            vec![b1, b0, up(b0), up(b1)],
            vec![up(a0), up(a1), up(b1), up(b0)],
        ]
        .into_iter()
        .map(|mut f| {
            // Wind so the Newell normal points away from the box's centre.
            let ctr = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (z0 + z1)];
            let fc = f.iter().fold([0.0; 3], |s, v| {
                [s[0] + v[0] / 4.0, s[1] + v[1] / 4.0, s[2] + v[2] / 4.0]
            });
            let nn = cross(sub3(f[1], f[0]), sub3(f[2], f[1]));
            if dot(nn, sub3(fc, ctr)) < 0.0 {
                f.reverse();
            }
            f
        })
        .collect()
    }
}

fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// A point `u` along window `w`'s wall and `d` into the room, in plan.
pub fn plan_point(w: &Window, u: f64, d: f64) -> [f64; 2] {
    let cu = dot(w.centroid, w.tangent);
    [
        w.centroid[0] + w.tangent[0] * (u - cu) - w.outward[0] * d,
        w.centroid[1] + w.tangent[1] * (u - cu) - w.outward[1] * d,
    ]
}

/// The panel of a local-obstruction effect in the model's room (`None` for other effects
/// or a legacy group the room cannot place).
pub fn slab_of(e: &Effect, m: &Model) -> Option<Slab> {
    slab_in(e, &m.room, &m.sensors)
}

/// [`slab_of`] from the room and sensors (what `rcalib apply` writes).
pub fn slab_in(
    e: &Effect,
    room: &crate::room::Room,
    sensors: &[crate::formats::sensors::Sensor],
) -> Option<Slab> {
    match e {
        Effect::Furniture { a, b, top, thick } => Some(Slab {
            a: *a,
            b: *b,
            thick: *thick,
            floor: room.floor,
            top: *top,
        }),
        Effect::LocalObstruction {
            sensors: g,
            fraction,
        } => {
            let p = local_panel(room, sensors, g, *fraction).ok()?;
            let w = room.windows.get(p.window)?;
            let dm = 0.5 * (p.d.0 + p.d.1);
            Some(Slab {
                a: plan_point(w, p.u.0, dm),
                b: plan_point(w, p.u.1, dm),
                thick: p.d.1 - p.d.0,
                floor: room.floor,
                top: p.top,
            })
        }
        _ => None,
    }
}

/// Per sensor, the sky cells it sees through a window: (patch, direction, weight), from
/// [`super::obstruction::Horizon`] (built once per model, [`Model::sight`]).
#[derive(Debug, Clone)]
pub struct Sight {
    cells: Vec<Vec<(usize, [f64; 3], f64)>>,
}

impl Sight {
    pub fn new(m: &Model) -> Sight {
        let hz = m.horizon();
        let cells = (0..m.nsens())
            .map(|s| {
                (1..m.comps.npatch)
                    .flat_map(|p| {
                        hz.direct_cells(s, p)
                            .into_iter()
                            .map(move |(d, w)| (p, d, w))
                    })
                    .collect()
            })
            .collect();
        Sight { cells }
    }
}

/// Luminance of what the panel hides from a sensor at `p` and of its face there, over the
/// mean the sensor sees (`W`, `κ` of the module documentation), by how far the face turns
/// to the windows (area-weighted cosine `c`): behind the panel (`c = -1`)
/// [`HIDDEN_BACK`], [`KAPPA_BACK`]; in front of it (`c = 1`) `1 / HIDDEN_BACK`, 1; beside
/// it (`c = 0`) halfway.
fn hidden_and_face(slab: &Slab, p: [f64; 3], m: &Model) -> (f64, f64) {
    let (_, n) = slab.face_towards(p);
    let (mut num, mut den) = (0.0, 0.0);
    for w in &m.room.windows {
        // A face turned towards a window has its normal along the window's `outward`.
        num += w.area * (n[0] * w.outward[0] + n[1] * w.outward[1]);
        den += w.area;
    }
    let c = if den > 0.0 {
        (num / den).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let hidden = if c < 0.0 {
        1.0 + (HIDDEN_BACK - 1.0) * -c
    } else {
        1.0 + (1.0 / HIDDEN_BACK - 1.0) * c
    };
    (hidden, KAPPA_BACK + (1.0 - KAPPA_BACK) * 0.5 * (c + 1.0))
}

/// Multiply the direct-light weights (sky cells and sun, per sensor) by what the panel
/// leaves, and the sensors' inter-reflected light by what it leaves of their view of the
/// room (see the module documentation).
pub fn apply(e: &Effect, m: &Model, w: &mut Weights) {
    let Some(slab) = slab_of(e, m) else {
        return;
    };
    let sight = m.sight();
    let (ns, np, nt) = (m.nsens(), m.comps.npatch, m.nsteps());
    let left = |org: [f64; 3], d: [f64; 3]| match slab.lowest_crossing(org, d) {
        Some(z) => 1.0 - smooth_step(slab.top - z, 0.01),
        None => 1.0,
    };
    let mut wd = w.win_dir.take().unwrap_or_else(|| vec![1.0; ns * np]);
    let mut sd = w.sun_win_dir.take().unwrap_or_else(|| vec![1.0; ns * nt]);
    let mut num = vec![0.0; np];
    let mut den = vec![0.0; np];
    for (s, sensor) in m.sensors.iter().enumerate() {
        let org = sensor.ray.org;
        num.iter_mut().for_each(|x| *x = 0.0);
        den.iter_mut().for_each(|x| *x = 0.0);
        for &(p, d, wt) in &sight.cells[s] {
            num[p] += wt * left(org, d);
            den[p] += wt;
        }
        for p in 1..np {
            if den[p] > 0.0 {
                wd[s * np + p] *= num[p] / den[p];
            }
        }
        for (t, sk) in m.skies.iter().enumerate() {
            if sk.sun_altitude_deg > 0.0 {
                sd[s * nt + t] *= left(org, sk.sun_dir);
            }
        }
        let f = slab.view_factor(org, sensor.ray.dir);
        if f > 0.0 {
            let (hidden, face) = hidden_and_face(&slab, org, m);
            w.local_ind[s] *= (1.0 - f * (hidden - face)).max(0.05);
        }
    }
    w.win_dir = Some(wd);
    w.sun_win_dir = Some(sd);
}

/// A candidate panel in the frame of window `w`: parallel to its wall at depth `d` from
/// `u0` to `u1`, or across it at `u0` from depth `d` to `u1`.
#[derive(Debug, Clone, Copy)]
struct Frame {
    across: bool,
    d: f64,
    u0: f64,
    u1: f64,
    top: f64,
}

impl Frame {
    fn effect(&self, w: &Window) -> Effect {
        let (a, b) = if self.across {
            (
                plan_point(w, self.u0, self.d),
                plan_point(w, self.u0, self.u1),
            )
        } else {
            (
                plan_point(w, self.u0, self.d),
                plan_point(w, self.u1, self.d),
            )
        };
        Effect::Furniture {
            a,
            b,
            top: self.top,
            thick: THICK,
        }
    }
}

/// Best panel given the other effects. Candidates stand in front of a group of sensors
/// (all within a radius of one sensor, at most half of them) as seen from each window
/// wall: parallel to the wall at a few gaps in front of the group and a few widths beyond
/// it, or across the room beside it; the top height of each by golden section. The best
/// candidate's position, ends and top are then refined one at a time, twice.
pub fn fit(f: &Fitter, base: &[Effect]) -> Option<Effect> {
    let base = without(base, "local-obstruction");
    let w0 = f.m.weights(&base);
    let m = f.m;
    let ns = m.nsens();
    let eval = |w: &Window, c: &Frame| score(f, &w0, &c.effect(w));
    // One frame per wall orientation (windows on the same wall share it).
    let mut walls: Vec<&Window> = Vec::new();
    for w in &m.room.windows {
        if !walls.iter().any(|x| dot(x.outward, w.outward) > 0.99) {
            walls.push(w);
        }
    }
    let mut seen: Vec<Vec<usize>> = Vec::new();
    let mut best: Option<(usize, Frame, f64)> = None;
    for c in 0..ns {
        for r in RADII {
            let group: Vec<usize> = (0..ns)
                .filter(|&s| m.sensor_distance(c, s) <= r + 1e-9)
                .collect();
            if group.len() > ns / 2 || seen.contains(&group) {
                continue;
            }
            seen.push(group.clone());
            let zg = group
                .iter()
                .map(|&s| m.sensors[s].ray.org[2])
                .fold(f64::NEG_INFINITY, f64::max);
            for (wi, w) in walls.iter().enumerate() {
                let ds: Vec<f64> = group
                    .iter()
                    .map(|&s| w.depth_of(m.sensors[s].ray.org))
                    .collect();
                let us: Vec<f64> = group
                    .iter()
                    .map(|&s| dot(m.sensors[s].ray.org, w.tangent))
                    .collect();
                let dmin = ds.iter().copied().fold(f64::INFINITY, f64::min);
                let dmax = ds.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let umin = us.iter().copied().fold(f64::INFINITY, f64::min);
                let umax = us.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                if dmin < 0.5 {
                    continue;
                }
                let mut cands = Vec::new();
                for gap in [0.25, 0.7, 1.5] {
                    if dmin - gap < 0.2 {
                        continue;
                    }
                    for margin in [0.3, 1.0] {
                        cands.push(Frame {
                            across: false,
                            d: dmin - gap,
                            u0: umin - margin,
                            u1: umax + margin,
                            top: 0.0,
                        });
                    }
                }
                for u in [umin - 0.4, umax + 0.4] {
                    cands.push(Frame {
                        across: true,
                        d: (dmin - 2.0).max(0.2),
                        u0: u,
                        u1: dmax + 0.5,
                        top: 0.0,
                    });
                }
                for mut cand in cands {
                    let (lo, hi) = top_range(m, zg);
                    let (top, s) = golden(&mut |z| eval(w, &Frame { top: z, ..cand }), lo, hi, 10);
                    cand.top = top;
                    if best.as_ref().is_none_or(|b| s < b.2) {
                        best = Some((wi, cand, s));
                    }
                }
            }
        }
    }
    let (wi, c, s) = best?;
    let top_hi = m.room.floor + MAX_TOP;
    Some(refine_frame(walls[wi], c, s, 2, top_hi, &|w, c| eval(w, c)))
}

/// Heights a panel's top is searched over: above the group's sensors, below [`MAX_TOP`]
/// over the floor.
fn top_range(m: &Model, zg: f64) -> (f64, f64) {
    let hi = m.room.floor + MAX_TOP;
    ((zg + 0.05).min(hi - 0.1), hi)
}

/// -2 ln L of the panel `e` on the other effects' weights `w0`; effectively infinite for a
/// panel within [`CLEARANCE`] of a sensor or with an end outside the floor (through a wall,
/// `rcalib apply` would write it out into the open).
fn score(f: &Fitter, w0: &Weights, e: &Effect) -> f64 {
    if let Some(slab) = slab_of(e, f.m)
        && (f
            .m
            .sensors
            .iter()
            .any(|s| slab.plan_distance(s.ray.org) < CLEARANCE)
            || !inside_floor(&f.m.room.outline, slab.a)
            || !inside_floor(&f.m.room.outline, slab.b))
    {
        return 1e30;
    }
    f.m2ll_on(w0, e)
}

/// Whether plan point `p` is inside the floor outline (even-odd rule over its edges, in any
/// order); true without an outline.
fn inside_floor(outline: &[[f64; 4]], p: [f64; 2]) -> bool {
    if outline.is_empty() {
        return true;
    }
    let mut inside = false;
    for e in outline {
        let (y0, y1) = (e[1], e[3]);
        if (y0 > p[1]) != (y1 > p[1]) {
            let x = e[0] + (p[1] - y0) / (y1 - y0) * (e[2] - e[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// Coordinate refinement of a panel's continuous parameters (position, ends, top), each by
/// golden section within 0.4 m, `passes` times.
fn refine_frame(
    w: &Window,
    mut c: Frame,
    mut s: f64,
    passes: usize,
    top_hi: f64,
    eval: &dyn Fn(&Window, &Frame) -> f64,
) -> Effect {
    for _ in 0..passes {
        for k in 0..4 {
            let get = |c: &Frame| match k {
                0 => c.d,
                1 => c.u0,
                2 => c.u1,
                _ => c.top,
            };
            let set = |c: &Frame, v: f64| {
                let mut x = *c;
                match k {
                    0 => x.d = v.max(0.1),
                    1 => x.u0 = v,
                    2 => x.u1 = v,
                    _ => x.top = v.min(top_hi),
                }
                x
            };
            let v0 = get(&c);
            let (v, s1) = golden(&mut |v| eval(w, &set(&c, v)), v0 - 0.4, v0 + 0.4, 10);
            if s1 < s {
                c = set(&c, v);
                s = s1;
            }
        }
    }
    c.effect(w)
}

/// Re-fit a kept panel from where it is (used by [`crate::explain::refine`] under the
/// re-simulation's correction): its position, ends and top refined locally on the wall it
/// stands parallel or across to. A full search there let the panel jump between a tall
/// one and none from one round to the next, as the correction made for one is no guide to
/// the other. `None` for other effects (the caller fits those afresh).
pub fn refit(f: &Fitter, base: &[Effect], current: &Effect) -> Option<Effect> {
    let Effect::Furniture { a, b, top, .. } = *current else {
        return None;
    };
    let base = without(base, "local-obstruction");
    let w0 = f.m.weights(&base);
    // The wall the panel is parallel or perpendicular to (the best aligned window).
    let seg = [b[0] - a[0], b[1] - a[1]];
    let len = seg[0].hypot(seg[1]).max(1e-9);
    let align = |w: &Window| (seg[0] * w.tangent[0] + seg[1] * w.tangent[1]).abs() / len;
    let w = f.m.room.windows.iter().max_by(|x, y| {
        let (ax, ay) = (align(x), align(y));
        ax.max(1.0 - ax).total_cmp(&ay.max(1.0 - ay))
    })?;
    let across = align(w) < 0.5;
    let ua = |p: [f64; 2]| p[0] * w.tangent[0] + p[1] * w.tangent[1];
    let da = |p: [f64; 2]| w.depth_of([p[0], p[1], 0.0]);
    let c = if across {
        Frame {
            across,
            d: da(a),
            u0: ua(a),
            u1: da(b),
            top,
        }
    } else {
        Frame {
            across,
            d: da(a),
            u0: ua(a),
            u1: ua(b),
            top,
        }
    };
    let eval = |w: &Window, c: &Frame| score(f, &w0, &c.effect(w));
    let s = eval(w, &c);
    Some(refine_frame(w, c, s, 2, f.m.room.floor + MAX_TOP, &eval))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slab() -> Slab {
        // A partition 2 m long along x at y = 0, 0.1 m thick, 1.6 m high.
        Slab {
            a: [0.0, 0.0],
            b: [2.0, 0.0],
            thick: 0.1,
            floor: 0.0,
            top: 1.6,
        }
    }

    #[test]
    fn view_factor_matches_the_rectangle_formula() {
        // A small surface facing a parallel rectangle a x b at distance c, on the normal
        // through one corner: F = (1/2pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + (X <-> Y)],
        // X = a/c, Y = b/c (Howell's catalogue of view factors, B-2).
        let s = Slab {
            thick: 0.0,
            ..slab()
        };
        let c: f64 = 0.7;
        let (x, y): (f64, f64) = (2.0 / c, 1.6 / c);
        let f = (x / (1.0 + x * x).sqrt() * (y / (1.0 + x * x).sqrt()).atan()
            + y / (1.0 + y * y).sqrt() * (x / (1.0 + y * y).sqrt()).atan())
            / (2.0 * std::f64::consts::PI);
        let got = s.view_factor([0.0, -c, 0.0], [0.0, 1.0, 0.0]);
        assert!((got - f).abs() < 1e-9, "{got} vs {f}");
        // Behind the sensor's plane: nothing; an upward sensor at mid height sees only the
        // part above its plane, less than a sensor facing the panel does.
        assert_eq!(s.view_factor([0.0, -c, 0.8], [0.0, -1.0, 0.0]), 0.0);
        let up = s.view_factor([1.0, -0.3, 0.8], [0.0, 0.0, 1.0]);
        let facing = s.view_factor([1.0, -0.3, 0.8], [0.0, 1.0, 0.0]);
        assert!(up > 0.05 && up < facing, "{up} {facing}");
    }

    #[test]
    fn inside_floor_by_its_edges() {
        // An L-shaped floor, edges in no particular order.
        let l = [
            [0.0, 0.0, 4.0, 0.0],
            [2.0, 2.0, 0.0, 2.0],
            [4.0, 0.0, 4.0, 1.0],
            [0.0, 2.0, 0.0, 0.0],
            [4.0, 1.0, 2.0, 1.0],
            [2.0, 1.0, 2.0, 2.0],
        ];
        assert!(inside_floor(&l, [1.0, 1.5]));
        assert!(inside_floor(&l, [3.0, 0.5]));
        assert!(!inside_floor(&l, [3.0, 1.5]));
        assert!(!inside_floor(&l, [-0.5, 1.0]));
        assert!(inside_floor(&[], [9.0, 9.0]));
    }

    #[test]
    fn crossing_blocks_below_the_top_only() {
        let s = slab();
        let org = [1.0, -1.0, 0.8];
        // Towards the panel at 20 degrees: crosses it at 0.8 + tan(20) * (1 - 0.05).
        let e = 20f64.to_radians();
        let z = s.lowest_crossing(org, [0.0, e.cos(), e.sin()]).unwrap();
        assert!((z - (0.8 + e.tan() * 0.95)).abs() < 1e-9, "{z}");
        assert!(z < s.top);
        // Steeply up (60 degrees) it crosses the footprint above the top: not blocked.
        let e = 60f64.to_radians();
        assert!(s.lowest_crossing(org, [0.0, e.cos(), e.sin()]).unwrap() > s.top);
        // Away from the panel, or beside it: no crossing.
        assert!(s.lowest_crossing(org, [0.0, -1.0, 0.0]).is_none());
        assert!(
            s.lowest_crossing([3.0, -1.0, 0.8], [0.0, 1.0, 0.0])
                .is_none()
        );
    }

    #[test]
    fn faces_close_the_box_with_outward_normals() {
        let s = Slab {
            a: [1.0, 2.0],
            b: [3.0, 3.0],
            thick: 0.4,
            floor: 0.1,
            top: 2.0,
        };
        let faces = s.faces();
        assert_eq!(faces.len(), 5);
        let ctr = [2.0, 2.5, 1.05];
        // Divergence theorem: sum of area-weighted outward normals of a closed box minus
        // its floor is the floor's upward-pointing area; and each normal points out.
        let mut total = [0.0; 3];
        for f in &faces {
            let mut n = [0.0; 3];
            for k in 0..f.len() {
                let c = cross(f[k], f[(k + 1) % f.len()]);
                n = [n[0] + 0.5 * c[0], n[1] + 0.5 * c[1], n[2] + 0.5 * c[2]];
            }
            let fc = f.iter().fold([0.0; 3], |s, v| {
                [s[0] + v[0] / 4.0, s[1] + v[1] / 4.0, s[2] + v[2] / 4.0]
            });
            assert!(dot(n, sub3(fc, ctr)) > 0.0, "{f:?}");
            total = [total[0] + n[0], total[1] + n[1], total[2] + n[2]];
        }
        let floor_area = 0.4 * (2f64 * 2.0 + 1.0).sqrt();
        assert!(total[0].abs() < 1e-9 && total[1].abs() < 1e-9, "{total:?}");
        assert!((total[2] - floor_area).abs() < 1e-9, "{total:?}");
    }

    /// The box `rcalib apply` writes blocks exactly the rays the fitted model blocks: rays
    /// from sensors around the room checked against the written polygons (Radiance's
    /// polygon intersection, `Shape::intersect`), for a panel parallel to the window, one
    /// across the room and the older fraction form.
    #[test]
    fn apply_writes_the_box_the_model_blocks_with() {
        use crate::formats::sensors::{Sensor, SensorRay};
        use rand::{Rng, SeedableRng};
        use rdaylight_physics::geometry::{Ray, Shape, Vec3};
        let text = "void plastic floor_mat 0 0 5 .3 .3 .3 0 0\n\
                    void glass glazing 0 0 3 .9 .9 .9\n\
                    floor_mat polygon floor 0 0 12 0 0 0 4 0 0 4 6 0 0 6 0\n\
                    glazing polygon win 0 0 12 1 0 0.9 3 0 0.9 3 0 2.1 1 0 2.1\n";
        let scene = crate::scene::parse_str(
            text,
            "<test>",
            std::path::Path::new(""),
            &crate::scene::LoadOptions::default(),
        )
        .unwrap();
        let sensors: Vec<Sensor> = [[1.0, 3.0], [2.0, 3.0], [3.0, 4.5], [2.0, 1.0]]
            .iter()
            .enumerate()
            .map(|(i, p)| Sensor {
                id: format!("s{i}"),
                ray: SensorRay::new([p[0], p[1], 0.8], [0.0, 0.0, 1.0]),
            })
            .collect();
        let room = crate::room::Room::new(&scene, [2.0, 3.0, 0.8], &[]);
        assert_eq!(room.windows.len(), 1);
        let panels = [
            Effect::Furniture {
                a: [0.8, 2.0],
                b: [2.6, 2.0],
                top: 1.6,
                thick: 0.1,
            },
            Effect::Furniture {
                a: [2.5, 1.5],
                b: [2.5, 5.0],
                top: 2.0,
                thick: 0.4,
            },
            Effect::LocalObstruction {
                sensors: vec![0, 1],
                fraction: 0.7,
            },
        ];
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        for e in &panels {
            let slab = slab_in(e, &room, &sensors).unwrap();
            let out =
                crate::apply::apply(&scene, &room, &sensors, std::slice::from_ref(e), "t").unwrap();
            let applied = crate::scene::parse_str(
                &out,
                "<applied>",
                std::path::Path::new(""),
                &crate::scene::LoadOptions::default(),
            )
            .unwrap();
            let faces: Vec<Shape> = applied
                .objects
                .iter()
                .filter(|o| o.id.starts_with("rcalib_local_") && !o.id.contains("mat"))
                .filter_map(|o| match &o.kind {
                    crate::scene::Primitive::Polygon { vertices } => Some(Shape::Polygon {
                        vertices: vertices.clone(),
                    }),
                    _ => None,
                })
                .collect();
            assert_eq!(faces.len(), 5, "{e:?}");
            let (mut blocked, mut agree, mut n) = (0, 0, 0);
            for s in &sensors {
                for _ in 0..400 {
                    // Upper hemisphere, uniform.
                    let z: f64 = rng.random();
                    let phi = 2.0 * std::f64::consts::PI * rng.random::<f64>();
                    let r = (1.0 - z * z).sqrt();
                    let d = [r * phi.cos(), r * phi.sin(), z];
                    let model = slab
                        .lowest_crossing(s.ray.org, d)
                        .is_some_and(|zc| zc < slab.top);
                    let ray = Ray::new(Vec3::from(s.ray.org), Vec3::from(d));
                    let written = faces.iter().any(|f| f.intersect(&ray, 1e-9, 1e9).is_some());
                    n += 1;
                    blocked += usize::from(written);
                    agree += usize::from(model == written);
                }
            }
            assert_eq!(agree, n, "{e:?}: {} of {n} rays disagree", n - agree);
            assert!(
                blocked > n / 50 && blocked < n / 2,
                "{e:?}: {blocked} of {n}"
            );
        }
    }

    #[test]
    fn spec_round_trips_and_the_older_form_still_reads() {
        let ids: Vec<String> = ["p1", "p2", "p3"].iter().map(|s| s.to_string()).collect();
        let e = Effect::Furniture {
            a: [1.25, 3.5],
            b: [2.75, 3.5],
            top: 1.9,
            thick: 0.3,
        };
        let spec = e.spec(&ids, &[]);
        assert_eq!(spec, "local-obstruction:1.25,3.50,2.75,3.50,1.90,0.30");
        assert_eq!(Effect::parse(&spec, &ids, &[]).unwrap(), e);
        let no_thick = Effect::parse("local-obstruction:0,0,1,0,1.5", &ids, &[]).unwrap();
        assert!(matches!(no_thick, Effect::Furniture { thick, .. } if thick == THICK));
        assert_eq!(
            Effect::parse("local-obstruction:0.6,p1+p3", &ids, &[]).unwrap(),
            Effect::LocalObstruction {
                sensors: vec![0, 2],
                fraction: 0.6
            }
        );
        assert_eq!(
            Effect::parse("local-obstruction:0.6,p2", &ids, &[]).unwrap(),
            Effect::LocalObstruction {
                sensors: vec![1],
                fraction: 0.6
            }
        );
        for bad in [
            "local-obstruction:0,0,0,0,1.5",
            "local-obstruction:0,0,1,0,-1",
            "local-obstruction:0,0,1,0,1.5,0",
            "local-obstruction:0,0,1,0,1.5,0.1,7",
        ] {
            assert!(Effect::parse(bad, &ids, &[]).is_err(), "{bad}");
        }
    }
}
