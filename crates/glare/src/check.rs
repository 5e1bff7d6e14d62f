//! The check picture (`-c file`): the evaluated picture with every glare-source pixel
//! recoloured by its source number, luminance kept, and pixels outside the evaluated field
//! (invalid) set to black, as evalglare's `setglcolor` and its E_v pass do. Colours cycle
//! through evalglare's palette (source n uses entry `n mod 5 + 1`: green, blue-ish, olive,
//! purple, teal); each colour is scaled so the pixel's luminance is unchanged.

use super::{Evaluation, Pixels};
use crate::formats::picture::{Picture, PixelFormat};
use crate::radiometry::Channels;

/// evalglare's palette (relative luminance shares before division by CIE_rf/gf/bf).
const PALETTE: [[f64; 3]; 7] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.15, 0.15, 0.7],
    [0.5, 0.5, 0.0],
    [0.5, 0.0, 0.5],
    [0.0, 0.5, 0.5],
    [0.333, 0.333, 0.333],
];

use crate::radiometry::RGB_PHOTOPIC as CIE;

/// The check picture (RGBE, the source picture's header lines kept). Only `pic`'s header
/// is read: its pixel values may already be freed.
pub fn check_picture(pic: &Picture, p: &Pixels, e: &Evaluation) -> Picture {
    let (w, h) = (p.xres, p.yres);
    let mut out = Picture::new(w, h, Channels::rgb(), PixelFormat::Rgbe);
    out.header = pic.header.clone();
    out.header.lines.retain(|l| !l.starts_with("EXPOSURE="));
    for x in 0..w {
        for y in 0..h {
            let i = p.at(x, y);
            let row = h - 1 - y;
            let at = (row * w + x) * 3;
            if !(p.inview[i] && p.valid[i]) {
                continue;
            }
            let l = p.lum[i];
            let g = e.gsn[i];
            let rgb = if g > 0 {
                let c = PALETTE[g as usize % 5 + 1];
                [
                    c[0] / CIE[0] * l / 179.0,
                    c[1] / CIE[1] * l / 179.0,
                    c[2] / CIE[2] * l / 179.0,
                ]
            } else {
                [l / 179.0; 3]
            };
            for (o, v) in out.data[at..at + 3].iter_mut().zip(rgb) {
                *o = v as f32;
            }
        }
    }
    out
}
