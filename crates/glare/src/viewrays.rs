//! View rays for imageless (annual) glare: a coarse pixel grid over a view, one ray per
//! pixel centre with the pixel's solid angle, so daylight coefficients are computed for a
//! few thousand directions instead of every pixel of a picture.
//!
//! The grid is the picture evalglare would read at `n × n` pixels: the same ray through
//! each pixel centre (Radiance's `pix2loc`/`viewray`, [`Camera::pixel_ray`]), the same
//! solid angle (the spherical quadrilateral of the corner rays,
//! [`Camera::pixel_solid_angle`]) and the same validity rule as [`super::Pixels`] (a ray,
//! a positive solid angle and, for `-vta`, a centre ray that looks forward). So Σ ω cos over
//! the rays is the picture's, and a 64 × 64 grid of a 180° angular fisheye (3 200 rays,
//! 1e-3 sr each) integrates E_v as a 64-pixel picture would.
//!
//! Neighbours (8-connected grid cells) are kept so bright rays can be merged into glare
//! sources the way connected pixels are.

use super::pixels::{V3, dot};
use crate::error::{Error, Result};
use crate::formats::view::{Camera, View, ViewType};

/// The rays of one view.
#[derive(Debug, Clone)]
pub struct ViewRays {
    /// Grid size (pixels per side).
    pub n: usize,
    /// The camera the rays come from.
    pub camera: Camera,
    /// Ray origin (the view point moved to the fore clipping distance).
    pub org: Vec<V3>,
    /// Unit directions.
    pub dir: Vec<V3>,
    /// Solid angle per ray (sr).
    pub omega: Vec<f64>,
    /// Grid cell (column, row from the top) of every ray.
    pub cell: Vec<(usize, usize)>,
    /// Ray index of every grid cell (`row * n + column`), `None` outside the view.
    pub index: Vec<Option<usize>>,
}

/// Largest grid accepted (a 512² grid is already a picture: 200 000 rays).
pub const MAX_GRID: usize = 512;

impl ViewRays {
    /// The `n × n` grid of `view`. Errors: a parallel view, an invalid view, `n` outside
    /// 4..=[`MAX_GRID`].
    pub fn new(view: &View, n: usize) -> Result<ViewRays> {
        if view.vtype == ViewType::Parallel {
            return Err(Error::Usage(
                "parallel view (-vtl) cannot be evaluated for glare; expected a fisheye or perspective view".into(),
            ));
        }
        if !(4..=MAX_GRID).contains(&n) {
            return Err(Error::Usage(format!(
                "--rays {n}: expected a grid of 4 to {MAX_GRID} rays per side"
            )));
        }
        let camera = view.setup()?;
        let vdir = camera.dir();
        let angular = view.vtype == ViewType::Angular;
        let mut r = ViewRays {
            n,
            camera,
            org: Vec::new(),
            dir: Vec::new(),
            omega: Vec::new(),
            cell: Vec::new(),
            index: vec![None; n * n],
        };
        for row in 0..n {
            for col in 0..n {
                let Some(ray) = camera.pixel_ray(col, row, n, n) else {
                    continue;
                };
                let omega = camera.pixel_solid_angle(col, row, n, n);
                if omega <= 0.0 || (angular && dot(ray.dir, vdir) < 0.0) {
                    continue;
                }
                r.index[row * n + col] = Some(r.dir.len());
                r.org.push(ray.org);
                r.dir.push(ray.dir);
                r.omega.push(omega);
                r.cell.push((col, row));
            }
        }
        if r.dir.is_empty() {
            return Err(Error::Usage("the view has no rays; check -vh/-vv".into()));
        }
        Ok(r)
    }

    /// Number of rays.
    pub fn len(&self) -> usize {
        self.dir.len()
    }

    /// True when there are no rays (never for a constructed grid).
    pub fn is_empty(&self) -> bool {
        self.dir.is_empty()
    }

    /// Indices of the 8-connected neighbours of ray `i`.
    pub fn neighbours(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let (c, r) = self.cell[i];
        let n = self.n as isize;
        (-1isize..=1)
            .flat_map(move |dr| (-1isize..=1).map(move |dc| (dr, dc)))
            .filter(|&(dr, dc)| dr != 0 || dc != 0)
            .filter_map(move |(dr, dc)| {
                let (rr, cc) = (r as isize + dr, c as isize + dc);
                if rr < 0 || cc < 0 || rr >= n || cc >= n {
                    None
                } else {
                    self.index[(rr * n + cc) as usize]
                }
            })
    }

    /// Σ ω over the rays (2π for a 180° fisheye, up to the rim).
    pub fn total_solid_angle(&self) -> f64 {
        self.omega.iter().sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fisheye(vt: &str) -> View {
        let mut v = View::default();
        v.apply_arg(&[vt]).unwrap();
        v.apply_arg(&["-vh", "180"]).unwrap();
        v.apply_arg(&["-vv", "180"]).unwrap();
        v.apply_arg(&["-vd", "0", "-1", "0"]).unwrap();
        v
    }

    #[test]
    fn angular_fisheye_covers_the_hemisphere() {
        let r = ViewRays::new(&fisheye("-vta"), 64).unwrap();
        // a disc of the 64² grid: about π/4 of the cells
        assert!((3000..3300).contains(&r.len()), "{}", r.len());
        let w = r.total_solid_angle();
        assert!((w - 2.0 * std::f64::consts::PI).abs() < 0.1, "{w}");
        // Σ ω cos = π (the cosine-weighted hemisphere), within the rim's coarseness
        let vdir = r.camera.dir();
        let e: f64 = (0..r.len()).map(|i| r.omega[i] * dot(r.dir[i], vdir)).sum();
        assert!((e - std::f64::consts::PI).abs() < 0.02, "{e}");
    }

    #[test]
    fn neighbours_are_adjacent_cells() {
        let r = ViewRays::new(&fisheye("-vth"), 16).unwrap();
        let mid = r.index[8 * 16 + 8].unwrap();
        assert_eq!(r.neighbours(mid).count(), 8);
        for j in r.neighbours(mid) {
            let (c, w) = r.cell[j];
            assert!(c.abs_diff(8) <= 1 && w.abs_diff(8) <= 1);
        }
    }

    #[test]
    fn bad_grids_are_usage_errors() {
        assert!(ViewRays::new(&fisheye("-vta"), 2).is_err());
        assert!(ViewRays::new(&fisheye("-vta"), 100_000).is_err());
    }
}
