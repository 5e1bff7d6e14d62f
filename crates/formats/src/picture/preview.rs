//! 8-bit previews (PNG, JPEG) of pictures, and photographs read as linear values.
//!
//! Reading undoes the sRGB transfer function (IEC 61966-2-1):
//! `v <= 0.04045 ? v / 12.92 : ((v + 0.055) / 1.055)^2.4`, giving *relative* linear RGB in
//! [0, 1] (a photograph carries no absolute radiance), stored as an RGBE picture.
//!
//! Writing tone-maps with a single multiplier and clipping, then applies the sRGB transfer
//! function: `out = srgb(min(1, k v))`. With [`Exposure::Auto`], `k` maps the log-average
//! luminance of the picture to 0.18 (Reinhard et al. 2002's "key" of a normal scene);
//! [`Exposure::Stops`] multiplies by `2^stops` as `pfilt -e +N` and `ra_tiff -e +N` do. The
//! curve is monotonic in every channel. Values are the picture's stored values (the
//! exposure in its header included), as Radiance's `ra_*` converters use them. XYZE pixels
//! are converted with the XYZ to linear sRGB matrix of IEC 61966-2-1; spectral pixels with
//! Radiance's band averages (`scolor2color`).

use super::{Picture, PixelFormat, spectral};
use crate::error::{Error, Location, Result};
use crate::radiometry::{Channels, RGB_PHOTOPIC};
use std::path::Path;

/// How bright the preview is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Exposure {
    /// Log-average luminance to 0.18.
    Auto,
    /// Multiply by `2^stops`.
    Stops(f64),
}

/// The sRGB transfer curves (IEC 61966-2-1) have one home, `colour::cie`.
use crate::colour::cie::{linear_to_srgb as srgb_encode, srgb_to_linear as srgb_decode};

/// XYZ to linear sRGB (IEC 61966-2-1).
const XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.2406, -1.5372, -0.4986],
    [-0.9689, 1.8758, 0.0415],
    [0.0557, -0.2040, 1.0570],
];

/// The RGB triple of each pixel (stored values), whatever the pixel format.
fn rgb_pixels(p: &Picture) -> Vec<[f64; 3]> {
    let nc = p.ncomp();
    p.data
        .chunks_exact(nc)
        .map(|px| match p.format {
            PixelFormat::Rgbe => [px[0] as f64, px[1] as f64, px[2] as f64],
            PixelFormat::Xyze => {
                let m = XYZ_TO_SRGB;
                let x = [px[0] as f64, px[1] as f64, px[2] as f64];
                [0, 1, 2].map(|r| (0..3).map(|c| m[r][c] * x[c]).sum::<f64>())
            }
            PixelFormat::Spectra => spectral::to_rgb(px, p.channels.splits).map(|v| v as f64),
        })
        .collect()
}

/// The tone-mapped 8-bit RGB preview of `p`.
pub fn tone_map(p: &Picture, exposure: Exposure) -> Result<image::RgbImage> {
    p.check_shape()?;
    let (w, h) = (
        u32::try_from(p.width).map_err(|_| Error::Usage("picture too wide".into()))?,
        u32::try_from(p.height).map_err(|_| Error::Usage("picture too tall".into()))?,
    );
    let rgb = rgb_pixels(p);
    let k = match exposure {
        Exposure::Stops(s) => 2f64.powf(s),
        Exposure::Auto => {
            // Log average with a small floor so black pixels do not drive it to zero.
            let lum = |c: &[f64; 3]| (0..3).map(|i| RGB_PHOTOPIC[i] * c[i]).sum::<f64>();
            let mean_log = rgb
                .iter()
                .map(|c| (lum(c).max(0.0) + 1e-9).ln())
                .sum::<f64>()
                / rgb.len() as f64;
            0.18 / mean_log.exp()
        }
    };
    let mut img = image::RgbImage::new(w, h);
    for (px, c) in img.pixels_mut().zip(&rgb) {
        for (o, &v) in px.0.iter_mut().zip(c) {
            *o = (srgb_encode((k * v).clamp(0.0, 1.0)) * 255.0 + 0.5) as u8;
        }
    }
    Ok(img)
}

/// Write a tone-mapped preview; the format (PNG or JPEG) follows the file extension.
pub fn write_preview(p: &Picture, path: impl AsRef<Path>, exposure: Exposure) -> Result<()> {
    let path = path.as_ref();
    let shown = path.display().to_string();
    let img = tone_map(p, exposure)?;
    img.save(path)
        .map_err(|e| Error::Usage(format!("{shown}: cannot write preview: {e}")))
}

/// Read a PNG or JPEG as linear relative RGB (sRGB transfer function undone).
pub fn read_photo(path: impl AsRef<Path>) -> Result<Picture> {
    let path = path.as_ref();
    let shown = path.display().to_string();
    let dims = image::ImageReader::open(path)
        .map_err(|e| Error::io(&shown, e))?
        .with_guessed_format()
        .map_err(|e| Error::io(&shown, e))?
        .into_dimensions();
    check_photo_size(dims, &shown)?;
    let img = image::open(path).map_err(|e| match e {
        image::ImageError::IoError(e) => Error::io(&shown, e),
        other => Error::parse(
            Location::file(&shown),
            format!("not a PNG or JPEG picture: {other}"),
        ),
    })?;
    Ok(from_image(&img, &shown))
}

/// Read a PNG or JPEG from memory (`name` for messages and the header).
pub fn read_photo_bytes(bytes: &[u8], name: &str) -> Result<Picture> {
    let dims = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| Error::io(name, e))?
        .into_dimensions();
    check_photo_size(dims, name)?;
    let img = image::load_from_memory(bytes).map_err(|e| {
        Error::parse(
            Location::file(name),
            format!("not a PNG or JPEG picture: {e}"),
        )
    })?;
    Ok(from_image(&img, name))
}

/// The size a PNG or JPEG header claims, checked with [`super::check_size`] before the
/// pixels are decoded (as linear RGB `f32`, 12 bytes a pixel). An unreadable header is
/// left for the decoder to report.
pub fn check_photo_size(dims: image::ImageResult<(u32, u32)>, name: &str) -> Result<()> {
    match dims {
        Ok((w, h)) => super::check_size(name, w as usize, h as usize, 3),
        Err(_) => Ok(()),
    }
}

fn from_image(img: &image::DynamicImage, name: &str) -> Picture {
    // to_rgb32f scales 8- and 16-bit samples to [0, 1] without touching the transfer curve.
    let rgb = img.to_rgb32f();
    let mut p = Picture::new(
        rgb.width() as usize,
        rgb.height() as usize,
        Channels::rgb(),
        PixelFormat::Rgbe,
    );
    for (d, &v) in p.data.iter_mut().zip(rgb.as_raw()) {
        *d = srgb_decode(v as f64) as f32;
    }
    p.header.push(format!(
        "converted from {name} (sRGB decoded, relative values)"
    ));
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curves_invert() {
        for i in 0..=255 {
            let v = i as f64 / 255.0;
            assert!((srgb_encode(srgb_decode(v)) - v).abs() < 1e-12);
        }
    }
}
