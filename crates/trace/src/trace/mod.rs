//! # Monte Carlo path tracing core (the engine behind `rdc`)
//!
//! Radiance's `rcontrib -I+` (daylight coefficients) and `rtrace -I -aa 0 -as 0` (point
//! values) estimate the same path integral by pure Monte Carlo (no irradiance cache, no
//! ambient super-sampling); this module estimates it with a path tracer that follows
//! Radiance's rules for path depth (`-ab`, `-lw`, `-lr`, `-av`) and for which rays see which
//! sources, so the expectations agree (radiance-notes.md sections 5, 6, 11, 12).
//!
//! | module | concept |
//! |---|---|
//! | [`compile`] | [`Renderable::compile`]: parsed scene -> shapes, materials, BVH, distant sources |
//! | [`compiled`] | compiled scene files (`rdc --compile`): the geometry as built, read back for later runs |
//! | [`expand`] | `mesh` (compiled mesh or `.obj`) and `instance` (octree) primitives flattened into surfaces, materials resolved as Radiance does |
//! | [`reweight`] | path re-weighting records: coefficients as polynomials in material reflectances, their file and [`reweight::Reweighting::apply`] |
//! | [`sources`] | distant `source`s: the sun (`light`), glow skies with `skybright.cal` / `perezlum.cal` patterns, Radiance's `sourcehit` |
//! | [`portals`] | window panes as portals: next-event estimation of sky light through glazing, combined with the material's sample by multiple importance sampling |
//! | [`integrator`] | [`Renderable::dc_sensor`], [`Renderable::irradiance`], [`Renderable::radiance`] |
//!
//! Randomness comes only from the `&mut impl rand::Rng` each call takes, so a driver that
//! seeds one generator per sensor (or pixel) from a run seed gets identical results whatever
//! the thread count. A [`Renderable`] is immutable and `Sync`: share it between threads.
//!
//! ```
//! use rdaylight_base::radiometry::Channels;
//! use rdaylight_formats::scene::{self, LoadOptions};
//! use rdaylight_physics::sky::SkyPatches;
//! use rdaylight_trace::trace::{Renderable, PathLimits};
//! use rdaylight_physics::geometry::Vec3;
//! use rand::SeedableRng;
//! let text = "void glow skyglow 0 0 4 1 1 1 0\nskyglow source sky 0 0 4 0 0 1 360\n";
//! let scene = scene::parse_str(text, "sky.rad", std::path::Path::new(""), &LoadOptions::default())?;
//! let r = Renderable::compile(&scene, &Channels::rgb(), &rdaylight_physics::material::ShadingOptions::rcontrib())?;
//! let patches = SkyPatches::new(1);
//! let mut dc = vec![0.0; patches.len() * 3];
//! let mut rng = rand_pcg::Pcg64::seed_from_u64(1);
//! let params = PathLimits { ab: 5, lw: 1e-5, ..PathLimits::rcontrib() };
//! r.dc_sensor(Vec3::ZERO, Vec3::new(0., 0., 1.), 1000, &params, &patches, &mut rng, &mut dc);
//! let total: f64 = dc.iter().step_by(3).sum();
//! assert!((total - std::f64::consts::PI).abs() < 1e-9); // every path escapes: row sum pi
//! # Ok::<(), rdaylight_base::Error>(())
//! ```

pub mod compile;
pub mod compiled;
pub mod expand;
pub mod integrator;
pub mod portals;
pub mod reweight;
pub mod sources;

pub use compile::{Renderable, SurfaceInfo};
pub use integrator::{PathLimits, SampleStats};
pub use sources::{DistantKind, DistantSource, SkyPattern, Sources};

/// Revision of the path tracer's sampling: change it whenever a given seed starts giving
/// other numbers (another random stream, a new estimator), so caches of traced results
/// (rcalib's coefficient cache) do not mix runs of two tracers.
pub const REVISION: &str =
    "2026-11-28: window portals (next-event estimation of the sky, falling continuation)";
