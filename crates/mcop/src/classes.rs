//! # What is uncertain: each tracked material's measured property and its MCoP draws
//!
//! The seed (section 3.3.2, Fig. 3.1-3.2) defines a Material Class of Precision as a normal
//! distribution of the *absolute* error of a measured reflectance or transmittance, centred
//! on the true value, with sigma 0.05, 0.10, 0.15 or 0.20 (the AHR technique's measured
//! errors had sigma 0.18). A draw replaces the model's value `p` by `p + sigma z`, `z`
//! standard normal, per material (or one `z` per surface class, [`Grouping::Class`]).
//!
//! **The property a draw changes** is the photopic value (rounded weights .265/.670/.065)
//! of the part of the material its colour controls, so that scaling the colour by
//! `s = p'/p` (what path re-weighting can do, [`rdaylight_trace::trace::reweight`]) moves
//! the material's measured reflectance or transmittance by exactly `p' - p`:
//!
//! | material | property `p` | bound on `p'` |
//! |---|---|---|
//! | `plastic` | diffuse reflectance `(1 - spec) Y(rgb)` (the white specular part is a finish, not a colour) | `s max(rgb) <= 1` |
//! | `metal`, `mirror` | reflectance `Y(rgb)` (the colour tints both lobes) | `s max(rgb) <= 1` |
//! | `trans` | diffuse albedo `(1 - spec) Y(rgb)` (reflected + transmitted) | `s max(rgb) <= 1` |
//! | `glass` | normal-incidence transmittance `Tn` of the pane, Radiance's glass law with its index | `Tn'` at most the pane's with transmissivity 1 (0.916 at n = 1.52) |
//!
//! **Truncation** (the seed's Fig. 3.2 draws a normal around 0.6 with sigma up to 0.2, so
//! bounds matter for dark and bright materials): [`Truncation::Redraw`] (the default)
//! draws `z` again until `p'` lies in `[0, upper]`, a truncated normal that keeps the
//! distribution's shape inside the bounds (the mean shifts away from a nearby bound);
//! [`Truncation::Clip`] clamps, which piles the tail's probability on the bound. Redrawing
//! stops after [`MAX_REDRAWS`] tries and clamps (a value exactly on a bound with sigma 0.2
//! is accepted half the time, so that never happens in practice).
//!
//! **Seeds.** The `z` of a material (or class) in draw `d` of sigma class `k` comes from a
//! PCG stream seeded by FNV-1a of `(seed, k, d, name)`: the same at every GLoD (common
//! random numbers, so differences between levels are geometry, not luck), independent
//! between sigma classes (as the seed's separate experiments were), and independent of how
//! the draws are split into shards or threads.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use rdaylight_base::hash::Fnv64;
use rdaylight_base::radiometry::RGB_PHOTOPIC_ROUNDED;
use rdaylight_base::{Error, Result};
use rdaylight_formats::scene::{Primitive, Scene};
use rdaylight_glod::Analysis;
use rdaylight_glod::objects::glob;
use rdaylight_glod::points::sample;
use rdaylight_physics::material::glass::{DEFAULT_INDEX, transmittance_from_transmissivity};
use serde::Serialize;

/// Tries before a redraw gives up and clamps.
pub const MAX_REDRAWS: usize = 1000;
/// Largest sigma accepted: an error of 1 is the whole range of a reflectance.
pub const MAX_SIGMA: f64 = 1.0;

/// Reflectance or transmittance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Kind {
    Reflectance,
    Transmittance,
}

/// One tracked material's measured property.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Property {
    pub name: String,
    pub kind: Kind,
    /// The model's value `p` (photopic).
    pub value: f64,
    /// Largest physical `p'`.
    pub upper: f64,
    /// Surface class (`--by class`): glazing, floor, ceiling, walls, furniture, or a user's.
    pub class: String,
    /// Glass: the pane's refractive index (re-simulation rebuilds the pane from `Tn'`).
    pub index: Option<f64>,
}

impl Property {
    /// The colour scale factor that turns `p` into `drawn`.
    pub fn scale(&self, drawn: f64) -> f64 {
        if self.value > 0.0 {
            drawn / self.value
        } else {
            1.0
        }
    }
}

/// Per material or per surface class.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Grouping {
    Material,
    Class,
}

/// What happens to a draw outside the physical bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Truncation {
    Redraw,
    Clip,
}

fn photopic(c: &[f64]) -> f64 {
    let w = RGB_PHOTOPIC_ROUNDED;
    if c.len() == 3 {
        w[0] * c[0] + w[1] * c[1] + w[2] * c[2]
    } else {
        c.iter().sum::<f64>() / c.len().max(1) as f64
    }
}

fn max_of(c: &[f64]) -> f64 {
    c.iter().copied().fold(0.0, f64::max)
}

/// The property of material `name` of `scene` (the last definition of that name, as
/// Radiance's loader lets a later definition shadow an earlier one).
pub fn property(scene: &Scene, name: &str) -> Result<Property> {
    let Some(o) = scene.objects.iter().rev().find(|o| {
        o.id == name
            && matches!(
                o.kind,
                Primitive::Plastic { .. }
                    | Primitive::Metal { .. }
                    | Primitive::Trans { .. }
                    | Primitive::Mirror { .. }
                    | Primitive::Glass { .. }
            )
    }) else {
        return Err(Error::Usage(format!(
            "material '{name}': not a plastic, metal, trans, mirror or glass of the scene"
        )));
    };
    let upper_of = |p: f64, c: &[f64]| {
        let m = max_of(c);
        if m > 0.0 { p / m } else { 0.0 }
    };
    let (kind, value, upper, index) = match &o.kind {
        Primitive::Plastic { color, spec, .. } | Primitive::Trans { color, spec, .. } => {
            let p = (1.0 - spec) * photopic(color);
            (Kind::Reflectance, p, upper_of(p, color), None)
        }
        Primitive::Metal { color, .. } | Primitive::Mirror { color, .. } => {
            let p = photopic(color);
            (Kind::Reflectance, p, upper_of(p, color), None)
        }
        Primitive::Glass {
            transmissivity,
            index,
        } => {
            let n = index.unwrap_or(DEFAULT_INDEX);
            let tn = transmittance_from_transmissivity(photopic(transmissivity), n);
            let upper = transmittance_from_transmissivity(1.0, n);
            (Kind::Transmittance, tn, upper, Some(n))
        }
        _ => unreachable!("filtered above"),
    };
    let kind = match &o.kind {
        Primitive::Trans { trans, .. } if *trans >= 0.5 => Kind::Transmittance,
        _ => kind,
    };
    Ok(Property {
        name: name.to_string(),
        kind,
        value,
        upper,
        class: String::new(),
        index,
    })
}

/// Surface class of every property (see [`Grouping::Class`]): a user's `NAME=GLOB` rules
/// first (on the material name), then glazing for transmitting materials, furniture when
/// most of the material's surfaces (by count) are non-permanent objects of `analysis`, and
/// otherwise by the mean normal of its shell surfaces: floor (facing up), ceiling (down) or
/// walls. An exterior ground plane is "floor"; name it with a rule to keep it apart.
pub fn assign_classes(
    props: &mut [Property],
    scene: &Scene,
    analysis: &Analysis,
    rules: &[(String, String)],
) {
    let shell: std::collections::HashSet<usize> = analysis.shell.iter().copied().collect();
    for p in props.iter_mut() {
        if let Some((class, _)) = rules.iter().find(|(_, g)| glob(g, &p.name)) {
            p.class.clone_from(class);
            continue;
        }
        if p.kind == Kind::Transmittance {
            p.class = "glazing".into();
            continue;
        }
        let (mut in_shell, mut outside, mut nz) = (0usize, 0usize, 0.0);
        for (i, o) in scene.objects.iter().enumerate() {
            let Some(m) = scene.material_of(i) else {
                continue;
            };
            if scene.objects[m].id != p.name
                || o.class() == rdaylight_formats::scene::Class::Material
            {
                continue;
            }
            if shell.contains(&i) {
                in_shell += 1;
                if let Some(s) = sample(&o.kind) {
                    nz +=
                        s.normals.iter().map(|n| n[2]).sum::<f64>() / s.normals.len().max(1) as f64;
                }
            } else {
                outside += 1;
            }
        }
        let mean_nz = if in_shell > 0 {
            nz / in_shell as f64
        } else {
            0.0
        };
        p.class = if outside > in_shell {
            "furniture".into()
        } else if mean_nz > 0.7 {
            "floor".into()
        } else if mean_nz < -0.7 {
            "ceiling".into()
        } else {
            "walls".into()
        };
    }
}

/// One MCoP: its sigma and how draws are made.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Mcop {
    pub sigma: f64,
    pub truncation: Truncation,
    pub grouping: Grouping,
}

/// Standard normal deviate by the Box-Muller transform (Box & Muller 1958, Ann. Math.
/// Stat. 29: `sqrt(-2 ln u1) cos(2 pi u2)`), one per call (the sine half is dropped so that
/// a stream's n-th value never depends on how many were taken before in pairs).
fn normal(rng: &mut Pcg64) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>(); // (0, 1]: ln never sees 0
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

fn stream(seed: u64, class_index: usize, draw: usize, name: &str) -> Pcg64 {
    let mut h = Fnv64::new();
    h.write(&seed.to_le_bytes());
    h.write(&(class_index as u64).to_le_bytes());
    h.write(&(draw as u64).to_le_bytes());
    h.write(name.as_bytes());
    Pcg64::seed_from_u64(h.finish())
}

impl Mcop {
    /// The drawn values `p'` of every property for draw `draw` of sigma class number
    /// `class_index` (see the module documentation for seeds and truncation).
    pub fn draw(&self, props: &[Property], seed: u64, class_index: usize, draw: usize) -> Vec<f64> {
        match self.grouping {
            Grouping::Material => props
                .iter()
                .map(|p| {
                    let mut rng = stream(seed, class_index, draw, &p.name);
                    self.one(&mut rng, std::slice::from_ref(p))[0]
                })
                .collect(),
            Grouping::Class => {
                let mut out = vec![0.0; props.len()];
                let mut classes: Vec<&str> = props.iter().map(|p| p.class.as_str()).collect();
                classes.sort_unstable();
                classes.dedup();
                for c in classes {
                    let members: Vec<Property> =
                        props.iter().filter(|p| p.class == c).cloned().collect();
                    let mut rng = stream(seed, class_index, draw, &format!("class:{c}"));
                    let v = self.one(&mut rng, &members);
                    let mut it = v.into_iter();
                    for (o, p) in out.iter_mut().zip(props) {
                        if p.class == c {
                            *o = it.next().unwrap_or(p.value);
                        }
                    }
                }
                out
            }
        }
    }

    /// One `z` shared by `members`, redrawn until all are in bounds (or clamped).
    fn one(&self, rng: &mut Pcg64, members: &[Property]) -> Vec<f64> {
        let inside = |z: f64| {
            members
                .iter()
                .all(|p| (0.0..=p.upper).contains(&(p.value + self.sigma * z)))
        };
        let mut z = normal(rng);
        if self.truncation == Truncation::Redraw {
            let mut tries = 1;
            while !inside(z) && tries < MAX_REDRAWS {
                z = normal(rng);
                tries += 1;
            }
        }
        members
            .iter()
            .map(|p| (p.value + self.sigma * z).clamp(0.0, p.upper))
            .collect()
    }
}

/// Parse a sigma list (`0.05,0.10,0.15,0.20`): each in (0, [`MAX_SIGMA`]], at most 64.
pub fn parse_sigmas(s: &str) -> Result<Vec<f64>> {
    let mut out = Vec::new();
    for part in s.split(',') {
        let v: f64 = part.trim().parse().map_err(|_| {
            Error::Usage(format!(
                "--sigmas: '{part}' is not a number; give e.g. 0.05,0.10,0.15,0.20"
            ))
        })?;
        if !(v > 0.0 && v <= MAX_SIGMA) {
            return Err(Error::Usage(format!(
                "--sigmas: {v} is outside (0, {MAX_SIGMA}]; a sigma is an absolute reflectance error"
            )));
        }
        out.push(v);
    }
    if out.len() > 64 {
        return Err(Error::Usage(format!(
            "--sigmas: {} classes, at most 64",
            out.len()
        )));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn prop(name: &str, value: f64, upper: f64, class: &str) -> Property {
        Property {
            name: name.into(),
            kind: Kind::Reflectance,
            value,
            upper,
            class: class.into(),
            index: None,
        }
    }

    #[test]
    fn draws_have_the_class_sigma_and_respect_bounds() {
        let props = [
            prop("wall", 0.5, 1.0, "walls"),
            prop("dark", 0.05, 1.0, "floor"),
        ];
        for truncation in [Truncation::Redraw, Truncation::Clip] {
            let m = Mcop {
                sigma: 0.1,
                truncation,
                grouping: Grouping::Material,
            };
            let v: Vec<Vec<f64>> = (0..4000).map(|d| m.draw(&props, 7, 0, d)).collect();
            let wall: Vec<f64> = v.iter().map(|x| x[0]).collect();
            let mean = wall.iter().sum::<f64>() / wall.len() as f64;
            let sd = (wall.iter().map(|x| (x - mean).powi(2)).sum::<f64>()
                / (wall.len() - 1) as f64)
                .sqrt();
            // 0.5 +- 0.1 is 5 sigma from both bounds: a plain normal (standard errors of the
            // mean and sd at n = 4000: 0.0016 and 0.0011).
            assert!(
                (mean - 0.5).abs() < 0.005 && (sd - 0.1).abs() < 0.004,
                "{mean} {sd}"
            );
            assert!(v.iter().all(|x| x[1] >= 0.0 && x[1] <= 1.0));
            let at_zero = v.iter().filter(|x| x[1] == 0.0).count();
            match truncation {
                // Clipping piles P(z < -0.5) = 31 % on the bound; redrawing puts none there.
                Truncation::Clip => assert!((1000..1500).contains(&at_zero), "{at_zero}"),
                Truncation::Redraw => assert_eq!(at_zero, 0),
            }
        }
    }

    #[test]
    fn draws_are_deterministic_per_seed_and_shared_within_a_class() {
        let props = [
            prop("a", 0.5, 1.0, "walls"),
            prop("b", 0.3, 1.0, "walls"),
            prop("c", 0.3, 1.0, "floor"),
        ];
        let m = Mcop {
            sigma: 0.2,
            truncation: Truncation::Redraw,
            grouping: Grouping::Class,
        };
        let x = m.draw(&props, 1, 2, 3);
        assert_eq!(x, m.draw(&props, 1, 2, 3));
        assert_ne!(x, m.draw(&props, 2, 2, 3));
        // One z per class: a and b moved by the same amount, c by another.
        assert!(((x[0] - 0.5) - (x[1] - 0.3)).abs() < 1e-12);
        assert!(((x[2] - 0.3) - (x[1] - 0.3)).abs() > 1e-9);
        // Per material, a material's draw does not depend on the others present.
        let pm = Mcop {
            grouping: Grouping::Material,
            ..m
        };
        assert_eq!(
            pm.draw(&props, 1, 2, 3)[2],
            pm.draw(&props[2..], 1, 2, 3)[0]
        );
    }

    #[test]
    fn sigma_lists_are_checked() {
        assert_eq!(parse_sigmas("0.05, 0.2").unwrap(), [0.05, 0.2]);
        assert!(parse_sigmas("0").is_err());
        assert!(parse_sigmas("x").unwrap_err().to_string().contains("'x'"));
    }
}
