//! # rdaylight: Radiance-compatible daylight tools for existing rooms
//!
//! The library behind the `r*` command-line tools. Everything reads and writes Radiance's own
//! formats so that any one tool can replace one stage of an existing Radiance pipeline.
//!
//! - [`formats`]: Radiance's file formats (information header, matrices, pictures, views,
//!   sensor rays, weather), each parsed with `nom`, streaming where files get large, with
//!   errors that name file, line and what was expected.
//! - [`scene`]: the `.rad` scene description: grammar, inline `!commands`, typed primitives.
//! - [`sky`]: sky patch layouts, solar position, CIE (gensky) and Perez (gendaymtx) skies.
//! - [`material`]: Radiance's materials for the path tracer (Ward, glass, mirror, sources).
//! - [`glare`]: glare from fisheye/perspective pictures (DGP, DGI, UGR, ...; evalglare 3.x).
//! - [`metrics`]: annual daylight metrics (TAI, UDI, DA, sDA, ASE), Appendix-A errors, maps.
//! - [`rdc`]: the ray-tracing driver (rcontrib / rtrace -I / rpict counterpart) and its
//!   tracer seam.
//! - [`radiometry`]: channel layouts (RGB or N spectral bands) shared by every buffer.
//! - [`info`]: summaries of any file (what `rinfo` prints).
//! - [`geometry`]: shapes, rays, polygon triangulation and the scene BVH for the ray tracer.
//! - [`trace`]: the Monte Carlo path tracer (daylight coefficients, irradiance, radiance).
//! - [`uplift`]: spectral uplifting (RGB -> smooth bounded reflectance; Jakob & Hanika and a
//!   learned basis), its validation on measured spectra and melanopic effect.
//! - [`calib`]: calibration against measurements (`rcalib`).
//! - [`recon`]: laser scan to a watertight room (`rrecon`).
//! - [`cli`]: what the thin binaries in `bin/` share (exit codes, progress, atomic output).

pub mod calib;
pub mod cal;
pub mod cli;
pub mod error;
pub mod formats;
pub mod geometry;
pub mod glare;
pub mod info;
pub mod material;
pub mod metrics;
pub mod radiometry;
pub mod rdc;
pub mod recon;
pub mod scene;
pub mod sky;
pub mod trace;
pub mod uplift;

pub use error::{Error, Location, Result};
