//! # rdaylight: Radiance-compatible daylight tools for existing rooms
//!
//! The library behind the `r*` command-line tools, as one facade over the workspace's layers
//! (lowest first; a crate never depends on one above it, so cycles are compile errors):
//!
//! | layer | crate | modules here |
//! |---|---|---|
//! | base | `rdaylight-base` | [`error`], [`radiometry`], [`colour`], [`io`] |
//! | formats | `rdaylight-formats` | [`formats`], [`scene`], [`info`] |
//! | core physics | `rdaylight-physics` | [`geometry`], [`material`], [`sky`], [`calc`], [`uplift`] (the method) |
//! | tracer | `rdaylight-trace` | [`trace`], [`rdc`] |
//! | analyses | `rdaylight-metrics`, `-glare`, `-reflectance`, `-calib`, `-recon` | [`metrics`], [`glare`], [`uplift`] (pictures, validation), [`calib`], [`recon`] |
//! | tools | this crate | [`cli`] and the binaries in `bin/` |
//!
//! Everything reads and writes Radiance's own formats so that any one tool can replace one
//! stage of an existing Radiance pipeline. `docs/architecture.md` follows one ray from a
//! `.rad` file to a matrix file, file by file.

pub mod cli;

pub use rdaylight_base::{Error, Location, Result, colour, error, io, radiometry, stats};
pub use rdaylight_formats::{info, scene};
pub use rdaylight_physics::{calc, geometry, material, sky};
pub use rdaylight_trace::{rdc, trace};

pub use rdaylight_calib as calib;
pub use rdaylight_glare as glare;
pub use rdaylight_metrics as metrics;
pub use rdaylight_recon as recon;

/// Radiance's file formats (`rdaylight-formats`).
pub mod formats {
    pub use rdaylight_formats::{header, matrix, picture, sensors, view, weather};
}

/// Spectral uplifting: the method (`rdaylight_physics::uplift`) and reflectances recovered
/// from pictures with its validation (`rdaylight-reflectance`).
pub mod uplift {
    pub use rdaylight_physics::uplift::*;
    pub use rdaylight_reflectance::{eval, kriging, mask, photo, plot, proxy, run};
}
