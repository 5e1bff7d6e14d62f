//! # Apply: the model with an effect added as real geometry or materials
//!
//! | effect | what is written |
//! |---|---|
//! | transmittance | every `glass` transmissivity times the scale (capped at 1) |
//! | walls / ceiling / floor / ground-albedo | the class's material colours times the scale (capped at 0.95) |
//! | obstruction | vertical facets (plastic, reflectance [`OBSTRUCTION_REFLECTANCE`]) on a circle of radius [`OBSTRUCTION_RADIUS`] around the windows, as high as the fitted horizon altitude seen from the window centres |
//! | skyline | vertical facets (plastic, the fitted facade reflectance) one per sector on a circle of the fitted distance around the windows' centre, each as high as its sector's altitude seen from the windows' centre (the geometry the effect models) |
//! | overhang | a horizontal plate `above` the window head, `depth` deep, wider than the window by `overrun` each side |
//! | local-obstruction | an opaque box standing on the floor along the fitted plan segment, as thick and as high as fitted (plastic, reflectance 0.5); the older `FRACTION,ID+ID` form: a box 0.1 m thick between the sensors and the window, as high as blocks that fraction of the window's elevation span seen from them |
//! | tint | a `spectrum` pattern (the fitted transmittance shape and level) on every `glass` material |
//! | sensor-fault | nothing in the model (comment only); the readings are divided by the factors ([`correct_readings`]) |
//!
//! The output is the scene written canonically (comments of the input are not kept) with a
//! comment block at the top saying what was changed and why, and the added objects at the
//! end under their own comment.

use super::effects::Effect;
use super::measurements::Reading;
use super::room::{Room, dot, scaled_scene};
use crate::error::{Error, Result};
use crate::formats::sensors::Sensor;
use crate::scene::{Primitive, Scene};

/// Distance of the modelled exterior obstruction from the windows (m): far enough that its
/// altitude is the same from every sensor (a horizon profile, as the effect models it).
pub const OBSTRUCTION_RADIUS: f64 = 300.0;
/// Height of the bottom of the skyline's facets (m, model coordinates): below a ground at
/// 0, so that no sky shows under them.
pub const SKYLINE_BOTTOM: f64 = -0.5;
/// Reflectance of added obstructions (a dull facade).
pub const OBSTRUCTION_REFLECTANCE: f64 = 0.1;

fn plastic(rho: f64) -> Primitive {
    Primitive::Plastic {
        color: vec![rho; 3],
        spec: 0.0,
        rough: 0.0,
    }
}

fn polygon(v: Vec<[f64; 3]>) -> Primitive {
    Primitive::Polygon { vertices: v }
}

fn add(
    scene: &mut Scene,
    added: &mut Scene,
    modifier: &str,
    id: String,
    p: Primitive,
) -> Result<()> {
    scene.push(modifier, id.clone(), p.clone())?;
    added
        .objects
        .push(scene.objects[scene.objects.len() - 1].clone());
    Ok(())
}

/// The model with `effects` applied, as `.rad` text; `why` is the reason written in the
/// comments (e.g. the explain verdict).
pub fn apply(
    scene: &Scene,
    room: &Room,
    sensors: &[Sensor],
    effects: &[Effect],
    why: &str,
) -> Result<String> {
    let ids: Vec<String> = sensors.iter().map(|s| s.id.clone()).collect();
    let wids: Vec<String> = room.windows.iter().map(|w| w.id.clone()).collect();
    let mut s = scene.clone();
    let mut added = Scene::default();
    let mut notes = Vec::new();
    for (k, e) in effects.iter().enumerate() {
        notes.push(format!(
            "{} -- {}",
            e.spec(&ids, &wids),
            e.describe(&ids, &wids)
        ));
        match e {
            Effect::Transmittance { scale } => {
                notes.extend(capped(
                    &s,
                    |_, o| matches!(o, Primitive::Glass { .. }),
                    *scale,
                    1.0,
                ));
                s = scaled_scene(&s, room, &[], *scale)
            }
            Effect::Reflectance { class, scale } => {
                if !room.materials.iter().any(|m| m.1 == *class) {
                    return Err(Error::Usage(format!(
                        "{}: the model has no {} material (name it so, or use --classes)",
                        e.family(),
                        class.name()
                    )));
                }
                let in_class = |id: &str, o: &Primitive| {
                    room.materials.iter().any(|m| m.0 == id && m.1 == *class)
                        && matches!(
                            o,
                            Primitive::Plastic { .. }
                                | Primitive::Metal { .. }
                                | Primitive::Trans { .. }
                        )
                };
                notes.extend(capped(&s, in_class, *scale, 0.95));
                s = scaled_scene(&s, room, &[(*class, *scale)], 1.0)
            }
            Effect::Obstruction {
                azimuth,
                half_width,
                altitude,
            } => {
                let (c, zref) = window_centre(room, sensors);
                let m = format!("rcalib_obstruction_mat_{k}");
                add(
                    &mut s,
                    &mut added,
                    "void",
                    m.clone(),
                    plastic(OBSTRUCTION_REFLECTANCE),
                )?;
                let top = zref + OBSTRUCTION_RADIUS * altitude.to_radians().tan();
                let n = ((2.0 * half_width / 5.0).ceil() as usize).max(1);
                for i in 0..n {
                    let a1 = (azimuth - half_width + 2.0 * half_width * i as f64 / n as f64)
                        .to_radians();
                    let a2 = (azimuth - half_width + 2.0 * half_width * (i + 1) as f64 / n as f64)
                        .to_radians();
                    let p = |a: f64, z: f64| {
                        [
                            c[0] + OBSTRUCTION_RADIUS * a.sin(),
                            c[1] + OBSTRUCTION_RADIUS * a.cos(),
                            z,
                        ]
                    };
                    // Clockwise in azimuth seen from above, so the normal faces the room.
                    let v = vec![p(a1, -0.5), p(a2, -0.5), p(a2, top), p(a1, top)];
                    add(
                        &mut s,
                        &mut added,
                        &m,
                        format!("rcalib_obstruction_{k}_{i}"),
                        polygon(v),
                    )?;
                }
            }
            Effect::Skyline {
                distance,
                start,
                step,
                alts,
                reflectance,
                ..
            } => {
                let (c, zref) = window_centre(room, sensors);
                let m = format!("rcalib_skyline_mat_{k}");
                add(&mut s, &mut added, "void", m.clone(), plastic(*reflectance))?;
                let p = |a: f64, z: f64| {
                    let a = a.to_radians();
                    [c[0] + distance * a.sin(), c[1] + distance * a.cos(), z]
                };
                let height = |alt: f64| zref + distance * alt.to_radians().tan();
                for (i, alt) in alts.iter().enumerate() {
                    // A sector at 0 hides nothing (the profile is 0 there).
                    if *alt <= 0.0 {
                        continue;
                    }
                    let (a1, a2) = (start + step * i as f64, start + step * (i + 1) as f64);
                    let t = height(*alt);
                    // Clockwise in azimuth seen from above, so the normal faces the room.
                    let v = vec![
                        p(a1, SKYLINE_BOTTOM),
                        p(a2, SKYLINE_BOTTOM),
                        p(a2, t),
                        p(a1, t),
                    ];
                    add(
                        &mut s,
                        &mut added,
                        &m,
                        format!("rcalib_skyline_{k}_{i}"),
                        polygon(v),
                    )?;
                }
            }
            Effect::Overhang {
                window,
                depth,
                above,
                overrun,
            } => {
                let w = room.windows.get(*window).ok_or_else(|| {
                    Error::Usage("overhang: the model has no window (glass polygon)".into())
                })?;
                let m = format!("rcalib_overhang_mat_{k}");
                add(&mut s, &mut added, "void", m.clone(), plastic(0.3))?;
                let cu = dot(w.centroid, w.tangent);
                let p = |u: f64, o: f64| {
                    [
                        w.centroid[0] + w.tangent[0] * (u - cu) + w.outward[0] * o,
                        w.centroid[1] + w.tangent[1] * (u - cu) + w.outward[1] * o,
                        w.head + above,
                    ]
                };
                let (u0, u1) = (w.span.0 - overrun, w.span.1 + overrun);
                let v = vec![
                    p(u0, 0.001),
                    p(u1, 0.001),
                    p(u1, 0.001 + depth),
                    p(u0, 0.001 + depth),
                ];
                add(
                    &mut s,
                    &mut added,
                    &m,
                    format!("rcalib_overhang_{k}"),
                    polygon(v),
                )?;
            }
            Effect::LocalObstruction { .. } | Effect::Furniture { .. } => {
                if let Effect::LocalObstruction {
                    sensors: g,
                    fraction,
                } = e
                {
                    // The reason it cannot be placed (no sensors, no window).
                    local_panel(room, sensors, g, *fraction)?;
                }
                let slab = super::effects::local::slab_in(e, room, sensors).ok_or_else(|| {
                    Error::Usage("local-obstruction: the model has no window".into())
                })?;
                let mat = format!("rcalib_local_mat_{k}");
                add(
                    &mut s,
                    &mut added,
                    "void",
                    mat.clone(),
                    plastic(super::effects::local::REFLECTANCE),
                )?;
                for (i, face) in slab.faces().into_iter().enumerate() {
                    add(
                        &mut s,
                        &mut added,
                        &mat,
                        format!("rcalib_local_{k}_{i}"),
                        polygon(face),
                    )?;
                }
            }
            Effect::SensorFault { .. } => {}
            Effect::Tint {
                scale,
                slope,
                curvature,
            } => s = super::effects::tint::tinted_scene(&s, *scale, *slope, *curvature)?,
        }
    }
    let mut out = String::new();
    out.push_str("# Model calibrated by rcalib apply. Changes:\n");
    for n in &notes {
        out.push_str(&format!("#   {n}\n"));
    }
    for line in why.lines().filter(|l| !l.trim().is_empty()) {
        out.push_str(&format!("# Why: {line}\n"));
    }
    out.push_str("# Materials changed in place; added objects are at the end.\n\n");
    let n_orig = s.objects.len() - added.objects.len();
    let orig = Scene {
        objects: s.objects[..n_orig].to_vec(),
        directives: s.directives.clone(),
    };
    out.push_str(&orig.to_string());
    out.push('\n');
    if !added.objects.is_empty() {
        out.push_str("\n# --- added by rcalib apply (see the header) ---\n");
        out.push_str(&added.to_string());
        out.push('\n');
    }
    Ok(out)
}

/// What the changes note says about materials `scale` takes beyond `cap` (where
/// [`scaled_scene`] clamps): the comment must say what was written, not only what was
/// asked (issue #19: walls:1e300 wrote 0.95 under a comment saying x1e300).
fn capped(
    scene: &Scene,
    selected: impl Fn(&str, &Primitive) -> bool,
    scale: f64,
    cap: f64,
) -> Vec<String> {
    scene
        .objects
        .iter()
        .filter(|o| selected(&o.id, &o.kind))
        .filter_map(|o| {
            let values = match &o.kind {
                Primitive::Plastic { color, .. }
                | Primitive::Metal { color, .. }
                | Primitive::Trans { color, .. } => color,
                Primitive::Glass { transmissivity, .. } => transmissivity,
                _ => return None,
            };
            let top = values.iter().copied().fold(0.0, f64::max);
            (top * scale > cap).then(|| {
                format!(
                    "  {}: {top:.3} x {scale:.3} = {:.3}, written as {cap} (the cap)",
                    o.id,
                    top * scale
                )
            })
        })
        .collect()
}

/// Centre of the windows in plan (area weighted; the sensors' centroid if none) and the
/// mean window-centre height.
pub(crate) fn window_centre(room: &Room, sensors: &[Sensor]) -> ([f64; 3], f64) {
    let a: f64 = room.windows.iter().map(|w| w.area).sum();
    if a > 0.0 {
        let c = room.windows.iter().fold([0.0; 3], |c, w| {
            let f = w.area / a;
            [
                c[0] + w.centroid[0] * f,
                c[1] + w.centroid[1] * f,
                c[2] + w.centroid[2] * f,
            ]
        });
        (c, c[2])
    } else {
        (super::room::sensor_centroid(sensors), 1.5)
    }
}

/// The panel `rcalib apply` writes for a local obstruction: a box 0.1 m thick from the
/// floor to `top`, between the group's sensors and their nearest window, across the group's
/// extent along the wall plus 0.4 m each side. Coordinates of that window: `u` along its
/// tangent, `d` depth into the room ([`super::room::Window::depth_of`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Panel {
    pub window: usize,
    pub u: (f64, f64),
    pub d: (f64, f64),
    pub top: f64,
}

/// The panel in front of `group` that blocks about `fraction` of the window's elevation span
/// seen from the sensors.
pub fn local_panel(
    room: &Room,
    sensors: &[Sensor],
    group: &[usize],
    fraction: f64,
) -> Result<Panel> {
    let pts: Vec<[f64; 3]> = group
        .iter()
        .filter_map(|&i| sensors.get(i).map(|s| s.ray.org))
        .collect();
    if pts.is_empty() {
        return Err(Error::Usage("local-obstruction: no sensors".into()));
    }
    let (wi, w) = room
        .windows
        .iter()
        .enumerate()
        .min_by(|a, b| {
            a.1.depth_of(pts[0])
                .abs()
                .total_cmp(&b.1.depth_of(pts[0]).abs())
        })
        .ok_or_else(|| Error::Usage("local-obstruction: the model has no window".into()))?;
    let depths: Vec<f64> = pts.iter().map(|p| w.depth_of(*p)).collect();
    let us: Vec<f64> = pts.iter().map(|p| dot(*p, w.tangent)).collect();
    let zs = pts.iter().map(|p| p[2]).sum::<f64>() / pts.len() as f64;
    let dmin = depths.iter().copied().fold(f64::INFINITY, f64::min);
    let dmean = depths.iter().sum::<f64>() / depths.len() as f64;
    let gap = 0.35_f64.min(dmin * 0.5);
    let e_lo = ((w.sill - zs) / dmean).atan();
    let e_hi = ((w.head - zs) / dmean).atan();
    let e_c = e_lo + fraction.clamp(0.0, 1.0) * (e_hi - e_lo);
    let top = (zs + gap * e_c.tan()).max(zs + 0.05);
    let u = (
        us.iter().copied().fold(f64::INFINITY, f64::min) - 0.4,
        us.iter().copied().fold(f64::NEG_INFINITY, f64::max) + 0.4,
    );
    // Between depth dmin - gap - 0.1 and dmin - gap (towards the window).
    let d = ((dmin - gap - 0.1).max(0.05), (dmin - gap).max(0.1));
    Ok(Panel {
        window: wi,
        u,
        d,
        top,
    })
}

/// Readings with the sensor-fault factors divided out (other effects leave them alone).
pub fn correct_readings(readings: &[Reading], ids: &[String], effects: &[Effect]) -> Vec<Reading> {
    let mut out = readings.to_vec();
    for e in effects {
        if let Effect::SensorFault { factors } = e {
            for (s, f) in factors {
                let Some(id) = ids.get(*s) else { continue };
                for r in out.iter_mut().filter(|r| &r.sensor == id) {
                    r.value /= f;
                }
            }
        }
    }
    out
}
