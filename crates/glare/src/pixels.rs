//! The per-pixel quantities every glare computation uses: direction, solid angle, luminance
//! and validity, laid out as evalglare 3.06 lays them out (`src/util/pictool.c`,
//! `pict_read_fp`, `pict_update_evalglare_caches`, `pict_is_validpixel`).
//!
//! Coordinates follow evalglare, not the picture: `x` from the left, `y` from the **bottom**
//! (evalglare stores the first scanline of a standard `-Y n +X m` picture at `y = n − 1`),
//! and the flat index is `y + x·yres` (column-major). The scan order of every detection pass
//! (x outer, y inner) and hence which source a pixel joins depend on this.
//!
//! - direction of `(x, y)`: the ray through the centre of picture row `yres − 1 − y`
//!   (`pict_get_ray` flips back before `pix2loc`);
//! - solid angle of `(x, y)`: evalglare's `pict_get_sangle` calls `pix2loc` **without** that
//!   flip, so it measures the pixel mirrored top-to-bottom, picture row `y`. For views
//!   symmetric about the horizontal axis (every fisheye, unshifted perspectives) this is the
//!   same number; for lifted views (`-vl`) it is evalglare's quirk, kept for agreement.
//!   The area is [`Camera::pixel_solid_angle`]'s (two Van Oosterom-Strackee triangles):
//!   identical to evalglare's Girard sum to printed precision for `-vta` and `-vtv`; on a
//!   `-vth` rim, pixels whose corner lies on the circle to within rounding are counted by
//!   evalglare and not by us (or the reverse): 8 of 31016 pixels of a 200² uniform picture,
//!   −0.04 % of E_v; measured −0.001 % to −0.024 % on the `-vth` fixtures;
//! - in view: the pixel has a ray (`pict_get_hangle` succeeds; outside a `-vth` circle it
//!   does not);
//! - valid: in view, solid angle > 0, and for `-vta` the centre ray looks forward
//!   (`dir·vdir ≥ 0`; the corners of a 180° angular fisheye do not).

use crate::formats::picture::Picture;
use crate::formats::view::{Camera, column_solid_angles};

/// 3-vectors; the dot product in Radiance's order (`DOT`) keeps `acos(dot)` of a pixel with
/// itself bit-identical to evalglare's.
pub use crate::vec3::{V3, dot};

/// The pixels of one picture in evalglare's layout (see the module documentation).
#[derive(Debug, Clone)]
pub struct Pixels {
    /// Pixels per row.
    pub xres: usize,
    /// Rows.
    pub yres: usize,
    /// Unit direction per pixel (zero where there is no ray).
    pub dir: Vec<V3>,
    /// Solid angle (sr).
    pub omega: Vec<f64>,
    /// Luminance (cd/m²), exposure divided out.
    pub lum: Vec<f64>,
    /// The pixel has a ray.
    pub inview: Vec<bool>,
    /// evalglare's `pict_is_validpixel`.
    pub valid: Vec<bool>,
    /// The camera the directions come from.
    pub camera: Camera,
}

impl Pixels {
    /// Directions, solid angles, luminances and validity of every pixel of `pic` seen
    /// through `camera` (rows computed in parallel).
    pub fn new(pic: &Picture, camera: Camera) -> Pixels {
        use rayon::prelude::*;
        let (xres, yres) = (pic.width, pic.height);
        let angular = camera.view().vtype == crate::formats::view::ViewType::Angular;
        let not_parallel = camera.view().vtype != crate::formats::view::ViewType::Parallel;
        let vdir = camera.dir();
        let n = xres * yres;
        let mut p = Pixels {
            xres,
            yres,
            dir: vec![[0.0; 3]; n],
            omega: vec![0.0; n],
            lum: vec![0.0; n],
            inview: vec![false; n],
            valid: vec![false; n],
            camera,
        };
        // Blocks of columns in parallel, written in place (the flat index is y + x·yres, so
        // a column is a contiguous run of yres pixels, y from the bottom). Pixel corners
        // are shared by adjacent pixels: a block computes its `BLOCK + 1` corner columns
        // once (the values `Camera::pixel_solid_angle` computes, with about a quarter of
        // the view rays). Directions come a column at a time (`Camera::view_dirs`: the
        // same numbers as `pixel_ray`), luminances a picture row of the block at a time
        // (the picture is stored row by row).
        const BLOCK: usize = 16;
        let chunk = (BLOCK * yres).max(1);
        let cam = &p.camera;
        // image-plane y of the corner rows (k / yres, k = 0 at the bottom) and of the pixel
        // centres of y = 0, 1, ... from the bottom (Radiance's pix2loc: (y + ½) / yres)
        let corner_y: Vec<f64> = (0..=yres).map(|k| k as f64 / yres as f64).collect();
        let centre_y: Vec<f64> = (0..yres).map(|y| (y as f64 + 0.5) / yres as f64).collect();
        let corners = |cx: usize, out: &mut [Option<V3>]| {
            cam.view_dirs(cx as f64 / xres as f64, &corner_y, out);
        };
        let lum_of = Luminance::new(pic);
        // Luminances in bands of rows: each picture row is read whole and in order (the
        // hardware prefetches it), while the band's part of every column stays in cache
        // until it is filled. (A block of columns at a time missed the cache on every row.)
        const BAND: usize = 16;
        for y0 in (0..yres).step_by(BAND) {
            for y in y0..(y0 + BAND).min(yres) {
                let row = yres - 1 - y;
                for x in 0..xres {
                    p.lum[x * yres + y] = lum_of.at(x, row);
                }
            }
        }
        p.dir
            .par_chunks_mut(chunk)
            .zip(p.omega.par_chunks_mut(chunk))
            .zip(p.inview.par_chunks_mut(chunk))
            .zip(p.valid.par_chunks_mut(chunk))
            .enumerate()
            .for_each(|(b, (((dir, omega), inview), valid))| {
                let x0 = b * BLOCK;
                let ncol = dir.len() / yres;
                let mut c0 = vec![None; yres + 1];
                let mut c1 = vec![None; yres + 1];
                let mut centre = vec![None; yres];
                let mut om_col = vec![0.0; yres];
                corners(x0, &mut c0);
                for c in 0..ncol {
                    let x = x0 + c;
                    corners(x + 1, &mut c1);
                    cam.view_dirs((x as f64 + 0.5) / xres as f64, &centre_y, &mut centre);
                    // by image row k from the bottom of the image plane; pixel y's is
                    // row yres − 1 − y (evalglare's mirrored solid angle, module docs)
                    if not_parallel {
                        column_solid_angles(&c0, &c1, &mut om_col);
                    }
                    for (y, centre) in centre.iter().enumerate() {
                        let i = c * yres + y;
                        let om = om_col[yres - 1 - y];
                        omega[i] = om;
                        if let Some(d) = *centre {
                            dir[i] = d;
                            inview[i] = true;
                            valid[i] = om > 0.0 && (!angular || dot(d, vdir) >= 0.0);
                        }
                    }
                    std::mem::swap(&mut c0, &mut c1);
                }
            });
        p
    }

    /// Flat index of `(x, y)` (y from the bottom).
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> usize {
        y + x * self.yres
    }

    /// Angle (rad) of evalglare's radius tests: `2·acos(dᵢ·dⱼ)` (twice the angle between
    /// the two directions, as `find_near_pgs` computes it; NaN when rounding makes the dot
    /// product exceed 1, which evalglare then treats as "outside").
    #[inline]
    pub fn radius(&self, i: usize, j: usize) -> f64 {
        dot(self.dir[i], self.dir[j]).acos() * 2.0
    }

    /// `self.radius(i, j) <= r` without the arc cosine, for the searches that test
    /// thousands of neighbours per pixel: `2·acos(d) <= r` is `d >= cos(r/2)` for `d <= 1`
    /// (and false for `d > 1`, where acos is NaN). `cos_half` is `cos(r/2)`. Within 1e-12 of
    /// the boundary the arc cosine decides, so every pixel falls on the side evalglare's
    /// test puts it.
    #[inline]
    pub fn within(&self, i: usize, j: usize, r: f64, cos_half: f64) -> bool {
        Self::within_dirs(self.dir[i], self.dir[j], r, cos_half)
    }

    /// [`Pixels::within`] for two directions.
    #[inline]
    pub fn within_dirs(a: V3, b: V3, r: f64, cos_half: f64) -> bool {
        let d = dot(a, b);
        if (d - cos_half).abs() < 1e-12 {
            d.acos() * 2.0 <= r
        } else {
            d >= cos_half && d <= 1.0
        }
    }

    /// Direction of `(x, y)` computed afresh (evalglare's `pict_get_dir` for positions
    /// given as reals: truncated to the pixel), `None` outside the view or the picture.
    pub fn dir_at(&self, x: f64, y: f64) -> Option<V3> {
        if !(x >= 0.0 && y >= 0.0) {
            return None;
        }
        let (xi, yi) = (x as usize, y as usize);
        if xi >= self.xres || yi >= self.yres {
            return None;
        }
        self.camera
            .pixel_ray(xi, self.yres - 1 - yi, self.xres, self.yres)
            .map(|r| r.dir)
    }
}

// Photopic weights and efficacy: Radiance's `luminance()` (see `radiometry::RGB_PHOTOPIC`,
// the values color.h's macros compute, which evalglare uses).
use crate::radiometry::{RGB_PHOTOPIC as CIE_RGB_W, WHITE_EFFICACY as WHTEFFICACY};

/// Radiance's `luminance()` of a pixel with the exposure divided out: what
/// [`Picture::luminance`] computes, without recomputing the exposure per pixel.
struct Luminance<'a> {
    pic: &'a Picture,
    /// The exposure per channel.
    ex: Vec<f64>,
    rgbe: bool,
    ncomp: usize,
}

impl<'a> Luminance<'a> {
    fn new(pic: &'a Picture) -> Self {
        use crate::formats::picture::PixelFormat;
        Luminance {
            pic,
            ex: pic.exposure(),
            rgbe: pic.format == PixelFormat::Rgbe,
            ncomp: pic.ncomp(),
        }
    }

    /// Pixel `x` of picture row `row` (from the top).
    #[inline]
    fn at(&self, x: usize, row: usize) -> f64 {
        if !self.rgbe {
            return self.pic.luminance(x, row);
        }
        let at = (row * self.pic.width + x) * self.ncomp;
        let px = &self.pic.data[at..at + 3];
        let ex = &self.ex;
        let [r, g, b] = CIE_RGB_W;
        WHTEFFICACY
            * (r * px[0] as f64 / ex[0] + g * px[1] as f64 / ex[1] + b * px[2] as f64 / ex[2])
    }
}
