//! Reconstruction of a room from a laser scan (`rrecon`): planes, watertight shell, windows
//! (issue 9; seed chapter 4, a GLoD0 model: walls, floor, ceiling, windows).
//!
//! Pipeline, in the seed's order: preprocessing (crop, voxel down-sampling to ~100,000 points,
//! statistical outliers, PCA normals over 16 neighbours facing the scanner) -> efficient
//! RANSAC planes (Schnabel et al. 2007, seed Table 4.2 parameters) -> a watertight shell from
//! the plane arrangement (PolyFit's hypothesis and data-fit/coverage selection, here as an
//! inside/outside labelling of the arrangement's cells solved exactly by a minimum cut, which
//! makes every edge join exactly two faces by construction) -> windows per wall from gaps in
//! the Delaunay triangulation of its points, told from occlusion shadows by the stations'
//! lines of sight (Adán & Huber 2011: open, occluded or unseen), ranked, regularised
//! (rectangles, else a symmetric outline), cut out of the wall as hole-free pieces, with
//! reveals and glazing (flush where no reveal was seen) -> `.rad` and a JSON summary. [`simulate`] and [`rooms`] provide scans of known rooms; [`eval`] measures
//! the result against them.
//!
//! ```
//! use rdaylight_recon::{ReconParams, reconstruct, openings::Selection, rooms::RoomSpec};
//! use rdaylight_recon::simulate::{ScanOptions, scan};
//! let room = RoomSpec::named("rect").unwrap();
//! let opts = ScanOptions { stations: room.stations.clone(), resolution: 1.0, ..Default::default() };
//! let cloud = scan(&room.scene()?, &opts)?;
//! let params = ReconParams { target_points: 20_000, ..Default::default() };
//! let r = reconstruct(cloud, &params, &Selection::Auto)?;
//! assert!(r.watertight.is_closed());
//! assert_eq!(r.model.faces.len(), 6);
//! # Ok::<(), rdaylight_base::Error>(())
//! ```
//!
//! | module | concept |
//! |---|---|
//! | [`arrangement`] | convex cells and facets of the plane arrangement (PolyFit hypotheses) |
//! | [`cloud`] | [`PointCloud`], bounds, the empty / non-finite / unit checks |
//! | [`eval`] | Chamfer / Hausdorff to a known model, window errors |
//! | [`mincut`] | exact binary labelling by s-t min cut (Kolmogorov & Zabih 2004) |
//! | [`model`] | shell faces + openings -> hole-free polygons, reveals, glazing; watertightness |
//! | [`preprocess`] | crop, voxel down-sampling, outlier removal, PCA normals (k-d tree), stations' angular steps |
//! | [`ransac`] | efficient RANSAC planes (Schnabel et al. 2007; seed Table 4.2 defaults) |
//! | [`radout`] | polygons -> `.rad` with the seed's default materials (or a materials file) |
//! | [`review`] | SVG per wall with numbered candidates for `--windows` |
//! | [`rooms`] | the known test rooms (rect, L, slanted, arched, cluttered; flush-glazed `flush`, `flushl`) |
//! | [`run`] | the `rrecon` commands as typed configurations and one call each |
//! | [`shell`] | watertight shell: inside/outside cells by exact min cut, facets merged per plane |
//! | [`simulate`] | laser scanner simulator (stations, resolution, range noise, glass, stray returns) |
//! | [`visibility`] | lines of sight from the stations: clutter occupancy, open / occluded / unseen |
//! | [`openings`] | window candidates (Delaunay holes), ranking, regularised outlines |
//! | [`pipeline`] | the whole run with timings: [`reconstruct`] |
//! | [`summary`] | the JSON summary (planes, areas, WWR, WFR, timings, candidates) |
//! | [`ply`], [`las`], [`e57`], [`xyz`], [`input`] | point cloud files (nom parsers, errors with line or byte offset) |

use rdaylight_base::error;
use rdaylight_formats::scene;
use rdaylight_physics::{geometry, material};

pub mod arrangement;
pub mod cloud;
pub mod e57;
pub mod eval;
pub mod input;
pub mod las;
pub mod mincut;
pub mod model;
pub mod openings;
pub mod pipeline;
pub mod ply;
pub mod preprocess;
pub mod radout;
pub mod ransac;
pub mod review;
pub mod rooms;
pub mod run;
pub mod shell;
pub mod simulate;
pub mod summary;
pub mod visibility;
pub mod xyz;

pub use cloud::{Bounds, PointCloud};
pub use input::read_cloud;
pub use pipeline::{ReconParams, Reconstruction, reconstruct, reconstruct_reporting};
