//! # rdaylight-base: the lowest layer
//!
//! What every other layer shares and nothing in it depends on a higher one:
//!
//! - [`calendar`]: day numbers (Radiance's `jdate` and the 0-based day of a year);
//! - [`error`]: one error type whose user-input errors carry file, line and column;
//! - [`radiometry`]: channel layouts (RGB or N spectral bands) and Radiance's RGB constants;
//! - [`colour`]: colour science (CIE tables, observers, band integrals, melanopic weights);
//! - [`hash`]: fingerprints of caches and checksums (FNV-1a; a word-wide hash for large files);
//! - [`io`]: atomic output (nothing half-written) and stream checks;
//! - [`progress`]: how long work reports how far it got (the tools draw it);
//! - [`stats`]: order statistics (median, percentiles);
//! - [`vec3`]: 3-vectors ([`vec3::Vec3`] and helpers on `[f64; 3]`).
//!
//! The layers above, lowest first: `rdaylight-formats` (Radiance's file formats and the
//! `.rad` scene grammar), `rdaylight-physics` (geometry, materials, skies, the `.cal`
//! language, spectral uplifting), `rdaylight-trace` (the path tracer and its driver), the
//! analyses (`rdaylight-metrics`, `-glare`, `-reflectance`, `-calib`, `-recon`) and the
//! tools (the `rdaylight` crate's binaries). `docs/architecture.md` draws them.

pub mod calendar;
pub mod colour;
pub mod error;
pub mod hash;
pub mod io;
pub mod progress;
pub mod radiometry;
pub mod stats;
pub mod vec3;

pub use error::{Error, Location, Result};
