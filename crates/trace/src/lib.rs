//! # rdaylight-trace: the tracer (layer 3)
//!
//! - [`trace`]: the Monte Carlo path tracer (daylight coefficients, irradiance, radiance,
//!   path re-weighting records);
//! - [`rdc`]: its driver, the library behind the `rdc` tool (rcontrib / rtrace -I / rpict
//!   counterpart): typed configuration, parallel deterministic sampling loops, output.
//!
//! Depends on the formats and physics layers only; the analyses call it directly.

use rdaylight_base::{error, io, progress, radiometry};
use rdaylight_formats as formats;
use rdaylight_formats::scene;
use rdaylight_physics::{calc, geometry, material, sky};

pub mod rdc;
pub mod trace;
