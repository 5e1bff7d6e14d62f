//! # Exterior obstruction: a horizon sector
//!
//! Buildings or trees opposite the window hide the sky below a horizon profile. The profile
//! is one sector: azimuth `a` (east of north), half width `w`, altitude `h`. What it hides
//! is computed on cells of 0.75 degrees inside each sky patch ([`Horizon`]): for the light
//! entering the room, the cells' share weighted by the windows' projected area towards
//! them; for each sensor's direct view of the sky, only the cells that sensor sees through
//! a window (a deep sensor sees the low part of a patch only). A sun is hidden when it
//! stands behind the sector (edges smoothed over half a degree so the fit sees a
//! continuous profile). In place of the sky it hides, the obstruction sends back the light
//! of its facade as `rcalib apply` writes it (Lambertian, reflectance 0.1, lit by the sky,
//! the ground and the sun on the room's side): a few percent of the hidden sky's light, but
//! left out it biased the fitted altitude low and a glazing scale fitted with it high.
//! Signature: deficits that depend on which part of the sky each sensor sees and on the
//! sun's azimuth and altitude.

use super::{Effect, golden, smooth_step};
use crate::fit::{Fitter, without};
use crate::model::{Fill, Model, Weights};
use crate::room::dot;
use crate::simulate::LUX_RGB;
use std::f64::consts::PI;

/// Signed angle difference a - b wrapped to (-180, 180] degrees.
pub fn wrap_deg(d: f64) -> f64 {
    let x = (d + 180.0).rem_euclid(360.0) - 180.0;
    if x == -180.0 { 180.0 } else { x }
}

/// Cells per patch side of [`Horizon`]: 16 x 16 cells of 0.75 degrees on Tregenza patches.
pub const CELLS: usize = 16;

/// The sky as the horizon profile sees it, precomputed once per model ([`Model::horizon`]):
/// every sky patch split into [`CELLS`] x [`CELLS`] cells of equal solid angle, with the
/// weight each cell carries
///
/// - for the light entering the room (what reaches the sensors after reflection): the
///   windows' projected area towards the cell, `sum A_w max(0, d . n_w)`;
/// - for each sensor's direct view: `max(0, d . n_s)` when the ray from the sensor along the
///   cell's centre passes through a window, else 0. A deep sensor sees only the lowest part
///   of a patch through the window: a sector up to 30 degrees hides all of what it sees of
///   the 24-36 degree band, though only half of that band.
///
/// A sector blocks a cell by the product of its overlaps in altitude and azimuth (the
/// cell's own altitude and azimuth range), so the blocked share is piecewise linear, hence
/// continuous, in the sector's parameters.
#[derive(Debug, Clone)]
pub struct Horizon {
    /// Per patch (index into the sky patches; none for the ground and the zenith cap):
    /// altitude edges (degrees, `CELLS + 1`), azimuth of the first edge and cell width.
    pub(crate) cells: Vec<Option<PatchCells>>,
    /// `[p][cell]` weight of light entering through the windows.
    pub(crate) ind: Vec<Vec<f64>>,
    /// `[s][p]`: `[cell]` weights of the sensor's direct view (empty: sees none of it).
    pub(crate) dir: Vec<Vec<Vec<f64>>>,
}

#[derive(Debug, Clone)]
pub(crate) struct PatchCells {
    pub(crate) alt: Vec<f64>,
    pub(crate) az0: f64,
    pub(crate) daz: f64,
    /// sin of the lowest and highest altitude.
    s0: f64,
    s1: f64,
}

impl PatchCells {
    /// Unit direction of cell `(a, b)` (altitude row, azimuth column).
    pub(crate) fn centre(&self, a: usize, b: usize) -> [f64; 3] {
        let z = self.s0 + (self.s1 - self.s0) * (a as f64 + 0.5) / CELLS as f64;
        let az = (self.az0 + self.daz * (b as f64 + 0.5)).to_radians();
        let c = (1.0 - z * z).max(0.0).sqrt();
        [c * az.sin(), c * az.cos(), z]
    }
}

pub(crate) fn window_hit(w: &crate::room::Window, org: [f64; 3], d: [f64; 3]) -> bool {
    let c = dot(d, w.outward);
    let dist = w.depth_of(org);
    if c <= 1e-6 || dist <= 0.0 {
        return false;
    }
    let t = dist / c;
    let hit = [org[0] + d[0] * t, org[1] + d[1] * t, org[2] + d[2] * t];
    let u = dot(hit, w.tangent);
    (w.sill..=w.head).contains(&hit[2]) && (w.span.0..=w.span.1).contains(&u)
}

impl Horizon {
    pub fn new(m: &Model) -> Horizon {
        let p = &m.patches;
        let np = p.len();
        let alpha = p.alpha().to_degrees();
        let mut cells = vec![None; np];
        let mut ind = vec![Vec::new(); np];
        let mut dir = vec![vec![Vec::new(); np]; m.sensors.len()];
        for i in 1..np {
            let Some(r) = p.row_of(i) else { continue };
            if r >= p.rows() {
                continue; // zenith cap: above any fitted sector
            }
            let (a0, a1) = (
                (r as f64 * alpha).to_radians(),
                ((r + 1) as f64 * alpha).to_radians(),
            );
            let (s0, s1) = (a0.sin(), a1.sin());
            // Equal solid angle: uniform in sin(altitude).
            let alt: Vec<f64> = (0..=CELLS)
                .map(|k| {
                    (s0 + (s1 - s0) * k as f64 / CELLS as f64)
                        .asin()
                        .to_degrees()
                })
                .collect();
            let n = p.row_len(r);
            let daz_patch = 360.0 / n as f64;
            let az0 = p.centre_angles(i).1.to_degrees() - 0.5 * daz_patch;
            let daz = daz_patch / CELLS as f64;
            let pc = PatchCells {
                alt,
                az0,
                daz,
                s0,
                s1,
            };
            let mut wi = vec![0.0; CELLS * CELLS];
            let mut ws = vec![vec![0.0; CELLS * CELLS]; m.sensors.len()];
            for a in 0..CELLS {
                for b in 0..CELLS {
                    let d = pc.centre(a, b);
                    wi[a * CELLS + b] = m
                        .room
                        .windows
                        .iter()
                        .map(|w| w.area * dot(d, w.outward).max(0.0))
                        .sum();
                    for (s, sensor) in m.sensors.iter().enumerate() {
                        let cos = dot(d, sensor.ray.dir);
                        if cos > 0.0
                            && m.room
                                .windows
                                .iter()
                                .any(|w| window_hit(w, sensor.ray.org, d))
                        {
                            ws[s][a * CELLS + b] = cos;
                        }
                    }
                }
            }
            for (s, v) in ws.into_iter().enumerate() {
                if v.iter().any(|x| *x > 0.0) {
                    dir[s][i] = v;
                }
            }
            ind[i] = wi;
            cells[i] = Some(pc);
        }
        Horizon { cells, ind, dir }
    }

    /// Mean of `f` over the cells of patch `p` that sensor `s` sees through a window,
    /// weighted as its direct view; `None` when it sees none of them.
    pub fn direct_mean(&self, s: usize, p: usize, f: impl Fn([f64; 3]) -> f64) -> Option<f64> {
        let c = self.cells.get(p)?.as_ref()?;
        let w = self.dir.get(s)?.get(p)?;
        if w.is_empty() {
            return None;
        }
        let (mut num, mut den) = (0.0, 0.0);
        for a in 0..CELLS {
            for b in 0..CELLS {
                let x = w[a * CELLS + b];
                if x > 0.0 {
                    num += x * f(c.centre(a, b));
                    den += x;
                }
            }
        }
        (den > 0.0).then(|| num / den)
    }

    /// The cells of patch `p` that sensor `s` sees through a window, as (direction,
    /// weight) pairs (the terms of [`Horizon::direct_mean`]); empty when it sees none.
    pub fn direct_cells(&self, s: usize, p: usize) -> Vec<([f64; 3], f64)> {
        let (Some(Some(c)), Some(w)) = (self.cells.get(p), self.dir.get(s).and_then(|d| d.get(p)))
        else {
            return Vec::new();
        };
        w.iter()
            .enumerate()
            .filter(|(_, x)| **x > 0.0)
            .map(|(k, x)| (c.centre(k / CELLS, k % CELLS), *x))
            .collect()
    }

    /// Per patch: the blocked share of each cell row (altitude) and column (azimuth).
    fn overlaps(
        &self,
        i: usize,
        azimuth: f64,
        half_width: f64,
        altitude: f64,
    ) -> Option<(Vec<f64>, Vec<f64>)> {
        let c = self.cells.get(i)?.as_ref()?;
        if altitude <= c.alt[0] {
            return None;
        }
        let fa: Vec<f64> = c
            .alt
            .windows(2)
            .map(|e| ((altitude - e[0]) / (e[1] - e[0])).clamp(0.0, 1.0))
            .collect();
        let fz: Vec<f64> = (0..CELLS)
            .map(|b| {
                if half_width >= 180.0 {
                    return 1.0;
                }
                // Overlap of the cell [x0, x0 + daz] with [-hw, hw] around the sector centre.
                let x0 = wrap_deg(c.az0 + c.daz * b as f64 + 0.5 * c.daz - azimuth) - 0.5 * c.daz;
                let lo = x0.max(-half_width);
                let hi = (x0 + c.daz).min(half_width);
                ((hi - lo) / c.daz).clamp(0.0, 1.0)
            })
            .collect();
        fz.iter().any(|x| *x > 0.0).then_some((fa, fz))
    }
}

fn share(wts: &[f64], fa: &[f64], fz: &[f64]) -> Option<f64> {
    let (mut blocked, mut total) = (0.0, 0.0);
    for (a, row) in wts.chunks_exact(CELLS).enumerate() {
        let mut rb = 0.0;
        for (w, z) in row.iter().zip(fz) {
            rb += w * z;
            total += w;
        }
        blocked += fa[a] * rb;
    }
    (total > 0.0).then(|| blocked / total)
}

/// Multiply the window weights (entering light per patch, direct view per sensor and
/// patch) and the sun weights by what the sector leaves visible.
pub fn apply(e: &Effect, m: &Model, w: &mut Weights) {
    let Effect::Obstruction {
        azimuth,
        half_width,
        altitude,
    } = *e
    else {
        return;
    };
    let hz = m.horizon();
    let (ns, np, nt) = (m.nsens(), m.comps.npatch, m.nsteps());
    let mut wd = w.win_dir.take().unwrap_or_else(|| vec![1.0; ns * np]);
    let mut fill = Fill {
        ind: vec![0.0; np],
        dir: vec![0.0; ns * np],
        ratio: vec![0.0; nt * np],
        gnd: None,
        glow: None,
    };
    for i in 1..np.min(hz.cells.len()) {
        let Some((fa, fz)) = hz.overlaps(i, azimuth, half_width, altitude) else {
            continue;
        };
        let f_ind = share(&hz.ind[i], &fa, &fz).unwrap_or(0.0);
        fill.ind[i] = f_ind * w.win_ind[i];
        w.win_ind[i] *= 1.0 - f_ind;
        if let Some(g) = w.gnd.as_mut() {
            g[i] *= 1.0 - f_ind;
        }
        for s in 0..ns {
            let f = if hz.dir[s][i].is_empty() {
                f_ind
            } else {
                share(&hz.dir[s][i], &fa, &fz).unwrap_or(f_ind)
            };
            fill.dir[s * np + i] = f * wd[s * np + i];
            wd[s * np + i] *= 1.0 - f;
        }
    }
    w.win_dir = Some(wd);
    let az = azimuth.to_radians();
    let n_f = [-az.sin(), -az.cos(), 0.0];
    for t in 0..nt {
        let l_o = facade_luminance(m, t, n_f);
        for p in 1..np {
            let l = sky_luminance(m, t, p);
            if l > 0.0 && fill.ind[p] + fill.dir.iter().skip(p).step_by(np).sum::<f64>() > 0.0 {
                fill.ratio[t * np + p] = l_o / l;
            }
        }
    }
    w.fill = Some(fill);
    for (t, sk) in m.skies.iter().enumerate() {
        if sk.sun_altitude_deg <= 0.0 {
            continue;
        }
        let d = wrap_deg(sk.sun_azimuth_deg - azimuth).abs();
        let inside = smooth_step(half_width - d, 0.5);
        let behind = smooth_step(altitude - sk.sun_altitude_deg, 0.5);
        w.sun[t] *= 1.0 - inside * behind;
    }
}

/// Photopic luminance (as the sky's `LUX_RGB` weighting) of sky patch `p` at step `t`.
pub fn sky_luminance(m: &Model, t: usize, p: usize) -> f64 {
    let sky = &m.skies[t].sky;
    (0..3)
        .map(|c| sky.get(p * 3 + c).copied().unwrap_or(0.0) * LUX_RGB[c])
        .sum()
}

/// Luminance of an obstruction's facade whose outward normal is `n_f` (horizontal, facing
/// the room) at step `t`, as `rcalib apply` writes it: Lambertian, reflectance
/// `apply::OBSTRUCTION_REFLECTANCE`, so `L = rho E_f / pi` with `E_f` the illuminance on the
/// vertical plane from the sky patches, the sky's ground patch (the lower quarter sphere,
/// pi/2 of cosine-weighted solid angle) and the sun.
pub fn facade_luminance(m: &Model, t: usize, n_f: [f64; 3]) -> f64 {
    facade_light(m, t, n_f).luminance(m, t)
}

/// The light on a facade of outward normal `n_f` at step `t` (see [`facade_luminance`]).
pub struct FacadeLight {
    /// Reflectance the luminances are for (`apply::OBSTRUCTION_REFLECTANCE`).
    pub rho: f64,
    /// Illuminance on the facade from the sky patches and the sun.
    pub e_direct: f64,
    /// Horizontal illuminance from the sky patches, and from the sun.
    pub e_sky: f64,
    pub e_sun: f64,
    /// Cosine between the sun's direction and the facade's normal (0 without a sun).
    pub toward: f64,
}

impl FacadeLight {
    /// [`facade_luminance`] of this light at step `t`.
    pub fn luminance(&self, m: &Model, t: usize) -> f64 {
        let mut ground = sky_luminance(m, t, 0);
        // A facade turned away from the sun stands in front of its own shadow: the ground
        // it sees is lit by the sky alone (the sky's ground luminance is its reflectance
        // times the whole horizontal illuminance over pi, gendaymtx).
        if self.toward <= 0.0 && self.e_sky + self.e_sun > 0.0 {
            ground *= self.e_sky / (self.e_sky + self.e_sun);
        }
        self.rho * (self.e_direct + ground * PI / 2.0) / PI
    }
}

pub fn facade_light(m: &Model, t: usize, n_f: [f64; 3]) -> FacadeLight {
    let np = m.comps.npatch;
    let sk = &m.skies[t];
    let sun_omega = 2.0 * PI * (1.0 - (0.533f64.to_radians() / 2.0).cos());
    let white: f64 = LUX_RGB.iter().sum();
    let (mut e_direct, mut e_sky, mut e_sun, mut toward) = (0.0, 0.0, 0.0, 0.0);
    for p in 1..np {
        let d = m.patches.centre(p);
        let l = sky_luminance(m, t, p) * m.patches.solid_angle(p);
        e_sky += l * d[2].max(0.0);
        let c = dot(d, n_f);
        if c > 0.0 {
            e_direct += l * c;
        }
    }
    if sk.sun_altitude_deg > 0.0 {
        toward = dot(sk.sun_dir, n_f);
        let e = sk.sun_radiance * white * sun_omega;
        e_direct += e * toward.max(0.0);
        e_sun = e * sk.sun_dir[2].max(0.0);
    }
    FacadeLight {
        rho: crate::apply::OBSTRUCTION_REFLECTANCE,
        e_direct,
        e_sky,
        e_sun,
        toward,
    }
}

/// Outward azimuths (degrees east of north) of the room's windows.
pub fn window_azimuths(m: &Model) -> Vec<f64> {
    let mut a: Vec<f64> = m
        .room
        .windows
        .iter()
        .map(|w| (w.outward[0].atan2(w.outward[1]) * 180.0 / PI).rem_euclid(360.0))
        .map(|x| (x / 5.0).round() * 5.0)
        .collect();
    a.sort_by(f64::total_cmp);
    a.dedup();
    if a.is_empty() {
        a.push(180.0);
    }
    a
}

/// Best sector given the other effects: centres every 15 degrees within 90 degrees of each
/// window's outward direction, a few half widths, the altitude by golden section; then the
/// sector's two edges are refined on a 1-degree grid, one at a time with the altitude
/// re-fitted, until neither moves (suns near the edges decide them: a sun wrongly blocked
/// or left in costs far more than the sky patches' share).
pub fn fit(f: &Fitter, base: &[Effect]) -> Option<Effect> {
    let base = without(base, "obstruction");
    let w0 = f.m.weights(&base);
    let eval = |a: f64, hw: f64, h: f64| {
        f.m2ll_on(
            &w0,
            &Effect::Obstruction {
                azimuth: a.rem_euclid(360.0),
                half_width: hw,
                altitude: h,
            },
        )
    };
    let best_h = |a: f64, hw: f64| golden(&mut |h| eval(a, hw, h), 0.0, 70.0, 22);
    let mut best: Option<(f64, f64, f64, f64)> = None;
    for wa in window_azimuths(f.m) {
        for k in -6..=6 {
            let a = (wa + 15.0 * k as f64).rem_euclid(360.0);
            for hw in [15.0, 30.0, 45.0, 60.0, 90.0] {
                let (h, s) = best_h(a, hw);
                if best.is_none_or(|b| s < b.3) {
                    best = Some((a, hw, h, s));
                }
            }
        }
    }
    let (a0, hw0, mut h0, mut s0) = best?;
    // Edges (degrees east of north, lo < hi when unwrapped).
    let (mut lo, mut hi) = (a0 - hw0, a0 + hw0);
    for _ in 0..4 {
        let mut moved = false;
        for edge in 0..2 {
            let cur = if edge == 0 { lo } else { hi };
            let mut pick = (cur, h0, s0);
            for k in -8..=8 {
                let x = cur + k as f64;
                let (l, u) = if edge == 0 { (x, hi) } else { (lo, x) };
                if u - l < 4.0 || u - l > 360.0 {
                    continue;
                }
                let (h, s) = best_h(0.5 * (l + u), 0.5 * (u - l));
                if s < pick.2 - 1e-9 {
                    pick = (x, h, s);
                }
            }
            if pick.0 != cur {
                moved = true;
                if edge == 0 {
                    lo = pick.0;
                } else {
                    hi = pick.0;
                }
                (h0, s0) = (pick.1, pick.2);
            }
        }
        if !moved {
            break;
        }
    }
    Some(Effect::Obstruction {
        azimuth: (0.5 * (lo + hi)).rem_euclid(360.0),
        half_width: 0.5 * (hi - lo),
        altitude: h0,
    })
}
