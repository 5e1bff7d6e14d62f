//! The figure machinery every rmetrics figure shares (maps, temporal maps, distributions):
//! one font, the palettes, and one way from a drawing to PNG or SVG bytes.
//!
//! Drawing goes through [`plotters`] so that one drawing function serves both outputs:
//! PNG through plotters' bitmap backend (rendered into an RGB buffer, encoded with the
//! `image` crate the workspace already uses) and SVG through its SVG backend. Text is set in
//! DejaVu Sans (a Latin-1 subset, `assets/fonts/`, Bitstream Vera licence), compiled into the
//! binary and rasterised by `ab_glyph`: no system font library, no fontconfig, the same
//! pixels on every machine. SVG files name the family (`sans-serif`) and let the viewer set
//! the text.
//!
//! Palettes ([`Palette`]): `viridis` (default; perceptually uniform, readable in grey and by
//! the colour-blind; matplotlib's map sampled at 10 points and interpolated linearly in sRGB)
//! and `falsecolor` (Radiance's `falsecolor` default palette `def`: the 23 linear RGB samples
//! of `def_redp/def_grnp/def_blup` in falsecolor.pl, interpolated linearly, then displayed
//! with Radiance's default gamma 2.2 as `ra_tiff`/`ra_ppm` would).

use crate::error::{Error, Result};
use image::RgbImage;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// DejaVu Sans, Latin-1 subset (`assets/fonts/README.md`).
pub static FONT: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans-subset.ttf");

/// The family every figure uses.
pub const FAMILY: &str = "sans-serif";

static FONT_ONCE: Once = Once::new();

/// Register the bundled font with plotters (once per process).
pub fn init_font() {
    FONT_ONCE.call_once(|| {
        // The bytes are compiled in and known to parse (a unit test checks it); a failure
        // here would only leave text undrawn, which the drawing then reports.
        let _ = plotters::style::register_font(FAMILY, FontStyle::Normal, FONT);
        let _ = plotters::style::register_font(FAMILY, FontStyle::Bold, FONT);
    });
}

/// A text style in the bundled font.
pub fn font(size: f64) -> TextStyle<'static> {
    init_font();
    (FAMILY, size).into_font().color(&BLACK)
}

/// Colour palette of a figure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Palette {
    /// Perceptually uniform (matplotlib's viridis): dark blue (low) to yellow (high).
    #[default]
    Viridis,
    /// Radiance's falsecolor `def` palette: purple/blue (low), green, red, yellow (high).
    Falsecolor,
}

/// matplotlib `viridis` at t = 0, 1/9, ..., 1 (sRGB).
const VIRIDIS: [[u8; 3]; 10] = [
    [0x44, 0x01, 0x54],
    [0x48, 0x28, 0x78],
    [0x3e, 0x49, 0x89],
    [0x31, 0x68, 0x8e],
    [0x26, 0x82, 0x8e],
    [0x1f, 0x9e, 0x89],
    [0x35, 0xb7, 0x79],
    [0x6e, 0xce, 0x58],
    [0xb5, 0xde, 0x2b],
    [0xfd, 0xe7, 0x25],
];

/// Radiance falsecolor.pl `def_redp`, `def_grnp`, `def_blup`: linear RGB at t = i/22.
const FC_RED: [f64; 23] = [
    0.18848,
    0.05468174,
    0.00103547,
    8.311144e-08,
    7.449763e-06,
    0.0004390987,
    0.001367254,
    0.003076,
    0.01376382,
    0.06170773,
    0.1739422,
    0.2881156,
    0.3299725,
    0.3552663,
    0.372552,
    0.3921184,
    0.4363976,
    0.6102754,
    0.7757267,
    0.9087369,
    1.0,
    1.0,
    0.9863,
];
const FC_GRN: [f64; 23] = [
    0.0009766,
    2.35501e-05,
    0.0008966244,
    0.0264977,
    0.1256843,
    0.2865799,
    0.4247083,
    0.4739468,
    0.4402732,
    0.3671876,
    0.2629843,
    0.1725325,
    0.1206819,
    0.07316644,
    0.03761026,
    0.01612362,
    0.004773749,
    6.830967e-06,
    0.00803605,
    0.1008085,
    0.3106831,
    0.6447838,
    0.9707,
];
const FC_BLU: [f64; 23] = [
    0.2666,
    0.3638662,
    0.4770437,
    0.5131397,
    0.5363797,
    0.5193677,
    0.4085123,
    0.1702815,
    0.05314236,
    0.05194055,
    0.08564082,
    0.09881395,
    0.08324373,
    0.06072902,
    0.0391076,
    0.02315354,
    0.01284458,
    0.005184709,
    0.001691774,
    2.432735e-05,
    1.212949e-05,
    0.006659406,
    0.02539,
];

/// Linear interpolation in a table sampled at t = i / (n - 1).
fn lerp_table(table: &[f64], t: f64) -> f64 {
    let x = t * (table.len() - 1) as f64;
    let i = (x.floor() as usize).min(table.len() - 2);
    let f = x - i as f64;
    table[i] + f * (table[i + 1] - table[i])
}

impl Palette {
    /// `viridis` or `falsecolor`.
    pub fn parse(s: &str) -> Result<Palette> {
        match s {
            "viridis" => Ok(Palette::Viridis),
            "falsecolor" | "def" => Ok(Palette::Falsecolor),
            _ => Err(Error::Usage(format!(
                "--palette: unknown palette '{s}'; one of viridis, falsecolor"
            ))),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Palette::Viridis => "viridis",
            Palette::Falsecolor => "falsecolor",
        }
    }

    /// sRGB colour of a normalised value `t` (clamped to [0, 1]; NaN counts as 0).
    pub fn colour(self, t: f64) -> [u8; 3] {
        let t = if t.is_finite() {
            t.clamp(0.0, 1.0)
        } else {
            0.0
        };
        match self {
            Palette::Viridis => {
                let x = t * (VIRIDIS.len() - 1) as f64;
                let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
                let f = x - i as f64;
                let c = |k: usize| {
                    let (a, b) = (VIRIDIS[i][k] as f64, VIRIDIS[i + 1][k] as f64);
                    (a + f * (b - a)).round() as u8
                };
                [c(0), c(1), c(2)]
            }
            Palette::Falsecolor => {
                // Radiance clips each channel to [0, 1], then displays with gamma 2.2.
                let g = |table: &[f64]| {
                    let v = lerp_table(table, t).clamp(0.0, 1.0);
                    (255.0 * v.powf(1.0 / 2.2)).round() as u8
                };
                [g(&FC_RED), g(&FC_GRN), g(&FC_BLU)]
            }
        }
    }

    /// Plotters colour of `t`.
    pub fn rgb(self, t: f64) -> RGBColor {
        let [r, g, b] = self.colour(t);
        RGBColor(r, g, b)
    }
}

/// Output format, from a file name's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Png,
    Svg,
}

impl Format {
    /// `.png` or `.svg` (any case); anything else is refused, naming the file.
    pub fn of(path: &str) -> Result<Format> {
        let ext = Path::new(path)
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("png") => Ok(Format::Png),
            Some("svg") => Ok(Format::Svg),
            _ => Err(Error::Usage(format!(
                "{path}: figures are written as .png or .svg; name the file with one of \
                 those extensions"
            ))),
        }
    }
}

/// A drawing failure (plotters reports backend and font errors this way).
pub fn draw_err<E: std::fmt::Debug>(e: E) -> Error {
    Error::Usage(format!("drawing the figure failed: {e:?}"))
}

/// A figure: a size in pixels and a drawing that works on any plotters backend.
pub trait Figure {
    fn size(&self) -> (u32, u32);
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>;
}

/// Rasterise a figure.
pub fn to_image(fig: &impl Figure) -> Result<RgbImage> {
    init_font();
    let (w, h) = fig.size();
    let mut buf = vec![255u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        fig.draw(&root)?;
        root.present().map_err(draw_err)?;
    }
    RgbImage::from_raw(w, h, buf)
        .ok_or_else(|| Error::Usage("drawing the figure failed: buffer size".into()))
}

/// PNG bytes of an image.
pub fn png_bytes(img: &RgbImage) -> Result<Vec<u8>> {
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(|e| Error::io("<png>", std::io::Error::other(e)))?;
    Ok(out.into_inner())
}

/// SVG text of a figure.
pub fn to_svg(fig: &impl Figure) -> Result<String> {
    init_font();
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, fig.size()).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        fig.draw(&root)?;
        root.present().map_err(draw_err)?;
    }
    Ok(s)
}

/// The figure's bytes in `format`.
pub fn encode(fig: &impl Figure, format: Format) -> Result<Vec<u8>> {
    match format {
        Format::Png => png_bytes(&to_image(fig)?),
        Format::Svg => Ok(to_svg(fig)?.into_bytes()),
    }
}

/// Write a figure to `path` (format from the extension), atomically.
pub fn write(fig: &impl Figure, path: &str) -> Result<()> {
    let bytes = encode(fig, Format::of(path)?)?;
    rdaylight_base::io::write_atomically(Path::new(path), |w| {
        w.write_all(&bytes).map_err(|e| Error::io(path, e))
    })
}

/// A "nice" step for about `n` intervals over `span` (1, 2, 2.5 or 5 times a power of 10).
pub fn nice_step(span: f64, n: usize) -> f64 {
    if !(span.is_finite() && span > 0.0) {
        return 1.0;
    }
    let raw = span / n.max(1) as f64;
    let p = 10f64.powf(raw.log10().floor());
    let m = raw / p;
    let k = if m <= 1.0 {
        1.0
    } else if m <= 2.0 {
        2.0
    } else if m <= 2.5 {
        2.5
    } else if m <= 5.0 {
        5.0
    } else {
        10.0
    };
    k * p
}

/// A tick or legend number: as many decimals as the step needs (`0.25` -> 2), at most 6.
pub fn tick_label(v: f64, step: f64) -> String {
    let decimals = (0..6)
        .find(|&d| {
            let x = step.abs() * 10f64.powi(d);
            (x - x.round()).abs() < 1e-6 * x.max(1.0)
        })
        .unwrap_or(6) as usize;
    let s = format!("{v:.decimals$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn font_parses_and_sets_text() {
        assert!(plotters::style::register_font("probe", FontStyle::Normal, FONT).is_ok());
        // A layout of real width: the font was found and has the glyphs.
        let (w, h) = font(20.0).font.box_size("klx·h ≥ 100 %").unwrap();
        assert!(w > 80 && h > 10, "{w} x {h}");
    }

    #[test]
    fn palettes() {
        assert_eq!(Palette::Viridis.colour(0.0), [0x44, 0x01, 0x54]);
        assert_eq!(Palette::Viridis.colour(1.0), [0xfd, 0xe7, 0x25]);
        assert_eq!(Palette::Viridis.colour(2.0), [0xfd, 0xe7, 0x25]);
        // falsecolor: dark purple at 0, yellow at the top, red-ish at 20/22.
        let lo = Palette::Falsecolor.colour(0.0);
        let hi = Palette::Falsecolor.colour(1.0);
        assert_eq!(
            lo,
            [(255.0 * 0.18848f64.powf(1.0 / 2.2)).round() as u8, 11, 140]
        );
        assert!(hi[0] > 250 && hi[1] > 250 && hi[2] < 60, "{hi:?}");
        // viridis' lightness grows monotonically (perceptual order).
        let luma = |c: [u8; 3]| 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64;
        let mut prev = -1.0;
        for k in 0..=100 {
            let l = luma(Palette::Viridis.colour(k as f64 / 100.0));
            assert!(l >= prev - 0.5, "{k}");
            prev = l;
        }
        assert!(Palette::parse("jet").is_err());
    }

    #[test]
    fn steps_and_labels() {
        assert_eq!(nice_step(100.0, 5), 20.0);
        assert_eq!(nice_step(20000.0, 5), 5000.0);
        assert_eq!(nice_step(1.0, 4), 0.25);
        assert_eq!(tick_label(20.0, 20.0), "20");
        assert_eq!(tick_label(0.5, 0.5), "0.5");
        assert_eq!(tick_label(0.25, 0.25), "0.25");
        assert_eq!(Format::of("a/b.PNG").unwrap(), Format::Png);
        assert_eq!(Format::of("b.svg").unwrap(), Format::Svg);
        assert!(Format::of("b.jpg").is_err());
    }
}
