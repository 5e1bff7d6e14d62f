//! A validated view ([`Camera`]): Radiance's `setview` checks and derived image vectors, the
//! ray of every image point (`viewray`), its inverse (`viewloc`), pixel centres (`pix2loc`),
//! resolution/aspect fitting (`normaspect`) and pixel solid angles (evalglare's
//! `pict_get_sangle`). Formulas are listed in the parent module's documentation.

use super::{View, ViewType};
use crate::error::{Error, Result};
use crate::vec3::{FTINY, V3, add, cross, dot, normalize_radiance as normalize, scale, sub};
use std::f64::consts::PI;

/// One view ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewRay {
    /// Origin: the view point moved to the fore clipping plane/sphere (`-vo`).
    pub org: [f64; 3],
    /// Unit direction.
    pub dir: [f64; 3],
    /// Length to the aft clipping plane (`-va`), `None` when there is none. `vwrays` writes
    /// `dir * max_dist` as the direction in that case.
    pub max_dist: Option<f64>,
}

/// Where a world point falls in a view (Radiance's `viewloc`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageLoc {
    /// Image-plane x in `[0,1]` when inside, left to right.
    pub x: f64,
    /// Image-plane y in `[0,1]` when inside, bottom to top.
    pub y: f64,
    /// Distance from the fore clipping plane/sphere (negative when behind it).
    pub depth: f64,
    /// `VL_BEHIND`: the point is behind the fore plane (or the eye).
    pub behind: bool,
    /// `VL_OUTSIDE`: the point projects outside `(0,1)²`.
    pub outside: bool,
    /// `VL_BEYOND`: the point is past the aft clipping plane.
    pub beyond: bool,
}

impl ImageLoc {
    /// `VL_GOOD` alone: visible inside the image and between the clipping planes.
    pub fn visible(&self) -> bool {
        !(self.behind || self.outside || self.beyond)
    }
}

/// A view after Radiance's `setview`: validated, with unit direction and image vectors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// The view as Radiance would print it after `setview`: `vu` normalised, `vd` unchanged.
    view: View,
    /// Unit view direction.
    vdir: V3,
    /// `|vd|`, Radiance's view (focal) distance.
    vdist: f64,
    /// Horizontal image vector, scaled by the half-size factor for `v`, `h`, `l`.
    hvec: V3,
    /// Vertical image vector, scaled for `v`, `h`, `l`, `c`.
    vvec: V3,
    /// Squared scale factors (`hn2`, `vn2` in `view.h`).
    hn2: f64,
    vn2: f64,
}

impl View {
    /// Validate the view as Radiance's `setview` does, in the same order and with the same
    /// reasons: clipping distances, zero direction, zero up, up parallel to direction, sizes
    /// (perspective < 180°, cylindrical horizontal ≤ 360° and vertical < 180°, angular ≤ 360°,
    /// hemispherical ≤ 180°, planisphere < 360°, all > 0).
    ///
    /// The error is one line: `bad view: <Radiance's reason> (<the view>)`.
    pub fn setup(&self) -> Result<Camera> {
        let bad = |why: &str| Error::Usage(format!("bad view: {why} ({self})"));
        let ill_h = "illegal horizontal view size";
        let ill_v = "illegal vertical view size";
        if self.vo < -FTINY || self.va < -FTINY || (self.va > FTINY && self.va <= self.vo) {
            return Err(bad("illegal fore/aft clipping plane"));
        }
        if self
            .vp
            .iter()
            .chain(&self.vd)
            .chain(&self.vu)
            .any(|c| !c.is_finite())
            || ![self.vh, self.vv, self.vs, self.vl, self.vo, self.va]
                .iter()
                .all(|c| c.is_finite())
        {
            // Our parsers reject these already; a View built in code might not.
            return Err(bad("non-finite view parameter"));
        }
        // Not a setview check: a view point beyond the geometry's bound (1e300 was accepted,
        // issue #19) sends its rays into the BVH from where no scene can be.
        let far = crate::vec3::MAX_COORDINATE;
        if self.vp.iter().any(|c| c.abs() > far) {
            return Err(bad(&format!(
                "view point out of range: coordinates are at most +-{far:e} m, as for geometry"
            )));
        }
        let mut vdir = self.vd;
        let vdist = normalize(&mut vdir);
        if vdist == 0.0 {
            return Err(bad("zero view direction"));
        }
        let mut vup = self.vu;
        if normalize(&mut vup) == 0.0 {
            return Err(bad("zero view up vector"));
        }
        let mut hvec = cross(vdir, vup);
        if normalize(&mut hvec) == 0.0 {
            return Err(bad("view up parallel to view direction"));
        }
        let mut vvec = cross(hvec, vdir);
        let (h, v) = (self.vh, self.vv);
        if h <= FTINY {
            return Err(bad(ill_h));
        }
        if v <= FTINY {
            return Err(bad(ill_v));
        }
        let half = |deg: f64| deg * (PI / 360.0);
        let (hn, vn) = match self.vtype {
            ViewType::Parallel => (h, v),
            ViewType::Perspective => {
                if h >= 180.0 - FTINY {
                    return Err(bad(ill_h));
                }
                if v >= 180.0 - FTINY {
                    return Err(bad(ill_v));
                }
                (2.0 * half(h).tan(), 2.0 * half(v).tan())
            }
            ViewType::Cylindrical => {
                if h > 360.0 + FTINY {
                    return Err(bad(ill_h));
                }
                if v >= 180.0 - FTINY {
                    return Err(bad(ill_v));
                }
                (h * (PI / 180.0), 2.0 * half(v).tan())
            }
            ViewType::Angular => {
                if h > 360.0 + FTINY {
                    return Err(bad(ill_h));
                }
                if v > 360.0 + FTINY {
                    return Err(bad(ill_v));
                }
                (h * (PI / 180.0), v * (PI / 180.0))
            }
            ViewType::Hemispherical => {
                if h > 180.0 + FTINY {
                    return Err(bad(ill_h));
                }
                if v > 180.0 + FTINY {
                    return Err(bad(ill_v));
                }
                (2.0 * half(h).sin(), 2.0 * half(v).sin())
            }
            ViewType::Planisphere => {
                if h >= 360.0 - FTINY {
                    return Err(bad(ill_h));
                }
                if v >= 360.0 - FTINY {
                    return Err(bad(ill_v));
                }
                (
                    2.0 * half(h).sin() / (1.0 + half(h).cos()),
                    2.0 * half(v).sin() / (1.0 + half(v).cos()),
                )
            }
        };
        // Angular and planisphere views keep unit image vectors (their formulas scale the
        // image coordinates instead); cylindrical views keep a unit horizontal vector.
        match self.vtype {
            ViewType::Angular | ViewType::Planisphere => {}
            ViewType::Cylindrical => vvec = scale(vvec, vn),
            _ => {
                hvec = scale(hvec, hn);
                vvec = scale(vvec, vn);
            }
        }
        let mut view = *self;
        view.vu = vup;
        Ok(Camera {
            view,
            vdir,
            vdist,
            hvec,
            vvec,
            hn2: hn * hn,
            vn2: vn * vn,
        })
    }
}

impl Camera {
    /// The view (with `vu` normalised, as Radiance prints it after `setview`).
    pub fn view(&self) -> &View {
        &self.view
    }

    /// Unit view direction.
    pub fn dir(&self) -> [f64; 3] {
        self.vdir
    }

    /// Length of `-vd` (Radiance's focal "view distance").
    pub fn focal_distance(&self) -> f64 {
        self.vdist
    }

    /// Image vectors after `setview` (`hvec`, `vvec`): scaled by the image half-size factor
    /// for perspective, hemispherical and parallel views (vertical also for cylindrical),
    /// unit otherwise.
    pub fn image_vectors(&self) -> ([f64; 3], [f64; 3]) {
        (self.hvec, self.vvec)
    }

    /// Height/width of the view (`viewaspect`: `√(vn2/hn2)`).
    pub fn aspect(&self) -> f64 {
        (self.vn2 / self.hn2).sqrt()
    }

    /// Ray through image point `(x, y)`, origin bottom left, `[0,1]²` covering the image
    /// (values outside extend the view). `None` outside a fisheye's circle (Radiance's
    /// `viewray` returning −1; `vwrays` writes a zero ray there).
    pub fn view_ray(&self, x: f64, y: f64) -> Option<ViewRay> {
        let v = &self.view;
        let x = x + v.vs - 0.5;
        let y = y + v.vl - 0.5;
        // Length to the aft plane along the view axis (scaled for tilted rays below).
        let aft = (v.va > FTINY).then_some(v.va - v.vo);
        let along = |z: f64, a: f64, b: f64| {
            add(
                add(scale(self.vdir, z), scale(self.hvec, a)),
                scale(self.vvec, b),
            )
        };
        let from_eye = |dir: V3| add(v.vp, scale(dir, v.vo));
        match v.vtype {
            ViewType::Parallel => {
                let org = add(
                    add(v.vp, scale(self.vdir, v.vo)),
                    add(scale(self.hvec, x), scale(self.vvec, y)),
                );
                Some(ViewRay {
                    org,
                    dir: self.vdir,
                    max_dist: aft,
                })
            }
            ViewType::Perspective | ViewType::Cylindrical => {
                let mut dir = if v.vtype == ViewType::Perspective {
                    along(1.0, x, y)
                } else {
                    let phi = x * v.vh * (PI / 180.0);
                    along(phi.cos(), phi.sin(), y)
                };
                // The origin uses the unnormalised direction: the fore clip is a plane
                // (perspective) or a cylinder (panorama), not a sphere.
                let org = from_eye(dir);
                let len = normalize(&mut dir);
                Some(ViewRay {
                    org,
                    dir,
                    max_dist: aft.map(|a| a * len),
                })
            }
            ViewType::Hemispherical => {
                let z = 1.0 - x * x * self.hn2 - y * y * self.vn2;
                if z < 0.0 {
                    return None;
                }
                let dir = along(z.sqrt(), x, y);
                Some(ViewRay {
                    org: from_eye(dir),
                    dir,
                    max_dist: aft,
                })
            }
            ViewType::Angular => {
                let x = x * v.vh / 180.0;
                let y = y * v.vv / 180.0;
                let d2 = x * x + y * y;
                if d2 > 1.0 {
                    return None;
                }
                let d = d2.sqrt();
                let z = (PI * d).cos();
                let s = if d <= FTINY {
                    PI
                } else {
                    (1.0 - z * z).sqrt() / d
                };
                let dir = along(z, x * s, y * s);
                Some(ViewRay {
                    org: from_eye(dir),
                    dir,
                    max_dist: aft,
                })
            }
            ViewType::Planisphere => {
                let x = x * self.hn2.sqrt();
                let y = y * self.vn2.sqrt();
                let d = x * x + y * y;
                let z = (1.0 - d) / (1.0 + d);
                let dir = along(z, x * (1.0 + z), y * (1.0 + z));
                Some(ViewRay {
                    org: from_eye(dir),
                    dir,
                    max_dist: aft,
                })
            }
        }
    }

    /// Directions of the rays through the image points `(x, ys[k])` (one column of pixel
    /// centres or corners): `out[k]` is `self.view_ray(x, ys[k]).map(|r| r.dir)`, bit for
    /// bit. Angular fisheyes are computed stage by stage over the column, so the square roots
    /// and divisions of many points overlap (in vector registers where the compiler can);
    /// the other view types point by point.
    ///
    /// # Panics
    /// If `ys` and `out` differ in length.
    pub fn view_dirs(&self, x: f64, ys: &[f64], out: &mut [Option<V3>]) {
        assert_eq!(ys.len(), out.len(), "view_dirs: one output per point");
        let v = &self.view;
        if v.vtype != ViewType::Angular {
            for (o, &y) in out.iter_mut().zip(ys) {
                *o = self.view_ray(x, y).map(|r| r.dir);
            }
            return;
        }
        // view_ray's angular branch, the same operations in the same order
        let x = (x + v.vs - 0.5) * v.vh / 180.0;
        // view_ray returns None only for d² > 1 (a NaN goes on)
        let inside = |d2: f64| d2 <= 1.0 || d2.is_nan();
        const N: usize = 64;
        let (mut yv, mut d2, mut d, mut z) = ([0.0; N], [0.0; N], [0.0; N], [0.0; N]);
        for (ys, out) in ys.chunks(N).zip(out.chunks_mut(N)) {
            let n = ys.len();
            for k in 0..n {
                yv[k] = (ys[k] + v.vl - 0.5) * v.vv / 180.0;
                d2[k] = x * x + yv[k] * yv[k];
                d[k] = d2[k].sqrt();
            }
            for k in 0..n {
                if inside(d2[k]) {
                    z[k] = (PI * d[k]).cos();
                }
            }
            for k in 0..n {
                out[k] = inside(d2[k]).then(|| {
                    let s = if d[k] <= FTINY {
                        PI
                    } else {
                        (1.0 - z[k] * z[k]).sqrt() / d[k]
                    };
                    add(
                        add(scale(self.vdir, z[k]), scale(self.hvec, x * s)),
                        scale(self.vvec, yv[k] * s),
                    )
                });
            }
        }
    }

    /// Image-plane centre of pixel `(px, py)` of an `xres × yres` picture in standard
    /// orientation (`-Y yres +X xres`: row 0 is the top): Radiance's `pix2loc`,
    /// `((px + ½)/xres, (yres − 1 − py + ½)/yres)`.
    pub fn pixel_loc(px: usize, py: usize, xres: usize, yres: usize) -> (f64, f64) {
        let y = yres as f64 - 1.0 - py as f64;
        ((px as f64 + 0.5) / xres as f64, (y + 0.5) / yres as f64)
    }

    /// Ray through the centre of pixel `(px, py)`, row 0 at the top (the order `vwrays`
    /// writes and rpict renders). `None` outside the view or outside the picture.
    pub fn pixel_ray(&self, px: usize, py: usize, xres: usize, yres: usize) -> Option<ViewRay> {
        if px >= xres || py >= yres {
            return None;
        }
        let (x, y) = Self::pixel_loc(px, py, xres, yres);
        self.view_ray(x, y)
    }

    /// Image location of world point `p` (Radiance's `viewloc`), `None` where Radiance
    /// returns `VL_BAD`: the view point itself, a point in the perspective eye plane, on a
    /// panorama's axis, or straight behind a planisphere.
    pub fn view_loc(&self, p: [f64; 3]) -> Option<ImageLoc> {
        let v = &self.view;
        let mut disp = sub(p, v.vp);
        let (x, y, depth);
        let mut beyond = false;
        match v.vtype {
            ViewType::Parallel | ViewType::Perspective | ViewType::Hemispherical => {
                let mut ip2;
                match v.vtype {
                    ViewType::Parallel => ip2 = dot(disp, self.vdir) - v.vo,
                    ViewType::Perspective => {
                        let mut d = dot(disp, self.vdir);
                        beyond = v.va > FTINY && d >= v.va;
                        ip2 = dot(disp, disp).sqrt();
                        if d < -FTINY {
                            // Points behind the eye fold through it (Radiance's "fold
                            // pyramid"), flagged behind by a negative depth.
                            ip2 = -ip2;
                            d = -d;
                        } else if d <= FTINY {
                            return None;
                        }
                        let mut inv = 1.0 / d;
                        disp = scale(disp, inv);
                        if ip2 < 0.0 {
                            inv = -inv;
                        }
                        ip2 *= 1.0 - v.vo * inv;
                    }
                    _ => {
                        let d = normalize(&mut disp);
                        ip2 = if dot(disp, self.vdir) < 0.0 { -d } else { d };
                        ip2 -= v.vo;
                    }
                }
                x = dot(disp, self.hvec) / self.hn2 + 0.5 - v.vs;
                y = dot(disp, self.vvec) / self.vn2 + 0.5 - v.vl;
                depth = ip2;
            }
            ViewType::Cylindrical => {
                let a = dot(disp, self.hvec);
                let b = dot(disp, self.vdir);
                x = 180.0 / PI * a.atan2(b) / v.vh + 0.5 - v.vs;
                let r2 = a * a + b * b;
                if r2 <= FTINY * FTINY {
                    return None;
                }
                beyond = v.va > FTINY && r2 >= v.va * v.va;
                let inv = 1.0 / r2.sqrt();
                y = dot(disp, self.vvec) * inv / self.vn2 + 0.5 - v.vl;
                depth = dot(disp, disp).sqrt() * (1.0 - v.vo * inv);
            }
            ViewType::Angular | ViewType::Planisphere => {
                let (mut ix, mut iy) = (0.5 - v.vs, 0.5 - v.vl);
                depth = normalize(&mut disp) - v.vo;
                let d = dot(disp, self.vdir);
                if d >= 1.0 - FTINY {
                    // straight ahead: image centre
                } else if d <= -(1.0 - FTINY) {
                    if v.vtype == ViewType::Planisphere {
                        return None;
                    }
                    ix += 180.0 / v.vh;
                } else if v.vtype == ViewType::Angular {
                    let f = (180.0 / PI) * d.acos() / (1.0 - d * d).sqrt();
                    ix += dot(disp, self.hvec) * f / v.vh;
                    iy += dot(disp, self.vvec) * f / v.vv;
                } else {
                    ix += dot(disp, self.hvec) / ((1.0 + d) * self.hn2.sqrt());
                    iy += dot(disp, self.vvec) / ((1.0 + d) * self.vn2.sqrt());
                }
                x = ix;
                y = iy;
            }
        }
        let behind = depth <= 0.0;
        if !behind && !matches!(v.vtype, ViewType::Perspective | ViewType::Cylindrical) {
            beyond = v.va > FTINY && depth >= v.va - v.vo;
        }
        let outside = !(x > 0.0 && x < 1.0 && y > 0.0 && y < 1.0);
        Some(ImageLoc {
            x,
            y,
            depth,
            behind,
            outside,
            beyond,
        })
    }

    /// Fit a resolution to the view's aspect as Radiance's `normaspect` does (rpict, vwrays):
    /// with `pixaspect > 0` (height/width of a pixel, default 1) the larger of `xres`, `yres`
    /// is reduced, rounding to nearest; with `pixaspect <= 0` the resolution is kept and the
    /// pixel aspect that fits is returned instead. Returns `(xres, yres, pixaspect)`.
    pub fn normalize_resolution(
        &self,
        xres: usize,
        yres: usize,
        pixaspect: f64,
    ) -> (usize, usize, f64) {
        let va = self.aspect();
        let (xf, yf) = (xres as f64, yres as f64);
        if pixaspect <= FTINY {
            (xres, yres, va * xf / yf)
        } else if va * xf > pixaspect * yf {
            // C assigns a positive double to an int: truncation after adding .5.
            ((yf / va * pixaspect + 0.5) as usize, yres, pixaspect)
        } else {
            (xres, (xf * va / pixaspect + 0.5) as usize, pixaspect)
        }
    }

    /// Solid angle (sr) of pixel `(px, py)` (row 0 at the top) as the spherical
    /// quadrilateral spanned by the rays through its four corners, which is what evalglare
    /// computes for every view type (`pict_get_sangle`). Zero when a corner is outside the
    /// view (as evalglare), for parallel views, and outside the picture.
    ///
    /// evalglare additionally ignores `-vta` pixels whose centre ray looks backwards
    /// (`pict_is_validpixel`: `dir · vdir < 0`, the corners of a 180° angular image, where
    /// Radiance still gives rays); callers that sum over a glare image should do the same.
    ///
    /// evalglare sums the quadrilateral's angles (Girard); we add the areas of its two
    /// triangles with Van Oosterom & Strackee's formula (IEEE Trans. Biomed. Eng. 30, 1983),
    /// the same area without the cancellation of `Σ angles − 2π` for tiny pixels.
    pub fn pixel_solid_angle(&self, px: usize, py: usize, xres: usize, yres: usize) -> f64 {
        if px >= xres || py >= yres || self.view.vtype == ViewType::Parallel {
            return 0.0;
        }
        let x0 = px as f64 / xres as f64;
        let x1 = (px + 1) as f64 / xres as f64;
        let y0 = (yres - 1 - py) as f64 / yres as f64;
        let y1 = (yres - py) as f64 / yres as f64;
        let corner = |x, y| self.view_ray(x, y).map(|r| r.dir);
        let (Some(a), Some(b), Some(c), Some(d)) = (
            corner(x0, y0),
            corner(x1, y0),
            corner(x1, y1),
            corner(x0, y1),
        ) else {
            return 0.0;
        };
        quad_solid_angle(a, b, c, d)
    }
}

/// Solid angle of the pixel whose corner directions are `a, b, c, d` in order (two
/// spherical triangles, [`Camera::pixel_solid_angle`]'s split).
pub fn quad_solid_angle(a: V3, b: V3, c: V3, d: V3) -> f64 {
    triangle_solid_angle(a, b, c) + triangle_solid_angle(a, c, d)
}

/// Solid angle of the spherical triangle of unit vectors `a, b, c`:
/// `tan(Ω/2) = |a·(b×c)| / (1 + a·b + b·c + c·a)` (Van Oosterom & Strackee 1983).
fn triangle_solid_angle(a: V3, b: V3, c: V3) -> f64 {
    let (num, den) = triangle_tan_half(a, b, c);
    2.0 * num.atan2(den)
}

/// The numerator and denominator of [`triangle_solid_angle`]'s `tan(Ω/2)`.
#[inline]
fn triangle_tan_half(a: V3, b: V3, c: V3) -> (f64, f64) {
    let num = dot(a, cross(b, c)).abs();
    let den = 1.0 + dot(a, b) + dot(b, c) + dot(c, a);
    (num, den)
}

/// Solid angles of a column of pixels from its two columns of corner directions (`n + 1`
/// each, as [`Camera::view_dirs`] gives them): `out[k]` is
/// `quad_solid_angle(left[k], right[k], right[k + 1], left[k + 1])`, bit for bit, or 0
/// where a corner has no ray. The products of a batch of pixels are formed before their
/// arc tangents, so the arc tangents run back to back instead of each waiting for its
/// pixel's arithmetic.
///
/// # Panics
/// If the corner columns are not one longer than `out`.
pub fn column_solid_angles(left: &[Option<V3>], right: &[Option<V3>], out: &mut [f64]) {
    assert!(
        left.len() == out.len() + 1 && right.len() == out.len() + 1,
        "column_solid_angles: n + 1 corners per column for n pixels"
    );
    const N: usize = 64;
    let mut t = [(0.0, 0.0, 0.0, 0.0); N];
    let mut has = [false; N];
    for (start, out) in (0..out.len()).step_by(N).zip(out.chunks_mut(N)) {
        for (j, (t, has)) in t.iter_mut().zip(has.iter_mut()).take(out.len()).enumerate() {
            let k = start + j;
            *has = false;
            if let (Some(a), Some(b), Some(c), Some(d)) =
                (left[k], right[k], right[k + 1], left[k + 1])
            {
                let (n1, d1) = triangle_tan_half(a, b, c);
                let (n2, d2) = triangle_tan_half(a, c, d);
                *t = (n1, d1, n2, d2);
                *has = true;
            }
        }
        for ((o, &(n1, d1, n2, d2)), &has) in out.iter_mut().zip(&t).zip(&has) {
            *o = if has {
                2.0 * n1.atan2(d1) + 2.0 * n2.atan2(d2)
            } else {
                0.0
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam(s: &str) -> Camera {
        let mut v = View::default();
        v.apply_str(s, "test").unwrap();
        v.setup().unwrap()
    }

    /// Σ ω over all pixels, or with `glare_valid` over those evalglare uses
    /// (`pict_is_validpixel`: for `-vta`, only pixels whose centre looks forward).
    fn sum_sangle(c: &Camera, n: usize, glare_valid: bool) -> f64 {
        let mut s = 0.0;
        for py in 0..n {
            for px in 0..n {
                let Some(r) = c.pixel_ray(px, py, n, n) else {
                    continue;
                };
                if glare_valid && c.view().vtype == ViewType::Angular && dot(r.dir, c.dir()) < 0.0 {
                    continue;
                }
                s += c.pixel_solid_angle(px, py, n, n);
            }
        }
        s
    }

    /// The column-at-a-time directions are view_ray's, bit for bit, for every view type,
    /// shifted and lifted views, and points outside the image and the fisheye circle.
    #[test]
    fn view_dirs_are_view_rays_bit_for_bit() {
        let ys: Vec<f64> = (0..=301).map(|k| k as f64 / 300.0 * 1.2 - 0.1).collect();
        for v in [
            "-vta -vh 180 -vv 180 -vd 0 -1 0",
            "-vta -vh 360 -vv 360 -vd 1 0 0",
            "-vta -vh 170 -vv 120 -vs 0.1 -vl -0.05 -vd 0.3 -1 0.2",
            "-vth -vh 180 -vv 180 -vd 0 -1 0",
            "-vtv -vh 70 -vv 50 -vd 0 -1 0.35",
            "-vtc -vh 300 -vv 60",
            "-vts -vh 200 -vv 200",
            "-vtl -vh 4 -vv 3",
        ] {
            let c = cam(v);
            let mut out = vec![None; ys.len()];
            for kx in 0..=40 {
                let x = kx as f64 / 40.0 * 1.2 - 0.1;
                c.view_dirs(x, &ys, &mut out);
                for (k, &y) in ys.iter().enumerate() {
                    let want = c.view_ray(x, y).map(|r| r.dir.map(f64::to_bits));
                    assert_eq!(out[k].map(|d| d.map(f64::to_bits)), want, "{v} at {x} {y}");
                }
            }
        }
    }

    /// A column's solid angles are quad_solid_angle's, bit for bit, with and without rays
    /// at the corners.
    #[test]
    fn column_solid_angles_are_quad_solid_angles_bit_for_bit() {
        // 300°: the image's corners lie outside the fisheye's circle
        let c = cam("-vta -vh 300 -vv 300 -vd 0 -1 0");
        let n = 150;
        let ys: Vec<f64> = (0..=n).map(|k| k as f64 / n as f64).collect();
        let (mut left, mut right) = (vec![None; n + 1], vec![None; n + 1]);
        let mut out = vec![0.0; n];
        let mut with_rays = 0;
        for col in 0..n {
            c.view_dirs(col as f64 / n as f64, &ys, &mut left);
            c.view_dirs((col + 1) as f64 / n as f64, &ys, &mut right);
            column_solid_angles(&left, &right, &mut out);
            for k in 0..n {
                let want = match (left[k], right[k], right[k + 1], left[k + 1]) {
                    (Some(a), Some(b), Some(c), Some(d)) => {
                        with_rays += 1;
                        quad_solid_angle(a, b, c, d)
                    }
                    _ => 0.0,
                };
                assert_eq!(out[k].to_bits(), want.to_bits(), "column {col}, pixel {k}");
            }
        }
        // the disc and the corners outside it
        assert!(with_rays > n * n / 2 && with_rays < n * n, "{with_rays}");
    }

    #[test]
    fn angular_180_covers_a_hemisphere() {
        // The square image of a 180-degree angular fisheye reaches past 90 degrees in its
        // corners (Radiance gives rays there up to 127 degrees); evalglare drops the pixels
        // whose centre looks backwards, and so does the sum.
        let c = cam("-vta -vh 180 -vv 180 -vd 0 0 1 -vu 0 1 0");
        let s = sum_sangle(&c, 512, true);
        let rel = (s - 2.0 * PI).abs() / (2.0 * PI);
        eprintln!("sum {s}, relative error {rel:e}");
        assert!(rel < 0.005, "sum {s}, relative error {rel}");
    }

    #[test]
    fn angular_360_covers_the_sphere() {
        let c = cam("-vta -vh 360 -vv 360 -vd 1 0 0");
        let s = sum_sangle(&c, 512, false);
        let rel = (s - 4.0 * PI).abs() / (4.0 * PI);
        eprintln!("sum {s}, relative error {rel:e}");
        assert!(rel < 0.005, "sum {s}, relative error {rel}");
    }

    #[test]
    fn hemispherical_and_perspective_solid_angles() {
        // -vth: orthographic projection, so a small pixel at direction cosine z covers
        // (hn/xres)(vn/yres)/z steradians (Jacobian of the projection).
        let c = cam("-vth -vh 180 -vv 180 -vd 0 0 1 -vu 0 1 0");
        let n = 256;
        for (px, py) in [(128, 128), (40, 100), (200, 30), (20, 128)] {
            let r = c.pixel_ray(px, py, n, n).unwrap();
            let want = (2.0 / n as f64) * (2.0 / n as f64) / r.dir[2];
            let got = c.pixel_solid_angle(px, py, n, n);
            // 2e-3: the Jacobian changes across a pixel near the rim ((200,30) has z = 0.31).
            assert!((got - want).abs() / want < 2e-3, "({px},{py}) {got} {want}");
        }
        // A 90x90 perspective view sees a sixth of the sphere (a cube face): 4π/6.
        let c = cam("-vtv -vh 90 -vv 90");
        let s = sum_sangle(&c, 64, false);
        assert!((s - 4.0 * PI / 6.0).abs() < 1e-9, "sum {s}");
    }

    #[test]
    fn setup_limits() {
        let bad = |s: &str| {
            let mut v = View::default();
            v.apply_str(s, "t").unwrap();
            v.setup().unwrap_err().to_string()
        };
        assert!(bad("-vtv -vh 180").contains("illegal horizontal view size"));
        assert!(bad("-vtv -vv 179.9999999").contains("illegal vertical view size"));
        assert!(bad("-vth -vh 180.1").contains("illegal horizontal view size"));
        assert!(bad("-vta -vv 360.1").contains("illegal vertical view size"));
        assert!(bad("-vts -vh 360").contains("illegal horizontal view size"));
        assert!(bad("-vtc -vv 180").contains("illegal vertical view size"));
        assert!(bad("-vtl -vh 0").contains("illegal horizontal view size"));
        assert!(bad("-vo 2 -va 1").contains("illegal fore/aft clipping plane"));
        assert!(bad("-vu 0 0 0").contains("zero view up vector"));
        for ok in [
            "-vth -vh 180 -vv 180",
            "-vta -vh 360 -vv 360",
            "-vtc -vh 360 -vv 100",
        ] {
            let mut v = View::default();
            v.apply_str(ok, "t").unwrap();
            assert!(v.setup().is_ok(), "{ok}");
        }
    }

    #[test]
    fn normaspect_cases() {
        // 60x40 perspective: aspect tan(20)/tan(30).
        let c = cam("-vtv -vh 60 -vv 40");
        assert_eq!(c.normalize_resolution(16, 12, 1.0).0, 16);
        assert_eq!(c.normalize_resolution(16, 12, 1.0).1, 10);
        let (x, y, pa) = c.normalize_resolution(16, 12, 0.0);
        assert_eq!((x, y), (16, 12));
        assert!((pa - c.aspect() * 16.0 / 12.0).abs() < 1e-15);
    }

    #[test]
    fn view_loc_inverts_view_ray_for_every_type() {
        for s in [
            "-vtv -vh 60 -vv 40 -vd 1 2 0.3 -vu 0 0 1 -vs 0.2 -vl -0.1",
            "-vth -vh 170 -vv 150 -vd 1 -1 0.5 -vu 0 0 1",
            "-vta -vh 200 -vv 180 -vd 0 0 1 -vu 0 1 0 -vs 0.1",
            "-vtl -vh 5 -vv 3 -vd 0.2 1 -0.3 -vp 1 2 3",
            "-vtc -vh 300 -vv 80 -vd 1 0 0 -vl 0.1",
            "-vts -vh 250 -vv 250 -vd 0 1 0.2",
        ] {
            let c = cam(s);
            for &(x, y) in &[(0.5, 0.5), (0.3, 0.7), (0.9, 0.2), (0.55, 0.45)] {
                let Some(r) = c.view_ray(x, y) else { continue };
                let p = add(r.org, scale(r.dir, 3.0));
                let l = c.view_loc(p).unwrap();
                assert!(
                    (l.x - x).abs() < 1e-9 && (l.y - y).abs() < 1e-9,
                    "{s} {x} {y} {l:?}"
                );
            }
        }
    }
}
