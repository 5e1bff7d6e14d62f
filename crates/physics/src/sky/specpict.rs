//! The `specpict` sky that Radiance 6's `genssky` writes: an equirectangular hyperspectral
//! picture (`FORMAT=Radiance_spectra`) looked up by direction.
//!
//! genssky's output (radiance-notes.md 5.6):
//!
//! ```text
//! void specpict skyfunc 5 noop out_sky.hsr . 'Atan2(Dy,Dx)/PI+1' '1-Acos(Dz)/PI' 0 0
//! skyfunc glow skyglow 0 0 4 1 1 1 0          (added by the user)
//! skyglow source sky 0 0 4 0 0 1 180
//! ```
//!
//! What Radiance does with it (`src/rt/p_data.c: p_specpict`, `src/common/data.c: getspec`,
//! `data_interp`; `src/rt/rayinit.cal` for `Atan2`, `Acos`, `noop`):
//! - the picture is a data array with `y` (0 at the bottom row, 1 at the top) and `x`
//!   (0 at the left column, the aspect ratio `width/height` at the right) whose samples sit
//!   *on* the ends (`org + k siz / (n - 1)`), bilinearly interpolated;
//! - pixel values decode as `(mantissa + 0.5) 2^(exp - 136)`, zero for exponent 0;
//! - the picture's `NCOMP` bands (from `WAVELENGTH_SPLITS`, longest first) are rebinned to
//!   the run's channels like any spectrum ([`crate::material::spectrum`]); the result
//!   multiplies the glow's colour (`r->pcol`).
//!
//! Only genssky's mapping (the two expressions above, function `noop`, no `.cal` file) is
//! evaluated natively: `u = atan2(Dy, Dx)/pi + 1`, `v = 1 - acos(Dz)/pi` for the outgoing
//! direction `D`. Other expressions are refused by the caller with their location.

use crate::error::{Error, Location, Result};
use crate::formats::picture::Picture;
use crate::material::Color;
use crate::material::spectrum::Sampled;
use crate::radiometry::Channels;
use std::path::Path;

/// genssky's coordinate expressions, as it writes them.
pub const GENSSKY_X: &str = "Atan2(Dy,Dx)/PI+1";
pub const GENSSKY_Y: &str = "1-Acos(Dz)/PI";

/// An equirectangular spectral sky picture in the run's channels.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecPictSky {
    width: usize,
    height: usize,
    ncomp: usize,
    /// Rows from the bottom (Radiance's y = 0) up, `ncomp` values per pixel.
    data: Vec<f32>,
    /// Extent of the x and y axes (`aspect` and 1 for a wide picture).
    x_siz: f64,
    y_siz: f64,
}

impl SpecPictSky {
    /// Load `path` and convert every pixel to `ch`.
    pub fn load(path: &Path, ch: &Channels) -> Result<SpecPictSky> {
        let pic = Picture::open(path)?;
        Self::from_picture(&pic, ch, &path.display().to_string())
    }

    /// From a picture in memory (`name` for errors).
    pub fn from_picture(pic: &Picture, ch: &Channels, name: &str) -> Result<SpecPictSky> {
        let src = pic.channels;
        if src.ncomp <= 3 || pic.width < 2 || pic.height < 2 {
            return Err(Error::parse(
                Location::file(name),
                format!(
                    "specpict needs a hyperspectral picture (NCOMP > 3, at least 2 x 2 \
                     pixels); found NCOMP={} and {} x {} pixels",
                    src.ncomp, pic.width, pic.height
                ),
            ));
        }
        // Sample k of the picture is the centre of band k (longest first).
        let step = (src.splits[3] - src.splits[0]) / src.ncomp as f64;
        let first = src.splits[0] + 0.5 * step;
        let last = src.splits[3] - 0.5 * step;
        let n = ch.ncomp;
        let mut data = vec![0f32; pic.width * pic.height * n];
        let mut vals = vec![0.0; src.ncomp];
        for row in 0..pic.height {
            let y = pic.height - 1 - row;
            for x in 0..pic.width {
                for (v, p) in vals.iter_mut().zip(pic.pixel(x, row)) {
                    *v = f64::from(*p);
                }
                let c = Sampled::new(first, last, vals.clone()).to_channels(ch);
                let at = (y * pic.width + x) * n;
                data[at..at + n].copy_from_slice(c.as_slice());
            }
        }
        // getspec: the longer side spans the aspect ratio, the shorter 1.
        let (w, h) = (pic.width as f64, pic.height as f64);
        let (x_siz, y_siz) = if w >= h { (w / h, 1.0) } else { (1.0, h / w) };
        Ok(SpecPictSky {
            width: pic.width,
            height: pic.height,
            ncomp: n,
            data,
            x_siz,
            y_siz,
        })
    }

    /// Interpolated value for the outgoing unit direction `d`.
    pub fn lookup(&self, d: [f64; 3]) -> Color {
        let az = if d[0] * d[0] + d[1] * d[1] > 0.0 {
            d[1].atan2(d[0])
        } else {
            0.0
        };
        let u = az / std::f64::consts::PI + 1.0;
        let v = 1.0 - d[2].clamp(-1.0, 1.0).acos() / std::f64::consts::PI;
        // Index space and the cell (clamped as data_interp does; inside [0, siz] always).
        // Inside the range `data_interp`'s weights (`scene::specdata::data_interp_weights`)
        // are these bilinear ones; they are written `1 - f` here, as this code always has,
        // so genssky skies keep their exact bits.
        let cell = |t: f64, siz: f64, ne: usize| -> (usize, f64) {
            let x = t / siz * (ne - 1) as f64;
            let i = (x.floor().max(0.0) as usize).min(ne - 2);
            (i, (x - i as f64).clamp(0.0, 1.0))
        };
        let (ix, fx) = cell(u, self.x_siz, self.width);
        let (iy, fy) = cell(v, self.y_siz, self.height);
        let n = self.ncomp;
        let px = |x: usize, y: usize| &self.data[(y * self.width + x) * n..][..n];
        let mut out = [0f32; crate::radiometry::MAX_SAMPLES];
        for (k, o) in out[..n].iter_mut().enumerate() {
            let a = f64::from(px(ix, iy)[k]) * (1.0 - fx) + f64::from(px(ix + 1, iy)[k]) * fx;
            let b =
                f64::from(px(ix, iy + 1)[k]) * (1.0 - fx) + f64::from(px(ix + 1, iy + 1)[k]) * fx;
            *o = (a * (1.0 - fy) + b * fy) as f32;
        }
        Color::from_slice(&out[..n])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formats::picture::PixelFormat;

    fn sky() -> SpecPictSky {
        // 4 x 2 picture, 4 bands; value = band index + 10 x column + 100 x (row from top).
        let ch = Channels::spectral(4, 380.0, 780.0).unwrap();
        let mut p = Picture::new(4, 2, ch, PixelFormat::Spectra);
        for row in 0..2 {
            for x in 0..4 {
                for b in 0..4 {
                    p.data[(row * 4 + x) * 4 + b] = (b + 10 * x + 100 * row) as f32;
                }
            }
        }
        SpecPictSky::from_picture(&p, &ch, "t.hsr").unwrap()
    }

    #[test]
    fn zenith_is_the_top_row_and_nadir_the_bottom() {
        let s = sky();
        // Straight up: v = 1 (top row, row 0 from the top); u = 1 (x = 1 of 2 -> column 1.5).
        let up = s.lookup([0.0, 0.0, 1.0]);
        assert!((up.as_slice()[0] - 15.0).abs() < 1e-4, "{up:?}");
        let down = s.lookup([0.0, 0.0, -1.0]);
        assert!((down.as_slice()[2] - 117.0).abs() < 1e-4, "{down:?}");
        // Horizon towards -x: atan2(0,-1) = pi -> u = 2, the last column; v = 0.5.
        let w = s.lookup([-1.0, 0.0, 0.0]);
        assert!(
            (w.as_slice()[1] - (1.0 + 30.0 + 50.0)).abs() < 1e-4,
            "{w:?}"
        );
    }

    #[test]
    fn rgb_pictures_are_refused() {
        let p = Picture::new(4, 2, Channels::rgb(), PixelFormat::Rgbe);
        let e = SpecPictSky::from_picture(&p, &Channels::rgb(), "t.hdr")
            .unwrap_err()
            .to_string();
        assert!(e.contains("NCOMP=3"), "{e}");
    }
}
