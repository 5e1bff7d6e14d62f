//! Reflectance from an ordinary photograph (Ferwerda 2018, as applied in the seed
//! dissertation's chapter 5): decode the sRGB transfer, adapt the camera's white to
//! equal-energy white, average over material masks.
//!
//! For each material region `m` of the mask:
//!
//! ```text
//! c_m   = mean over the region's pixels of srgb_decode(pixel)     (IEC 61966-2-1)
//! XYZ_m = M_srgb c_m                                              (sRGB primaries, D65)
//! rho_m = M_rad^-1 A^-1 diag(A XYZ_target / A XYZ_white) A XYZ_m  (von Kries-type CAT)
//! ```
//!
//! `A` is the chromatic adaptation transform's cone-like space ([`Cat`]): Bradford (Lam
//! 1985; the matrix of CIECAM97s and of the ICC v4 profile connection, values from
//! Lindbloom's "Chromatic Adaptation" tables), von Kries with the Hunt-Pointer-Estevez cone
//! fundamentals normalised to D65, or plain XYZ scaling. `M_rad` is Radiance's RGB
//! (standard primaries, equal-energy white, [`crate::colour::cie::Observer`]), so `rho_m` is
//! a Radiance RGB reflectance ready for a `plastic`.
//!
//! The source white (`XYZ_white`, the colour the camera recorded for a known surface) and its
//! target (`XYZ_target`, that surface's colour under equal-energy light) come from
//! ([`White`]):
//!
//! - a reference patch of known reflectance in the legend (a white or grey card photographed
//!   beside the samples, Ferwerda's protocol; each material may name its own card) or a
//!   rectangle of the picture: white = the patch's mean, target = its known reflectance;
//!   this also fixes the absolute scale (exposure);
//! - grey world: white = the mean of every labelled pixel, target = a grey of the given
//!   reflectance (the assumed scene average);
//! - the camera: white = sRGB's own white (1, 1, 1) = D65, target = equal-energy white: the
//!   camera's white balance and exposure are trusted, pixel value 1 = reflectance 1.
//!
//! Clipped pixels (any channel at or above [`CLIPPED`] after decoding) are left out of every
//! mean: a clipped channel underestimates its colour.

use crate::error::{Error, Result};
use crate::formats::picture::Picture;

use super::mask::LabelMap;
use crate::colour::cie::{Observer, RgbSpace, inv3, linear_to_srgb, mul3};

/// Linear value at or above which a channel counts as clipped (254.5/255 decoded).
pub const CLIPPED: f64 = 0.99;

/// Chromatic adaptation transform.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cat {
    /// Bradford (Lam 1985), the default: the CAT of CIECAM97s and ICC v4.
    Bradford,
    /// von Kries with Hunt-Pointer-Estevez cone fundamentals (normalised to D65).
    VonKries,
    /// Scaling of X, Y, Z (the crudest; for comparison).
    XyzScaling,
}

impl Cat {
    /// XYZ -> cone-like responses (Lindbloom, "Chromatic Adaptation").
    pub fn matrix(self) -> [[f64; 3]; 3] {
        match self {
            Cat::Bradford => [
                [0.8951, 0.2664, -0.1614],
                [-0.7502, 1.7135, 0.0367],
                [0.0389, -0.0685, 1.0296],
            ],
            Cat::VonKries => [
                [0.40024, 0.70760, -0.08081],
                [-0.22630, 1.16532, 0.04570],
                [0.0, 0.0, 0.91822],
            ],
            Cat::XyzScaling => [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    /// The 3 x 3 matrix taking XYZ seen under the source (where a surface of colour `target`
    /// was recorded as `white`) to XYZ under the target's light.
    pub fn adaptation(self, white: [f64; 3], target: [f64; 3]) -> [[f64; 3]; 3] {
        let a = self.matrix();
        let ai = inv3(a);
        let (ws, wt) = (mul3(&a, white), mul3(&a, target));
        let d: [f64; 3] = std::array::from_fn(|i| wt[i] / ws[i]);
        // A^-1 diag(d) A
        std::array::from_fn(|r| {
            std::array::from_fn(|c| (0..3).map(|k| ai[r][k] * d[k] * a[k][c]).sum())
        })
    }
}

/// Where the camera's white comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum White {
    /// The reference patches of the legend (entries with a known reflectance).
    Legend,
    /// A rectangle `x0 y0 x1 y1` (inclusive pixel bounds, `y` from the top) of known
    /// reflectance (Radiance RGB).
    Rect { rect: [usize; 4], known: [f64; 3] },
    /// Grey world: the labelled pixels average to this grey reflectance.
    GreyWorld(f64),
    /// Trust the camera: sRGB white (1, 1, 1) is a perfect white.
    Camera,
}

/// The estimate for one material.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    pub name: String,
    /// Radiance RGB reflectance.
    pub rgb: [f64; 3],
    /// Pixels averaged.
    pub pixels: usize,
    /// Pixels left out because a channel was clipped.
    pub clipped: usize,
    /// The white it was adapted from: a reference patch's name, `rect`, `grey-world` or
    /// `camera`.
    pub white: String,
    /// True for the reference patches themselves.
    pub is_reference: bool,
}

/// Mean linear RGB of pixels (indices into `photo`), skipping clipped ones.
fn mean_rgb(photo: &Picture, pixels: impl Iterator<Item = usize>) -> ([f64; 3], usize, usize) {
    let mut sum = [0.0; 3];
    let (mut n, mut clipped) = (0, 0);
    for i in pixels {
        let px = &photo.data[3 * i..3 * i + 3];
        if px.iter().any(|&v| v as f64 >= CLIPPED) {
            clipped += 1;
            continue;
        }
        for c in 0..3 {
            sum[c] += px[c] as f64;
        }
        n += 1;
    }
    (sum.map(|s| s / n.max(1) as f64), n, clipped)
}

/// Ferwerda's estimate for every material of the mask. `photo` holds linear sRGB values
/// (what [`crate::formats::picture::preview::read_photo`] returns).
pub fn estimate(
    photo: &Picture,
    mask: &LabelMap,
    white: &White,
    cat: Cat,
) -> Result<Vec<Estimate>> {
    if photo.ncomp() != 3 {
        return Err(Error::Mismatch(format!(
            "a photo has 3 channels, this picture has {}",
            photo.ncomp()
        )));
    }
    mask.check_size(photo.width, photo.height, "the photo")?;
    let srgb = Observer::new(RgbSpace::SrgbLinear);
    let rad = Observer::new(RgbSpace::Radiance);
    let regions = mask.regions();
    let means: Vec<([f64; 3], usize, usize)> = regions
        .iter()
        .map(|r| mean_rgb(photo, r.iter().copied()))
        .collect();
    let xyz_rad = |rgb: [f64; 3]| rad.rgb_to_xyz(rgb);
    // (camera XYZ of the white, its target XYZ under E, label of the white)
    let global: Option<([f64; 3], [f64; 3], String)> = match white {
        White::Legend => None,
        White::Camera => Some((srgb.white, rad.white, "camera".into())),
        White::GreyWorld(g) => {
            if !(*g > 0.0 && *g <= 1.0) {
                return Err(Error::Usage(format!(
                    "grey world reflectance must be in (0, 1], got {g}"
                )));
            }
            let (m, n, _) = mean_rgb(photo, regions.iter().flatten().copied());
            if n == 0 {
                return Err(Error::Usage(
                    "grey world: the mask labels no unclipped pixel".into(),
                ));
            }
            Some((
                srgb.rgb_to_xyz(m),
                rad.white.map(|w| w * g),
                "grey-world".into(),
            ))
        }
        White::Rect { rect, known } => {
            let [x0, y0, x1, y1] = *rect;
            if x0 > x1 || y0 > y1 || x1 >= photo.width || y1 >= photo.height {
                return Err(Error::Usage(format!(
                    "white rectangle {x0} {y0} {x1} {y1} is not inside the {} x {} photo \
                     (x0 y0 x1 y1, inclusive, y from the top)",
                    photo.width, photo.height
                )));
            }
            let w = photo.width;
            let (m, n, _) = mean_rgb(
                photo,
                (y0..=y1).flat_map(move |y| (x0..=x1).map(move |x| y * w + x)),
            );
            if n == 0 {
                return Err(Error::Usage(
                    "white rectangle: every pixel is clipped; expose the photo for the card".into(),
                ));
            }
            Some((srgb.rgb_to_xyz(m), xyz_rad(*known), "rect".into()))
        }
    };
    let entries = &mask.legend.entries;
    let first_ref = entries.iter().position(|e| e.known.is_some());
    if global.is_none() && first_ref.is_none() {
        return Err(Error::Usage(
            "no white reference: mark a card in the legend (a known reflectance), or give a \
             rectangle, grey world or the camera's white"
                .into(),
        ));
    }
    let mut out = Vec::new();
    for (i, e) in entries.iter().enumerate() {
        let (mean, n, clipped) = means[i];
        if n == 0 {
            continue;
        }
        let (w_xyz, target, label) = match &global {
            Some(g) => g.clone(),
            None => {
                // The material's own card, else the first card.
                let r = match &e.reference {
                    Some(name) => mask.legend.find(name).unwrap_or(0),
                    None if e.known.is_some() => i,
                    None => first_ref.unwrap_or(0),
                };
                let (rm, rn, _) = means[r];
                if rn == 0 {
                    return Err(Error::Usage(format!(
                        "reference patch '{}' has no unclipped pixel in the mask",
                        entries[r].name
                    )));
                }
                let known = entries[r].known.unwrap_or([1.0; 3]);
                (srgb.rgb_to_xyz(rm), xyz_rad(known), entries[r].name.clone())
            }
        };
        let adapt = cat.adaptation(w_xyz, target);
        let xyz = mul3(&adapt, srgb.rgb_to_xyz(mean));
        out.push(Estimate {
            name: e.name.clone(),
            rgb: rad.xyz_to_rgb(xyz),
            pixels: n,
            clipped,
            white: label,
            is_reference: e.known.is_some(),
        });
    }
    Ok(out)
}

/// A simple camera for synthetic tests: Radiance RGB radiance -> XYZ -> linear sRGB (no
/// white balance: the camera is set to D65 "daylight"), times `exposure`, clipped to 1,
/// sRGB-encoded to 8 bits. So a perfect white under equal-energy light of radiance
/// `1/exposure` is recorded as sRGB's reading of E: (1.21, 0.95, 0.91) before clipping,
/// i.e. pinkish, which the CAT must undo.
pub fn camera_srgb(radiance: &Picture, exposure: f64) -> Result<image::RgbImage> {
    if radiance.ncomp() != 3 {
        return Err(Error::Mismatch(format!(
            "the camera takes RGB pictures, this one has {} channels",
            radiance.ncomp()
        )));
    }
    let rad = Observer::new(RgbSpace::Radiance);
    let srgb = Observer::new(RgbSpace::SrgbLinear);
    let values = radiance.radiance_values();
    let (w, h) = (
        u32::try_from(radiance.width).map_err(|_| Error::Usage("picture too wide".into()))?,
        u32::try_from(radiance.height).map_err(|_| Error::Usage("picture too tall".into()))?,
    );
    let mut img = image::RgbImage::new(w, h);
    for (px, v) in img.pixels_mut().zip(values.chunks_exact(3)) {
        // Both spaces are linear: rgb_to_xyz / xyz_to_rgb apply no transfer curve.
        let lin = srgb.xyz_to_rgb(rad.rgb_to_xyz([v[0] as f64, v[1] as f64, v[2] as f64]));
        for (o, l) in px.0.iter_mut().zip(lin) {
            let e = linear_to_srgb((exposure * l).clamp(0.0, 1.0));
            *o = (e * 255.0).round() as u8;
        }
    }
    Ok(img)
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // matrix checks index rows and columns
mod tests {
    use super::*;
    use crate::formats::picture::PixelFormat;
    use crate::mask::Legend;
    use crate::radiometry::Channels;

    fn photo_of(colours: &[[f64; 3]], light: [f64; 3], exposure: f64) -> (Picture, LabelMap) {
        // One column of 4 x 4 pixels per colour, radiance = rho * light / pi, then the camera.
        let n = colours.len();
        let mut p = Picture::new(4 * n, 4, Channels::rgb(), PixelFormat::Rgbe);
        let mut mask = image::RgbImage::new(4 * n as u32, 4);
        for y in 0..4 {
            for x in 0..4 * n {
                let k = x / 4;
                for c in 0..3 {
                    p.data[3 * (y * 4 * n + x) + c] =
                        (colours[k][c] * light[c] / std::f64::consts::PI) as f32;
                }
                mask.put_pixel(x as u32, y as u32, image::Rgb([10 * k as u8 + 10, 0, 0]));
            }
        }
        let img = camera_srgb(&p, exposure).unwrap();
        let mut lin = Picture::new(4 * n, 4, Channels::rgb(), PixelFormat::Rgbe);
        for (d, s) in lin.data.iter_mut().zip(img.as_raw()) {
            *d = crate::colour::cie::srgb_to_linear(*s as f64 / 255.0) as f32;
        }
        let mut legend = String::new();
        for k in 0..n {
            let known = if k == 0 { ", 0.9" } else { "" };
            legend.push_str(&format!("{:02x}0000, m{k}{known}\n", 10 * k + 10));
        }
        let legend = Legend::parse(&legend, "l.csv").unwrap();
        (
            lin,
            LabelMap::from_image(&mask, Some(legend), "m.png").unwrap(),
        )
    }

    #[test]
    fn adaptation_maps_white_to_target() {
        let rad = Observer::new(RgbSpace::Radiance);
        let srgb = Observer::new(RgbSpace::SrgbLinear);
        for cat in [Cat::Bradford, Cat::VonKries, Cat::XyzScaling] {
            let m = cat.adaptation(srgb.white, rad.white);
            let w = mul3(&m, srgb.white);
            for c in 0..3 {
                assert!((w[c] - rad.white[c]).abs() < 1e-12, "{cat:?} {w:?}");
            }
            // Identity when source and target agree.
            let id = cat.adaptation([0.3, 0.4, 0.5], [0.3, 0.4, 0.5]);
            for r in 0..3 {
                for c in 0..3 {
                    assert!((id[r][c] - if r == c { 1.0 } else { 0.0 }).abs() < 1e-12);
                }
            }
        }
        // Bradford D65 -> D50 against Lindbloom's published matrix (whites 0.95047 1 1.08883
        // and 0.96422 1 0.82521): 1.0478112 0.0228866 -0.0501270 / 0.0295424 0.9904844
        // -0.0170491 / -0.0092345 0.0150436 0.7521316.
        let m = Cat::Bradford.adaptation([0.95047, 1.0, 1.08883], [0.96422, 1.0, 0.82521]);
        let want = [
            [1.0478112, 0.0228866, -0.0501270],
            [0.0295424, 0.9904844, -0.0170491],
            [-0.0092345, 0.0150436, 0.7521316],
        ];
        for r in 0..3 {
            for c in 0..3 {
                assert!((m[r][c] - want[r][c]).abs() < 1e-7, "{m:?}");
            }
        }
    }

    #[test]
    fn recovers_reflectance_under_white_and_tinted_light() {
        // Colours inside the sRGB gamut (the camera clips negative sRGB values).
        let colours = [[0.9; 3], [0.6, 0.4, 0.3], [0.25, 0.4, 0.6], [0.1, 0.1, 0.1]];
        // Equal-energy light: the card fixes scale and white exactly (8-bit quantisation
        // only).
        let (p, m) = photo_of(&colours, [1.0; 3], 2.0);
        let est = estimate(&p, &m, &White::Legend, Cat::Bradford).unwrap();
        assert_eq!(est.len(), 4);
        for (e, c) in est.iter().zip(&colours) {
            for k in 0..3 {
                assert!((e.rgb[k] - c[k]).abs() < 0.01, "{e:?} vs {c:?}");
            }
        }
        assert!(est[0].is_reference && !est[1].is_reference);
        // Warm light: the CAT removes most of the tint (a diagonal in Radiance RGB is not a
        // diagonal in Bradford space, so not all).
        let (p, m) = photo_of(&colours, [1.0, 0.8, 0.55], 2.0);
        let b = estimate(&p, &m, &White::Legend, Cat::Bradford).unwrap();
        let none = estimate(&p, &m, &White::Camera, Cat::Bradford).unwrap();
        for k in 1..4 {
            let err = |e: &Estimate| {
                (0..3)
                    .map(|c| (e.rgb[c] - colours[k][c]).abs())
                    .fold(0.0, f64::max)
            };
            assert!(err(&b[k]) < 0.03, "{:?}", b[k]);
            assert!(err(&none[k]) > 2.0 * err(&b[k]), "{:?}", none[k]);
        }
        // A rectangle over the card is the same as the legend's card.
        let r = estimate(
            &p,
            &m,
            &White::Rect {
                rect: [0, 0, 3, 3],
                known: [0.9; 3],
            },
            Cat::Bradford,
        )
        .unwrap();
        for k in 0..4 {
            for c in 0..3 {
                assert!((r[k].rgb[c] - b[k].rgb[c]).abs() < 1e-9);
            }
        }
        // Grey world with the true mean grey of the scene (luminance-wise) is close.
        let g = estimate(&p, &m, &White::GreyWorld(0.45), Cat::Bradford).unwrap();
        assert!(g.iter().all(|e| e.rgb.iter().all(|v| v.is_finite())));
        assert!(
            estimate(
                &p,
                &m,
                &White::Rect {
                    rect: [0, 0, 99, 3],
                    known: [0.9; 3]
                },
                Cat::Bradford
            )
            .is_err()
        );
    }

    #[test]
    fn clipped_pixels_are_skipped() {
        let (mut p, m) = photo_of(&[[0.9; 3], [0.5; 3]], [1.0; 3], 2.0);
        // Clip half the pixels of material 1.
        for y in 0..2 {
            for x in 4..8 {
                p.data[3 * (y * 8 + x)] = 1.0;
            }
        }
        let e = estimate(&p, &m, &White::Legend, Cat::Bradford).unwrap();
        assert_eq!((e[1].pixels, e[1].clipped), (8, 8));
        assert!((e[1].rgb[0] - 0.5).abs() < 0.01);
    }
}
