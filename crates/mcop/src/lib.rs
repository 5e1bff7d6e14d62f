//! # rdaylight-mcop: Material Classes of Precision (the seed's chapter 3)
//!
//! How far do annual daylight results move when every material's reflectance and
//! transmittance is only known to a measurement's precision? The seed answered it for six
//! rooms with 500 full simulations per GLoD x MCoP cell (60,000 in all). Here each GLoD is
//! traced **once** with path re-weighting records and every draw re-weights the recorded
//! paths (`rdaylight_trace::trace::reweight`), which costs microseconds per draw for TAI
//! and milliseconds for hourly metrics instead of a re-simulation.
//!
//! | module | concept |
//! |---|---|
//! | [`classes`] | which property each material has, MCoP draws, truncation, surface classes |
//! | [`engine`] | one traced level: TAI and hourly illuminance of a draw |
//! | [`stats`] | summaries, D'Agostino-Pearson K2, Kolmogorov-Smirnov against the fitted normal |
//! | [`study`] | the GLoD x MCoP experiment, shards and their exact merge |
//! | [`report`] | the seed-shaped tables, box plots, KS curves, spread maps |
//! | [`validate`] | re-weighting against brute-force re-simulation with the drawn materials |

pub mod classes;
pub mod engine;
pub mod report;
pub mod stats;
pub mod study;
pub mod validate;

pub use classes::{Grouping, Kind, Mcop, Property, Truncation};
pub use engine::LevelModel;
pub use study::{Prepared, Results, StudyConfig, draws, prepare, reduce};
