//! # `rdc`: the ray-tracing core's driver (rcontrib / rtrace -I / rpict counterpart)
//!
//! Everything around the light transport, behind one narrow trait so that the path tracer
//! (after `geometry` and `material`) drops in without touching the rest:
//!
//! | module | concept |
//! |---|---|
//! | [`config`] | the typed configuration: sampling (Radiance's letters and meanings, rcontrib's defaults, presets), channels, target, seeds |
//! | [`intake`] | scene loading and the primitive types rdc accepts (the sky is evaluated by `crate::trace::sources`) |
//! | [`tracer`] | the seam: [`tracer::Estimator`], [`tracer::Tally`], [`tracer::Mode`], seeding and stratification |
//! | [`traced`] | the estimator: the path tracer of `crate::trace` behind the seam (and `--reweight` records) |
//! | [`run`] | [`Tracer`] (a scene compiled for a [`Config`]) and the parallel, deterministic, streaming driver of the `rdc` tool (sensors and pictures, [`Run`]) |
//! | [`flux`] | sender and receiver surfaces (`--flux`, rfluxmtx): `#@rfluxmtx` bases, binning, sender sampling |
//! | [`output`] | headers (rcontrib's order), ascii/float/double/RGBE rows, pictures, `--se-out` |
//!
//! Modes (radiance-notes.md 6.2, 6.4, 6.6, 11.1):
//!
//! ```text
//! rdc [opts] -I -m MF scene.rad < sensors.pts > dc.mtx      sky coefficients, rows = sensors,
//!                                                           columns = 144 MF^2 + 2 (ground first)
//! rdc -I --direct -m MF ...                                 direct-only coefficients (C_dcd)
//! rdc -I --suns MF|site.wea ...                             sun coefficients (C_ds)
//! rdc -I scene.rad sky.rad < sensors.pts                    point-in-time irradiance (rtrace -I -h)
//! rdc --flux -I -ab 3 - window.rad room.rad < sensors.pts  view matrix V (rfluxmtx): rows =
//!                                                           sensors, columns = Klems patches
//! rdc --flux -c 1000 window.rad sky.rad room.rad            daylight matrix D: rows = window
//!                                                           patches, columns = sky patches
//! rdc -vta ... -x X -y Y scene.rad sky.rad > view.hdr       picture (rpict); with -m MF: per-pixel
//!                                                           coefficients, rows = pixels
//! ```
//!
//! Light transport is [`traced::Traced`]: the path tracer of `crate::trace` behind the
//! [`tracer::Estimator`] seam; this module owns options, sampling loops, seeding and output.

pub mod config;
pub mod flux;
pub mod intake;
pub mod output;
pub mod run;
pub mod traced;
pub mod tracer;

pub use config::{
    Adaptive, Config, Flux, Preset, Reweight, Sampling, SenderInput, SunSource, Target,
};
pub use run::{RecordResult, Run, Tracer};
pub use tracer::{Estimator, Mode, Quantity, Query, Tally};
