//! # rdaylight-formats: Radiance's file formats (layer 1)
//!
//! One module per format; each has its own tests. Every parser is written with `nom`,
//! reports file, line and what it expected, and streams where files get large. Above
//! `rdaylight-base` only.
//!
//! | module | format | Radiance source |
//! |---|---|---|
//! | [`bsdf`] | BSDF XML (LBNL WINDOW 6 schema: Klems matrices, tensor trees) | `src/common/bsdf.c`, `bsdf_m.c`, `bsdf_t.c` |
//! | [`header`] | information header (`#?RADIANCE` ... empty line) | `src/common/header.c` |
//! | [`matrix`] | matrices: ascii/float/double/RGBE, `NROWS`/`NCOLS`/`NCOMP` | `src/util/rmatrix.c` |
//! | [`picture`] | pictures: RGBE/XYZE (flat, old and new RLE), spectral, EXR, PNG | `src/common/color.c` |
//! | [`view`] | view options `-vt? -vp -vd ...` and `VIEW=` | `src/common/image.c` |
//! | [`sensors`] | sensor rays `x y z dx dy dz` | `src/rt/rtmain.c` |
//! | [`weather`] | `.wea` (DAYSIM) and EPW weather | `src/gen/loadEPW.c` |
//! | [`scene`] | the `.rad` scene description: grammar, inline `!commands`, typed primitives | `src/common/readobj.c` |
//! | [`info`] | summaries of any of these files (what `rinfo` prints) | `getinfo` |

use rdaylight_base::{colour, error, io, progress, radiometry, vec3};

pub mod bsdf;
pub mod header;
pub mod hours;
pub mod info;
pub mod matrix;
pub mod picture;
pub mod scene;
pub mod sensors;
pub mod shard;
pub mod view;
pub mod weather;
