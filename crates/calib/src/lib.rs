//! # Calibration against field measurements (`rcalib`, issue 7)
//!
//! Compare a model with measured illuminances, show where it fails, name the missing
//! physical effect, add it to the model and watch the error fall.
//!
//! | module | concept |
//! |---|---|
//! | [`csv`] | the one CSV reader of readings, spectral readings and response curves |
//! | [`measurements`] | the long-form readings CSV (`month,day,hour,sensor,lux`) and its checks |
//! | [`inputs`] | sensors from `.pts` or CSV with ids |
//! | [`simulate`] | five-phase-style simulation of the measured steps through `rdc` coefficients |
//! | [`cache`] | coefficient cache on disk, keyed by a hash of scene, sensors and settings |
//! | [`room`] | windows and surface classes of the model |
//! | [`model`] | components + sensitivities + observations; prediction with effects |
//! | [`stats`] | MBE_rel, RMSE_rel, sigma_rel (seed Eq. 6.2-6.4), MAE (6.1), Pearson r |
//! | [`score`] | noise-aware BIC (random per-sensor offsets) |
//! | [`effects`] | the candidate missing effects, each with its fit |
//! | [`fit`] | scoring effect lists against readings |
//! | [`explain`] | ranking and greedy forward selection |
//! | [`apply`] | writing the model with an effect added as geometry or materials |
//! | [`tmscan`] | the seed's chapter-6 transmittance option scan |
//! | [`compare`] | per-sensor / per-step statistics and figure data |
//! | [`svg`], [`report`] | inline-SVG figures, the HTML report, JSON and text summaries |
//! | [`cases`] | hidden-effect test cases: truth rooms, climates, noisy readings |
//! | [`run`] | the `rcalib` commands as typed configurations and one call each |
//! | [`session`] | files -> model, shared by every command |
//! | [`spectral`] | spectral readings (18-channel sensors): the seed's chapter-6 workflow, Table 6.4, the glazing tint (issue 8) |

use rdaylight_base::{colour, error, progress, radiometry};
use rdaylight_formats as formats;
use rdaylight_formats::scene;
use rdaylight_metrics as metrics;
use rdaylight_physics::{material, sky};
use rdaylight_trace::{rdc, trace};

pub mod apply;
pub mod cache;
pub mod cases;
pub mod compare;
pub mod csv;
pub mod effects;
pub mod explain;
pub mod fit;
pub mod inputs;
pub mod measurements;
pub mod model;
pub mod report;
pub mod room;
pub mod run;
pub mod score;
pub mod session;
pub mod simulate;
pub mod spectral;
pub mod stats;
pub mod svg;
pub mod tmscan;
