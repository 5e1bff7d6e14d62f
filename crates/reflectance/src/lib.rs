//! # rdaylight-reflectance: reflectances from pictures, and the uplifting validation
//!
//! The analyses of the seed's chapter 5 above the uplifting method
//! (`rdaylight_physics::uplift`):
//!
//! - [`photo`]: Ferwerda's method for ordinary photos (sRGB decoding, chromatic adaptation of
//!   the camera white to equal-energy white, means over [`mask`] regions);
//! - [`proxy`]: the illuminance proxy of Mardaljevic et al. for calibrated HDR pictures and
//!   points of known reflectance, with ordinary [`kriging`] of the illuminance;
//! - [`eval`]: the validation of the uplifting methods on held-out measured spectra
//!   (`docs/uplift-validation.md`), and [`plot`], its per-wavelength error plot.
//! - [`run`]: `ruplift photo`, `proxy` and `validate` as typed configurations and calls.

use rdaylight_base::{Result, colour, error, radiometry};
use rdaylight_formats as formats;
use rdaylight_physics::uplift;

pub mod eval;
pub mod kriging;
pub mod mask;
pub mod photo;
pub mod plot;
pub mod proxy;
pub mod run;
