//! # Scene intake: loading the `.rad` inputs for `rdc`
//!
//! [`load`] reads the scene inputs (files, `-`, `!command`, [`crate::scene::load`]) and
//! refuses, with its location, any primitive type outside [`SUPPORTED`], including ones no
//! surface uses (an unknown modifier is more likely a typo than something to skip).
//!
//! Everything at infinity (suns, sky and ground glows with their `skybright.cal` /
//! `perezlum.cal` patterns) is evaluated in one place, [`crate::trace::sources`], which the
//! scene compiler ([`crate::trace::Renderable::compile`]) fills; point-in-time runs check
//! there that the scene has a sky at all.

use crate::error::Result;
use crate::scene::{LoadOptions, Scene};

/// Primitive types `rdc` understands (everything else is reported with its location by
/// [`Scene::check_supported`]); the scene compiler refines what it can trace (local light
/// sources, alternate materials, patterns on surfaces are refused there).
pub const SUPPORTED: &[&str] = &[
    "source",
    "glow",
    "light",
    "brightfunc",
    "polygon",
    "sphere",
    "bubble",
    "ring",
    "cone",
    "cup",
    "cylinder",
    "tube",
    // Flattened into polygons and the octree's surfaces (`crate::trace::expand`).
    "mesh",
    "instance",
    "plastic",
    "metal",
    "trans",
    "glass",
    "mirror",
    "BSDF",
    "aBSDF",
    "illum",
    "spectrum",
    "specfile",
    "specpict",
    // Function-file patterns (`crate::calc`): on skies per ray, elsewhere when constant.
    "colorfunc",
    "specfunc",
    "specdata",
];

/// Load scene inputs (file paths, `-`, `!command`) and check their primitive types.
pub fn load(inputs: &[String], opts: &LoadOptions) -> Result<Scene> {
    let scene = crate::scene::load(inputs, opts)?;
    scene.check_supported(SUPPORTED)?;
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_types_are_reported_with_their_line() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.rad");
        std::fs::write(
            &p,
            "void glow g 0 0 4 1 1 1 0\nvoid antimatter a 1 void 0 0\n",
        )
        .unwrap();
        let opts = LoadOptions {
            allow_exec: false,
            command_env: Vec::new(),
        };
        let e = load(&[p.to_string_lossy().into_owned()], &opts)
            .unwrap_err()
            .to_string();
        assert!(e.contains("t.rad:2") && e.contains("'antimatter'"), "{e}");
    }
}
