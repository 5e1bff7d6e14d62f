//! # rdaylight-glod: Geometrical Levels of Detail (the seed's chapter 2)
//!
//! A furnished room's scene is reduced to five levels (seed section 2.3.1): GLoD0 the
//! permanent shell (walls, floor, ceiling, windows), GLoD1-3 add the non-permanent objects
//! whose oriented-bounding-box (OBB) surface area reaches 3.0, 2.4 and 0.5 m2, GLoD4 is
//! everything. The seed measured TAI errors of 1.1, 6.6, 11.2 and 18.1 % for GLoD3..0 against
//! GLoD4 over six rooms.
//!
//! | module | concept |
//! |---|---|
//! | [`points`] | the points each primitive's box must enclose |
//! | [`obb`] | smallest-surface-area oriented box (Freeman & Shapira per axis, searched over axes) |
//! | [`objects`] | primitives -> objects (prefix, modifier, connectivity, source), the shell |
//! | [`level`] | thresholds, levels, thresholds from percentiles |
//! | [`filter`] | the scene at one level, with the modifiers it still uses |
//! | [`report`] | the `rglod objects` table |
//! | [`plan`] | the plan view, objects coloured by level (SVG) |
//! | [`study`] | the chapter-2 experiment: TAI per level against GLoD4, trace time (seed Table 2.4) |
//!
//! ```
//! use rdaylight_formats::scene::{self, LoadOptions};
//! use rdaylight_glod::{analyse, filter, Options};
//! let text = "void plastic grey 0 0 5 .5 .5 .5 0 0\n\
//!     grey polygon floor 0 0 12 0 0 0 4 0 0 4 4 0 0 4 0\n\
//!     grey polygon ceiling 0 0 12 0 0 3 0 4 3 4 4 3 4 0 3\n\
//!     grey polygon desk_1.top 0 0 12 1 1 .7 2.6 1 .7 2.6 1.8 .7 1 1.8 .7\n";
//! let scene = scene::parse_str(text, "room.rad", std::path::Path::new(""), &LoadOptions::default())?;
//! let a = analyse(&scene, &Options::default())?;
//! assert_eq!(a.shell.len(), 2);
//! // A 1.6 x 0.8 m desk top as one polygon: a flat box, area 2ab = 2.56 m2, so GLoD2.
//! assert!((a.objects[0].area - 2.56).abs() < 1e-9);
//! assert_eq!(a.objects[0].level, 2);
//! assert_eq!(filter::filter(&scene, &a, 1)?.objects.len(), 3); // material + shell
//! # Ok::<(), rdaylight_base::Error>(())
//! ```

pub mod filter;
pub mod level;
pub mod obb;
pub mod objects;
pub mod plan;
pub mod points;
pub mod report;
pub mod study;

pub use level::{MAX_LEVEL, Thresholds, percentiles};
pub use obb::{Obb, min_area_obb};
pub use objects::{Analysis, Frame, GlodObject, Grouping, Options, analyse};
