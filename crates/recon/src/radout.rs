//! Writing a reconstructed (or test) room as a Radiance scene.
//!
//! Materials, named by role: `floor`, `ceiling`, `wall`, `reveal` (grey `plastic`,
//! reflectance 0.5, no specularity) and `glazing` (`glass` whose normal-incidence
//! transmittance is 0.75). These are the seed's evaluation materials (chapter 4: "0.5 ... for
//! opaque surfaces and a transmittance of 0.75 for glazings"), chosen there to isolate
//! geometric error. A materials file (any `.rad` defining some of these names, e.g. from
//! `ruplift`) replaces the defaults it defines.

use super::model::{FaceKind, NamedPolygon, Role};
use crate::error::Result;
use crate::material::glass::transmissivity_from_transmittance;
use crate::scene::{Primitive, Scene};

/// Default opaque reflectance and glazing transmittance (seed chapter 4).
pub const OPAQUE_REFLECTANCE: f64 = 0.5;
pub const GLAZING_TRANSMITTANCE: f64 = 0.75;

/// The material name of a polygon role.
pub fn material_name(role: Role) -> &'static str {
    match role {
        Role::Shell(FaceKind::Floor) => "floor",
        Role::Shell(FaceKind::Ceiling) => "ceiling",
        Role::Shell(FaceKind::Wall) => "wall",
        Role::Reveal => "reveal",
        Role::Glazing => "glazing",
    }
}

/// The scene: materials (defaults unless `overrides` defines them), then the polygons.
pub fn to_scene(polys: &[NamedPolygon], overrides: Option<&Scene>) -> Result<Scene> {
    let mut scene = Scene::default();
    if let Some(o) = overrides {
        scene.objects.extend(o.objects.iter().cloned());
    }
    let grey = vec![OPAQUE_REFLECTANCE; 3];
    for name in ["floor", "ceiling", "wall", "reveal"] {
        if scene.find_modifier(name).is_none() {
            scene.push(
                "void",
                name,
                Primitive::Plastic {
                    color: grey.clone(),
                    spec: 0.0,
                    rough: 0.0,
                },
            )?;
        }
    }
    if scene.find_modifier("glazing").is_none() {
        let tn = transmissivity_from_transmittance(GLAZING_TRANSMITTANCE);
        scene.push(
            "void",
            "glazing",
            Primitive::Glass {
                transmissivity: vec![tn; 3],
                index: None,
            },
        )?;
    }
    for p in polys {
        scene.push(
            material_name(p.role),
            p.name.clone(),
            Primitive::Polygon {
                vertices: p.vertices.iter().map(|v| v.to_array()).collect(),
            },
        )?;
    }
    Ok(scene)
}
