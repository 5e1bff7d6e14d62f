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
//! | analyses | `rdaylight-metrics`, `-glare`, `-glod`, `-mcop`, `-reflectance`, `-calib`, `-recon` | [`metrics`], [`glare`], [`glod`], [`mcop`], [`uplift`] (pictures, validation), [`calib`], [`recon`] |
//! | tools | this crate | [`cli`] and the binaries in `bin/` |
//!
//! Everything reads and writes Radiance's own formats so that any one tool can replace one
//! stage of an existing Radiance pipeline. `docs/architecture.md` follows one ray from a
//! `.rad` file to a matrix file, file by file.
//!
//! From a scene to one row of daylight coefficients with the typed API (what `rdc -I -m 1`
//! computes per sensor; the tools are thin layers over these calls):
//!
//! ```
//! use rdaylight::formats::sensors::SensorRay;
//! use rdaylight::rdc::{Config, Sampling, Tracer};
//! use rdaylight::scene::{self, LoadOptions};
//!
//! // A grey floor under the open sky.
//! let text = "void plastic grey 0 0 5 .2 .2 .2 0 0\n\
//!             grey polygon floor 0 0 12 -5 -5 0  5 -5 0  5 5 0  -5 5 0\n";
//! let scene = scene::parse_str(text, "floor.rad", std::path::Path::new(""), &LoadOptions::default())?;
//! // Sky coefficients over the 145 Tregenza patches and the ground (146 columns).
//! let config = Config::sky_coefficients(1, Sampling { ab: 2, ad: 1024, ..Sampling::default() });
//! let tracer = Tracer::new(&config, &scene)?;
//! let row = &tracer.compute(&[SensorRay::new([0.0, 0.0, 0.8], [0.0, 0.0, 1.0])])?[0];
//! assert_eq!(row.values.len(), 146 * 3);
//! // Facing up under a sky of unit radiance, the sensor receives pi (W/m2 per W/sr/m2):
//! // the coefficients of the sky patches (columns 1..146, red channel) sum to pi.
//! let sky: f64 = (1..146).map(|p| row.values[p * 3]).sum();
//! assert!((sky - std::f64::consts::PI).abs() < 1e-3 * std::f64::consts::PI, "{sky}");
//! # Ok::<(), rdaylight::Error>(())
//! ```

pub mod cli;

pub use rdaylight_base::{Error, Location, Result, colour, error, io, progress, radiometry, stats};
pub use rdaylight_formats::{bsdf, info, scene};
pub use rdaylight_physics::{calc, geometry, material, sky};
pub use rdaylight_trace::{rdc, trace};

pub use rdaylight_calib as calib;
pub use rdaylight_glare as glare;
pub use rdaylight_glod as glod;
pub use rdaylight_mcop as mcop;
pub use rdaylight_metrics as metrics;
pub use rdaylight_recon as recon;

/// Radiance's file formats (`rdaylight-formats`).
pub mod formats {
    pub use rdaylight_formats::{header, hours, matrix, picture, sensors, shard, view, weather};
}

/// Spectral uplifting: the method (`rdaylight_physics::uplift`) and reflectances recovered
/// from pictures with its validation (`rdaylight-reflectance`).
pub mod uplift {
    pub use rdaylight_physics::uplift::*;
    pub use rdaylight_reflectance::{eval, kriging, mask, photo, plot, proxy, run};
}
