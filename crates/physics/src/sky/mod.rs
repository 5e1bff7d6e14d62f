//! # Skies: patch layouts, solar position, CIE and Perez sky models
//!
//! Groundwork shared by the daylight-coefficient tracer (`rdc`, which needs the patch layout,
//! patch sampling and native evaluation of `gensky`/`gendaylit` skies) and the sky-matrix
//! generator (`rspecsky`, the `gendaymtx` counterpart).
//!
//! - [`patches`]: Tregenza/Reinhart subdivision, index order exactly as `gendaymtx` and
//!   `reinhart.cal` (`bin_of`, `centre`, `solid_angle`, `sample`).
//! - [`solar`]: solar position as Radiance's `sun.c` (gensky/gendaymtx conventions).
//! - [`efficacy`]: Perez 1990 clearness, brightness and luminous efficacy (irradiance to
//!   illuminance), gendaymtx's handling of radiometric and photometric input.
//! - [`cie`]: gensky's CIE skies and the `skybright.cal` radiance function.
//! - [`perez`]: the Perez all-weather model as `gendaymtx` uses it (one sky vector per time
//!   step) and the `perezlum.cal` radiance function of `gendaylit` skies.
//!
//! - [`gendaylit`]: gendaylit's own Perez implementation (its `perezlum.cal` arguments),
//!   so gendaylit skies can be evaluated natively.
//! - [`matrix`]: gendaymtx's time-series sky matrix (weather file to patch x time steps).
//! - [`pointsky`]: a point-in-time gendaylit sky as Radiance scene text, with glow sources.
//! - [`spectral`]: spectral sky matrices (Perez with CIE daylight spectra).
//! - [`atmosphere`]: Bruneton's precomputed atmospheric scattering with genssky's tables
//!   (cached on disk); [`genssky`]: the point-in-time spectral sky and sun genssky writes;
//!   [`atmosphere_matrix`]: gensdaymtx's physically based spectral sky matrices.
//! - [`specpict`]: the `specpict` sky picture of genssky, evaluated natively.
//! - [`config`]: typed configurations of the three `rspecsky` modes (sky matrix, point-in-time
//!   gendaylit sky, genssky), each validated and written by one call.
//!
//! Coordinates everywhere: +X east, +Y north, +Z zenith; radiance in W sr^-1 m^-2 of
//! Radiance's visible "white" (luminance / 179).

pub mod atmosphere;
pub mod atmosphere_matrix;
pub mod cie;
pub mod config;
pub mod efficacy;
pub mod gendaylit;
pub mod genssky;
pub mod matrix;
pub mod patches;
pub mod perez;
pub mod pointsky;
pub mod solar;
pub mod specpict;
pub mod spectral;

pub use cie::{CieSky, CieSkyDescription, GenskyOptions};
pub use patches::SkyPatches;
pub use perez::{PerezOptions, SkyVector, TimeStep, perez_sky_vector};
pub use solar::SunPosition;
