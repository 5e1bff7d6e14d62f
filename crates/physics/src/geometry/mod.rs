//! Scene geometry for the ray tracer: shapes, rays, polygon triangulation, and one BVH.
//!
//! - `Vec3`: the `f64` vector of the hot path (`rdaylight_base::vec3`).
//! - [`ray`]: [`Ray`], [`Hit`] (Radiance's front side) and the secondary-ray offset.
//! - [`triangulate`]: ear clipping for Radiance polygons (non-convex, holes joined by seams).
//! - [`shapes`]: [`Shape`] (polygon, sphere/bubble, cone/cup, cylinder/tube, ring), filled by
//!   the scene converter, and their exact intersections.
//! - [`bvh`]: [`Bvh`], closest hit and occlusion over everything, `f32` BVH from `obvhs`
//!   with `f64` hits and internal recentring.
//! - [`wide`]: obvhs's binary BVH to its compressed 8-wide BVH on every core, node for node
//!   obvhs's own serial conversion.
//!
//! ```
//! use rdaylight_physics::geometry::{Bvh, Object, Ray, Shape, Vec3};
//! // A 1 m floor square facing up (counter-clockwise seen from above), object id 7.
//! let floor = Shape::Polygon {
//!     vertices: vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
//! };
//! let bvh = Bvh::build(&[Object { shape: floor, id: 7 }]).unwrap();
//! let ray = Ray::new(Vec3::new(0.5, 0.5, 2.0), Vec3::new(0., 0., -1.));
//! let hit = bvh.intersect(&ray, 0.0, f64::INFINITY).unwrap();
//! assert_eq!((hit.object, hit.t, hit.front), (7, 2.0, true));
//! assert_eq!(hit.normal, Vec3::new(0., 0., 1.));
//! ```

pub mod bvh;
pub mod klems;
pub mod ray;
pub mod shapes;
pub mod triangulate;
pub mod wide;

pub use bvh::{BuildError, Bvh, Placed, ShapeSource};
pub use klems::{KlemsBasis, KlemsFrame, KlemsKind};
pub use ray::{Hit, Ray, offset_distance};
pub use rdaylight_base::vec3::{self, Vec3};
pub use shapes::{Object, Shape, ShapeError, ShapeRef};
pub use triangulate::{PolygonError, polygon_area, triangulate, triangulate_into};
