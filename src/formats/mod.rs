//! Radiance's file formats. One module per format; each has its own tests.
//!
//! | module | format | Radiance source |
//! |---|---|---|
//! | [`header`] | information header (`#?RADIANCE` ... empty line) | `src/common/header.c` |
//! | [`matrix`] | matrices: ascii/float/double/RGBE, `NROWS`/`NCOLS`/`NCOMP` | `src/util/rmatrix.c` |
//! | [`picture`] | pictures: RGBE/XYZE (flat, old and new RLE), spectral, EXR, PNG | `src/common/color.c` |
//! | [`view`] | view options `-vt? -vp -vd ...` and `VIEW=` | `src/common/image.c` |
//! | [`sensors`] | sensor rays `x y z dx dy dz` | `src/rt/rtmain.c` |
//! | [`weather`] | `.wea` (DAYSIM) and EPW weather | `src/gen/loadEPW.c` |

pub mod header;
pub mod matrix;
pub mod picture;
pub mod sensors;
pub mod view;
pub mod weather;
