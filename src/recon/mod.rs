//! Reconstruction of a room from a laser scan (`rrecon`): planes, watertight shell, windows
//! (issue 9; seed chapter 4).
//!
//! | module | concept |
//! |---|---|
//! | [`cloud`] | [`PointCloud`], bounds, the empty / non-finite / unit checks |
//! | [`model`] | shell faces + openings -> hole-free polygons, reveals, glazing; watertightness |
//! | [`preprocess`] | crop, voxel down-sampling, outlier removal, PCA normals (k-d tree) |
//! | [`ransac`] | efficient RANSAC planes (Schnabel et al. 2007; seed Table 4.2 defaults) |
//! | [`radout`] | polygons -> `.rad` with the seed's default materials (or a materials file) |
//! | [`rooms`] | the known test rooms (rect, L, slanted, arched, cluttered) |
//! | [`simulate`] | laser scanner simulator (stations, resolution, range noise, glass) |
//! | [`ply`], [`xyz`], [`input`] | point cloud files (nom parsers, errors with line or byte offset) |

pub mod cloud;
pub mod input;
pub mod model;
pub mod ply;
pub mod preprocess;
pub mod radout;
pub mod ransac;
pub mod rooms;
pub mod simulate;
pub mod xyz;

pub use cloud::{Bounds, PointCloud};
pub use input::read_cloud;
