//! Reconstruction of a room from a laser scan (`rrecon`): planes, watertight shell, windows
//! (issue 9; seed chapter 4).
//!
//! | module | concept |
//! |---|---|
//! | [`cloud`] | [`PointCloud`], bounds, the empty / non-finite / unit checks |
//! | [`ply`], [`xyz`], [`input`] | point cloud files (nom parsers, errors with line or byte offset) |

pub mod cloud;
pub mod input;
pub mod ply;
pub mod xyz;

pub use cloud::{Bounds, PointCloud};
pub use input::read_cloud;
