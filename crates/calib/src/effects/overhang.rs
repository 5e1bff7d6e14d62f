//! # Overhang (shading) above a window
//!
//! A horizontal projection of depth `D` at height `A` above the head of a window hides, for
//! a direction with profile angle φ (tan φ = d_z / (d · n_out), the altitude projected on
//! the plane normal to the window: Tregenza & Wilson, *Daylighting*, 2011, sec. 10.2), the
//! upper `D tan φ - A` of the opening. Real overhangs (a balcony, the floor slab above, a
//! brise-soleil) often sit well above the head: one fitted at the head (`A = 0`) cuts the
//! high sun too early and the low sun too late, so both are fitted. So:
//!
//! - light of a sky patch or the sun entering the room (what reaches sensors through
//!   inter-reflection) loses the shaded fraction of that window's share (16 columns);
//! - the direct view from a sensor through the point at height z of the opening is blocked
//!   when `z + D tan φ > head` (per sensor, patch and sun; smoothed over 1 cm).
//!
//! The overhang is the plate `rcalib apply` writes: as wide as the opening plus `overrun` on
//! each side (a balcony or a floor slab runs well past the opening; fitted, as deep as the
//! plate in the earlier form), so rays leaving obliquely can pass beside it (exact per ray,
//! [`blocked_z`]).
//!
//! Light of a sky patch or the sun also enters off the exterior ground it lights, which
//! the overhang does not block. For a vertical opening that sees the ground's half of its
//! view, a ground of reflectance ρ lit with `E_h = L Ω sin(alt)` sends in `ρ E_h / 2` per
//! unit area against `L Ω cos θ` straight from the patch (θ from the window's normal):
//! that share `g = ρ sin(alt) / 2 / (ρ sin(alt) / 2 + cos θ)` of the entering light is left
//! alone. Without it, a deep plate that shades the high sun and sky entirely removed the
//! sunlit ground's light too, and the fit answered a real 1.4 m slab with a 0.5 m one.
//!
//! Signature: high sun and high sky, so mostly sun hours and sensors near the window.

use super::{Effect, MAX_ABOVE, MAX_OVERRUN, golden, smooth_step};
use crate::fit::{Fitter, without};
use crate::model::{Model, Weights};
use crate::room::{Window, dot};

/// Columns of the opening sampled by [`shaded`].
const COLUMNS: usize = 16;

/// The overhang as `rcalib apply` writes it: a plate `above` metres over the head, `depth`
/// deep, wider than the opening by `overrun` on each side. For a ray leaving the opening at
/// `(u, z)` (along the wall, height) in direction `d`, the heights `z` whose rays hit the
/// plate at `zp = head + above`: those within `depth tan(phi)` below `zp` whose lateral
/// drift up to it, `k (zp - z)` with `k = (d . t) / d_z`, keeps them within the plate's
/// width. Returns the blocked range of `z` (possibly empty).
fn blocked_z(w: &Window, g: Plate, d: [f64; 3], u: f64) -> (f64, f64) {
    let Plate {
        depth,
        above,
        overrun,
    } = g;
    let c = dot(d, w.outward);
    if c <= 1e-6 || d[2] <= 1e-6 {
        return (0.0, 0.0);
    }
    let tan_phi = d[2] / c;
    let zp = w.head + above;
    let mut lo = zp - depth * tan_phi;
    let mut hi = w.head;
    let k = dot(d, w.tangent) / d[2];
    let (a, b) = (w.span.0 - overrun, w.span.1 + overrun);
    // u + k (zp - z) in [a, b]  <=>  z in [zp - (b - u)/k, zp - (a - u)/k] (k > 0).
    if k.abs() > 1e-9 {
        let (z1, z2) = (zp - (b - u) / k, zp - (a - u) / k);
        lo = lo.max(z1.min(z2));
        hi = hi.min(z1.max(z2));
    }
    (lo, hi)
}

/// Fraction of the opening `w` shaded for direction `d` (unit, towards the sky), and the
/// window's projected area towards `d`.
fn shaded(w: &Window, g: Plate, d: [f64; 3]) -> (f64, f64) {
    let c = dot(d, w.outward);
    if c <= 1e-6 {
        return (0.0, 0.0);
    }
    let h = w.height().max(1e-9);
    let mut f = 0.0;
    for i in 0..COLUMNS {
        let u = w.span.0 + (w.span.1 - w.span.0) * (i as f64 + 0.5) / COLUMNS as f64;
        let (lo, hi) = blocked_z(w, g, d, u);
        f += ((hi.min(w.head) - lo.max(w.sill)) / h).clamp(0.0, 1.0);
    }
    (f / COLUMNS as f64, w.area * c)
}

/// Weight of the direct view from `org` along `d` past an overhang on window `w`: 1 when the
/// ray misses the window (edges smoothed over 1 cm for the fit).
fn direct(w: &Window, g: Plate, org: [f64; 3], d: [f64; 3]) -> f64 {
    let c = dot(d, w.outward);
    let dist = w.depth_of(org);
    if c <= 1e-6 || dist <= 0.0 {
        return 1.0;
    }
    let t = dist / c;
    let hit = [org[0] + d[0] * t, org[1] + d[1] * t, org[2] + d[2] * t];
    let u = dot(hit, w.tangent);
    if hit[2] < w.sill - 1e-6 || hit[2] > w.head + 1e-6 || u < w.span.0 || u > w.span.1 {
        return 1.0;
    }
    let (lo, hi) = blocked_z(w, g, d, u);
    if hi <= lo {
        return 1.0;
    }
    1.0 - smooth_step(hit[2] - lo, 0.01) * smooth_step(hi - hit[2] + 1e-3, 0.01)
}

/// The plate's dimensions (m).
#[derive(Debug, Clone, Copy)]
struct Plate {
    depth: f64,
    above: f64,
    overrun: f64,
}

/// Multiply the window weights by what the overhang leaves.
pub fn apply(e: &Effect, m: &Model, wt: &mut Weights) {
    let Effect::Overhang {
        window,
        depth,
        above,
        overrun,
    } = *e
    else {
        return;
    };
    let Some(win) = m.room.windows.get(window) else {
        return;
    };
    let g = Plate {
        depth,
        above,
        overrun,
    };
    let rho = m.room.ground_reflectance;
    let area: f64 = m.room.windows.iter().map(|w| w.area).sum();
    // Share of the light from direction `d` entering the windows that the plate stops:
    // its shaded share of the light straight from `d` (module documentation: the light
    // off the sunlit ground is not stopped).
    let share = |d: [f64; 3]| -> f64 {
        let (f, a) = shaded(win, g, d);
        let total: f64 = m
            .room
            .windows
            .iter()
            .map(|w| w.area * dot(d, w.outward).max(0.0))
            .sum();
        let ground = 0.5 * rho * d[2].max(0.0) * area;
        if total > 0.0 {
            f * a / (total + ground)
        } else {
            0.0
        }
    };
    let np = m.comps.npatch;
    let ns = m.nsens();
    let hz = m.horizon();
    let nt = m.nsteps();
    let mut wd = wt.win_dir.take().unwrap_or_else(|| vec![1.0; ns * np]);
    for p in 1..np {
        let d = m.patches.centre(p);
        wt.win_ind[p] *= 1.0 - share(d);
        // Where a skyline weighs the ground's part on its own, the overhang keeps acting
        // on it as on the rest (as without one): the effects commute.
        if let Some(g) = wt.gnd.as_mut() {
            g[p] *= 1.0 - share(d);
        }
        for (s, sensor) in m.sensors.iter().enumerate() {
            // Over the part of the patch the sensor sees through a window (0.75-degree
            // cells), else at the patch centre.
            let org = sensor.ray.org;
            wd[s * np + p] *= hz
                .direct_mean(s, p, |c| direct(win, g, org, c))
                .unwrap_or_else(|| direct(win, g, org, d));
        }
    }
    wt.win_dir = Some(wd);
    let mut sd = wt.sun_win_dir.take().unwrap_or_else(|| vec![1.0; ns * nt]);
    for (t, sk) in m.skies.iter().enumerate() {
        if sk.sun_altitude_deg <= 0.0 {
            continue;
        }
        wt.sun_win_ind[t] *= 1.0 - share(sk.sun_dir);
        if let Some(g) = wt.sun_gnd.as_mut() {
            g[t] *= 1.0 - share(sk.sun_dir);
        }
        for (s, sensor) in m.sensors.iter().enumerate() {
            sd[s * nt + t] *= direct(win, g, sensor.ray.org, sk.sun_dir);
        }
    }
    wt.sun_win_dir = Some(sd);
}

/// Heights above the head the fit starts from (m): from a plate at the head to one a
/// storey-slab above it.
const ABOVE_GRID: [f64; 6] = [0.0, 0.15, 0.3, 0.5, 0.75, 1.0];

/// Overruns the fit starts from, as fractions of the depth: a plate flush with the
/// opening's sides, half as far, and as far as deep (the earlier form's only choice). The
/// overrun decides which oblique suns the plate's ends let in, which trades against the
/// height and the depth, so it is searched with them from the start.
const OVERRUN_GRID: [f64; 3] = [0.0, 0.5, 1.0];

/// Best depth (0 to 3 m), height above the head (0 to [`MAX_ABOVE`]) and overrun beyond the
/// opening's sides for each window given the other effects: a coarse grid over all three
/// (the likelihood has shoulders where suns cross the plate's edges), then golden-section refinement of the depth, the height and
/// the overrun in turn, twice (the overrun decides the oblique suns of mornings and
/// evenings and the sensors' side views).
pub fn fit(f: &Fitter, base: &[Effect]) -> Option<Effect> {
    let base = without(base, "overhang");
    let w0 = f.m.weights(&base);
    let mut best: Option<(Effect, f64)> = None;
    for window in 0..f.m.room.windows.len() {
        let eval3 = |depth: f64, above: f64, overrun: f64| {
            f.m2ll_on(
                &w0,
                &Effect::Overhang {
                    window,
                    depth,
                    above,
                    overrun,
                },
            )
        };
        let mut start = (0.0, 0.0, 0.0, f64::INFINITY);
        for &a in &ABOVE_GRID {
            for k in 0..=12 {
                let d = 0.25 * k as f64;
                for o in OVERRUN_GRID {
                    let s = eval3(d, a, o * d);
                    if s < start.3 {
                        start = (d, a, o * d, s);
                    }
                }
            }
        }
        let (mut d, mut a, mut o, mut s) = start;
        for _ in 0..2 {
            let (d1, s1) = golden(&mut |x| eval3(x, a, o), (d - 0.25).max(0.0), d + 0.25, 14);
            if s1 < s {
                (d, s) = (d1, s1);
            }
            let (a1, s1) = golden(
                &mut |x| eval3(d, x, o),
                (a - 0.2).max(0.0),
                (a + 0.2).min(MAX_ABOVE),
                12,
            );
            if s1 < s {
                (a, s) = (a1, s1);
            }
            let (o1, s1) = golden(
                &mut |x| eval3(d, a, x),
                (o - 0.6).max(0.0),
                (o + 0.6).min(MAX_OVERRUN),
                12,
            );
            if s1 < s {
                (o, s) = (o1, s1);
            }
        }
        if best.as_ref().is_none_or(|b| s < b.1) {
            best = Some((
                Effect::Overhang {
                    window,
                    depth: d,
                    above: a,
                    overrun: o,
                },
                s,
            ));
        }
    }
    best.map(|b| b.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 m wide, 1.4 m high opening in the wall y = 0, facing -y (outward), head at 2.3 m.
    fn window() -> Window {
        Window {
            id: "w".into(),
            centroid: [1.0, 0.0, 1.6],
            outward: [0.0, -1.0, 0.0],
            sill: 0.9,
            head: 2.3,
            area: 2.8,
            span: (-2.0, 0.0),
            tangent: [1.0, 0.0, 0.0],
        }
    }

    #[test]
    fn overrun_decides_the_oblique_sun_under_the_plate_ends() {
        let w = window();
        // Sun 30 degrees up, 50 degrees off the window's normal (towards +tangent, so -x in
        // the tangent's terms is where the ray drifts from): d = (sin a cos h, -cos a cos h,
        // sin h) with tangent (1, 0, 0): drift along the wall k = d.t / d_z.
        let (h, a) = (30f64.to_radians(), 50f64.to_radians());
        let d = [a.sin() * h.cos(), -a.cos() * h.cos(), h.sin()];
        let plate = |overrun| Plate {
            depth: 1.4,
            above: 0.4,
            overrun,
        };
        // Flush with the opening's sides: the columns near the far end are sunlit under the
        // plate's end; 1.5 m past the sides the whole width is shaded alike.
        let (flush, _) = shaded(&w, plate(0.0), d);
        let (wide, _) = shaded(&w, plate(1.5), d);
        assert!(flush < wide - 0.05, "{flush} {wide}");
        // Straight out (no drift) the overrun changes nothing.
        let n = [0.0, -h.cos(), h.sin()];
        let (a0, _) = shaded(&w, plate(0.0), n);
        let (a1, _) = shaded(&w, plate(1.5), n);
        assert!((a0 - a1).abs() < 1e-12);
        // And the shaded share is the profile-angle rule there: the top D tan(phi) - A of
        // the opening (tan(phi) = tan(30 deg) straight out).
        let expect = ((1.4 * h.tan() - 0.4) / 1.4).clamp(0.0, 1.0);
        assert!((a0 - expect).abs() < 1e-9, "{a0} {expect}");
    }

    #[test]
    fn overhang_spec_reads_the_overrun_and_defaults_it_to_the_depth() {
        let w = vec!["w".to_string()];
        let e = Effect::parse("overhang:1.4,w,0.4,0.5", &[], &w).unwrap();
        assert_eq!(
            e,
            Effect::Overhang {
                window: 0,
                depth: 1.4,
                above: 0.4,
                overrun: 0.5
            }
        );
        assert_eq!(e.spec(&[], &w), "overhang:1.40,w,0.40,0.50");
        assert!(matches!(
            Effect::parse("overhang:1.2", &[], &w).unwrap(),
            Effect::Overhang { overrun, .. } if overrun == 1.2
        ));
        assert!(Effect::parse("overhang:1.2,w,0,9", &[], &w).is_err());
    }
}
