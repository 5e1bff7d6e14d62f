//! # rdaylight-physics: core physics (layer 2)
//!
//! What light does in a room, independent of how it is sampled:
//!
//! - [`geometry`]: shapes, rays, polygon triangulation and the scene BVH;
//! - [`material`]: Radiance's materials (Ward plastic/metal/trans, glass, mirror, light
//!   sources), their sampling and spectral patterns;
//! - [`sky`]: sky patch layouts, solar position, CIE, Perez (gendaylit, gendaymtx) and
//!   physically based (genssky, gensdaymtx) skies;
//! - [`calc`]: Radiance's function-file language (`.cal`) and the patterns written in it;
//! - [`uplift`]: RGB to smooth reflectance spectra (the method; the colour science under it
//!   is `rdaylight_base::colour`).
//!
//! Depends on `rdaylight-base` and `rdaylight-formats` only.

use rdaylight_base::{Error, Location, Result, colour, error, io, progress, radiometry, vec3};
use rdaylight_formats as formats;
use rdaylight_formats::scene;

pub mod calc;
pub mod geometry;
pub mod material;
pub mod sky;
pub mod uplift;
