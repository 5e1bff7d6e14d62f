//! Material masks for the image methods: a PNG with one flat colour per material, and a legend
//! naming the colours.
//!
//! Mask: any PNG (or other lossless picture the `image` crate reads); each pixel's 8-bit RGB
//! colour is looked up in the legend; colours not in the legend (and, without a legend,
//! black) belong to no material. A lossy (JPEG) mask would blur colours at edges, so its
//! edge pixels simply fall out of every region.
//!
//! Legend (CSV, `#` starts a comment line, blank lines ignored):
//!
//! ```text
//! # colour, name[, known reflectance: 1 or 3 values][, white reference of this material]
//! c08040, back_wall
//! ffffff, card_back, 0.9
//! 4060ff, poster, , card_back
//! ```
//!
//! - `colour`: six hexadecimal digits `rrggbb` (no `#`, which starts comments).
//! - `name`: one word, the material name written to the `.rad` file.
//! - `known reflectance`: marks a reference patch (the photo method's white or grey card);
//!   one value (grey) or three (Radiance RGB).
//! - `reference`: for the photo method, the name of the reference patch whose white this
//!   material is adapted to (Ferwerda's protocol: photograph each sample beside a card under
//!   the same light); empty = the first reference patch of the legend.
//!
//! Without a legend, every distinct non-black colour of the mask is a material named
//! `m_rrggbb`.
//!
//! Erosion (`erode`): a pixel keeps its label only if every pixel within `n` pixels
//! (Chebyshev distance) has the same label, which drops the boundary pixels where a photo
//! or a rendering mixes two materials.

use nom::{
    Parser,
    bytes::complete::{take_while_m_n, take_while1},
    character::complete::space0,
    combinator::all_consuming,
    multi::separated_list0,
    number::complete::double,
};
use std::path::Path;

use crate::error::{Error, Location, Result};

/// Most materials a mask may hold (more means the mask is not flat colours, e.g. a JPEG).
pub const MAX_MATERIALS: usize = 1024;

/// One legend entry.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    pub colour: [u8; 3],
    pub name: String,
    /// Known reflectance (Radiance RGB; a grey value is repeated) of a reference patch.
    pub known: Option<[f64; 3]>,
    /// Name of the white reference this material is adapted to (photo method).
    pub reference: Option<String>,
}

/// The legend of a mask.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Legend {
    pub entries: Vec<Entry>,
}

fn is_name(c: char) -> bool {
    !c.is_whitespace() && c != ','
}

fn hex_colour(s: &str) -> Option<[u8; 3]> {
    let r: nom::IResult<&str, &str> =
        all_consuming(take_while_m_n(6, 6, |c: char| c.is_ascii_hexdigit())).parse(s);
    let (_, h) = r.ok()?;
    let v = u32::from_str_radix(h, 16).ok()?;
    Some([(v >> 16) as u8, (v >> 8) as u8, v as u8])
}

fn numbers(s: &str) -> Option<Vec<f64>> {
    let r: nom::IResult<&str, Vec<f64>> = all_consuming((
        space0,
        separated_list0(take_while1(|c: char| c == ' ' || c == '\t'), double),
        space0,
    ))
    .map(|(_, v, _)| v)
    .parse(s);
    r.ok().map(|(_, v)| v)
}

/// Parse `1` or `3` reflectance values in 0..1 (one value is repeated for grey).
pub fn reflectance_values(s: &str) -> std::result::Result<[f64; 3], String> {
    let v = numbers(s).ok_or_else(|| format!("expected 1 or 3 numbers, found '{s}'"))?;
    let rho = match v.as_slice() {
        [g] => [*g; 3],
        [r, g, b] => [*r, *g, *b],
        _ => {
            return Err(format!(
                "expected 1 or 3 reflectance values, found {}",
                v.len()
            ));
        }
    };
    if rho.iter().any(|r| !(*r > 0.0 && *r <= 1.0)) {
        return Err(format!(
            "reflectance must be in (0, 1], found '{}'",
            s.trim()
        ));
    }
    Ok(rho)
}

impl Legend {
    /// Parse a legend; `file` names it in errors (`file:line: ...`).
    pub fn parse(text: &str, file: &str) -> Result<Legend> {
        let mut entries: Vec<Entry> = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let loc = || Location::line(file, i + 1);
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() < 2 || fields.len() > 4 {
                return Err(Error::parse(
                    loc(),
                    format!("expected 'rrggbb, name[, reflectance][, reference]', found '{line}'"),
                ));
            }
            let colour = hex_colour(fields[0]).ok_or_else(|| {
                Error::parse(
                    loc(),
                    format!(
                        "expected a colour of six hex digits (rrggbb), found '{}'",
                        fields[0]
                    ),
                )
            })?;
            let name = fields[1];
            if name.is_empty() || !name.chars().all(is_name) {
                return Err(Error::parse(
                    loc(),
                    format!("expected a material name (one word), found '{name}'"),
                ));
            }
            let known = match fields.get(2) {
                Some(s) if !s.is_empty() => {
                    Some(reflectance_values(s).map_err(|m| Error::parse(loc(), m))?)
                }
                _ => None,
            };
            let reference = match fields.get(3) {
                Some(s) if !s.is_empty() => {
                    if !s.chars().all(is_name) {
                        return Err(Error::parse(
                            loc(),
                            format!("expected a reference name (one word), found '{s}'"),
                        ));
                    }
                    Some(s.to_string())
                }
                _ => None,
            };
            if entries.iter().any(|e| e.colour == colour) {
                return Err(Error::parse(
                    loc(),
                    format!("colour {} is listed twice", fields[0]),
                ));
            }
            if entries.iter().any(|e| e.name == name) {
                return Err(Error::parse(
                    loc(),
                    format!("material name '{name}' is listed twice"),
                ));
            }
            if entries.len() == MAX_MATERIALS {
                return Err(Error::parse(
                    loc(),
                    format!("more than {MAX_MATERIALS} materials"),
                ));
            }
            entries.push(Entry {
                colour,
                name: name.to_string(),
                known,
                reference,
            });
        }
        for e in &entries {
            if let Some(r) = &e.reference {
                if !entries.iter().any(|x| &x.name == r && x.known.is_some()) {
                    return Err(Error::parse(
                        Location::file(file),
                        format!(
                            "material '{}' refers to '{r}', which is not a reference patch \
                             (an entry with a known reflectance)",
                            e.name
                        ),
                    ));
                }
            }
        }
        Ok(Legend { entries })
    }

    /// Read a legend file.
    pub fn open(path: &Path) -> Result<Legend> {
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(&shown, e))?;
        Legend::parse(&text, &shown)
    }

    /// Index of the entry named `name`.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.entries.iter().position(|e| e.name == name)
    }
}

/// Per-pixel material labels (index into the legend), row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct LabelMap {
    pub width: usize,
    pub height: usize,
    pub labels: Vec<Option<u16>>,
    pub legend: Legend,
}

impl LabelMap {
    /// Label an 8-bit RGB picture with a legend, or, without one, with every distinct
    /// non-black colour.
    pub fn from_image(img: &image::RgbImage, legend: Option<Legend>, name: &str) -> Result<Self> {
        let mut legend = legend.unwrap_or_default();
        let auto = legend.entries.is_empty();
        let mut labels = Vec::with_capacity(img.as_raw().len() / 3);
        for px in img.pixels() {
            let c = px.0;
            let mut found = legend.entries.iter().position(|e| e.colour == c);
            if found.is_none() && auto && c != [0, 0, 0] {
                if legend.entries.len() == MAX_MATERIALS {
                    return Err(Error::parse(
                        Location::file(name),
                        format!(
                            "more than {MAX_MATERIALS} colours: a mask has one flat colour per \
                             material (give a legend to pick the colours that matter)"
                        ),
                    ));
                }
                legend.entries.push(Entry {
                    colour: c,
                    name: format!("m_{:02x}{:02x}{:02x}", c[0], c[1], c[2]),
                    known: None,
                    reference: None,
                });
                found = Some(legend.entries.len() - 1);
            }
            labels.push(found.map(|i| i as u16));
        }
        Ok(LabelMap {
            width: img.width() as usize,
            height: img.height() as usize,
            labels,
            legend,
        })
    }

    /// Read a mask picture.
    pub fn open(path: &Path, legend: Option<Legend>) -> Result<Self> {
        let shown = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| Error::io(&shown, e))?;
        Self::from_bytes(&bytes, legend, &shown)
    }

    /// Decode a mask picture from memory (`name` for messages; the format is recognised by
    /// its content), its size checked from the header before any pixel is decoded.
    pub fn from_bytes(bytes: &[u8], legend: Option<Legend>, name: &str) -> Result<Self> {
        let dims = image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| Error::io(name, e))?
            .into_dimensions();
        rdaylight_formats::picture::preview::check_photo_size(dims, name)?;
        let img = image::load_from_memory(bytes).map_err(|e| {
            Error::parse(Location::file(name), format!("not a PNG mask picture: {e}"))
        })?;
        Self::from_image(&img.to_rgb8(), legend, name)
    }

    /// Label of pixel (`x` from the left, `y` from the top); `None` outside.
    pub fn get(&self, x: usize, y: usize) -> Option<usize> {
        if x >= self.width || y >= self.height {
            return None;
        }
        self.labels[y * self.width + x].map(usize::from)
    }

    /// Drop the pixels within `n` pixels of a different label or of an unlabelled pixel
    /// (the picture's border does not count).
    pub fn erode(&self, n: usize) -> LabelMap {
        if n == 0 {
            return self.clone();
        }
        let (w, h) = (self.width, self.height);
        let mut labels = self.labels.clone();
        for y in 0..h {
            for x in 0..w {
                let l = self.labels[y * w + x];
                if l.is_none() {
                    continue;
                }
                let (x0, x1) = (x.saturating_sub(n), (x + n).min(w - 1));
                let (y0, y1) = (y.saturating_sub(n), (y + n).min(h - 1));
                let same = (y0..=y1).all(|yy| (x0..=x1).all(|xx| self.labels[yy * w + xx] == l));
                if !same {
                    labels[y * w + x] = None;
                }
            }
        }
        LabelMap {
            labels,
            ..self.clone()
        }
    }

    /// Pixel indices (`y * width + x`) of each label.
    pub fn regions(&self) -> Vec<Vec<usize>> {
        let mut r = vec![Vec::new(); self.legend.entries.len()];
        for (i, l) in self.labels.iter().enumerate() {
            if let Some(l) = l {
                r[*l as usize].push(i);
            }
        }
        r
    }

    /// Check that the mask has the size of the picture it labels.
    pub fn check_size(&self, width: usize, height: usize, what: &str) -> Result<()> {
        if (self.width, self.height) != (width, height) {
            return Err(Error::Mismatch(format!(
                "the mask is {} x {} pixels but {what} is {width} x {height}",
                self.width, self.height
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LEGEND: &str = "# test\nc04080, wall\nffffff, card, 0.9\n\n4060ff, poster, , card\n\
                          00ff00, rug, 0.2 0.3 0.4\n";

    #[test]
    fn legend_parses() {
        let l = Legend::parse(LEGEND, "l.csv").unwrap();
        assert_eq!(l.entries.len(), 4);
        assert_eq!(l.entries[0].colour, [0xc0, 0x40, 0x80]);
        assert_eq!(l.entries[1].known, Some([0.9; 3]));
        assert_eq!(l.entries[2].reference.as_deref(), Some("card"));
        assert_eq!(l.entries[2].known, None);
        assert_eq!(l.entries[3].known, Some([0.2, 0.3, 0.4]));
        assert_eq!(l.find("rug"), Some(3));
    }

    #[test]
    fn legend_errors() {
        let e = |t: &str| Legend::parse(t, "l.csv").unwrap_err().to_string();
        assert!(
            e("c08040\n").starts_with("l.csv:1: expected 'rrggbb, name"),
            "{}",
            e("c08040\n")
        );
        assert!(e("# x\nc0804, wall\n").starts_with("l.csv:2: expected a colour of six hex"));
        assert!(e("c08040, two words\n").starts_with("l.csv:1: expected a material name"));
        assert!(e("c08040, a, 0.5 0.5\n").starts_with("l.csv:1: expected 1 or 3 reflectance"));
        assert!(e("c08040, a, 1.5\n").starts_with("l.csv:1: reflectance must be in (0, 1]"));
        assert!(e("c08040, a, x\n").starts_with("l.csv:1: expected 1 or 3 numbers"));
        assert!(e("c08040, a\nc08040, b\n").starts_with("l.csv:2: colour c08040 is listed twice"));
        assert!(e("c08040, a\nc08041, a\n").starts_with("l.csv:2: material name 'a'"));
        assert!(
            e("c08040, a, , b\n").starts_with("l.csv: material 'a' refers to 'b', which is not")
        );
        for cut in 0..LEGEND.len() {
            let _ = Legend::parse(&LEGEND[..cut], "cut");
        }
    }

    fn picture() -> image::RgbImage {
        // 6 x 4: left half colour A, right half colour B, one black pixel.
        let mut img = image::RgbImage::new(6, 4);
        for (x, y, p) in img.enumerate_pixels_mut() {
            p.0 = if x < 3 {
                [0xc0, 0x40, 0x80]
            } else {
                [0, 255, 0]
            };
            if (x, y) == (5, 3) {
                p.0 = [0, 0, 0];
            }
        }
        img
    }

    #[test]
    fn labels_and_erosion() {
        let legend = Legend::parse(LEGEND, "l.csv").unwrap();
        let m = LabelMap::from_image(&picture(), Some(legend), "m.png").unwrap();
        assert_eq!(m.get(0, 0), Some(0));
        assert_eq!(m.get(4, 0), Some(3));
        assert_eq!(m.get(5, 3), None);
        assert_eq!(m.get(6, 0), None);
        let r = m.regions();
        assert_eq!((r[0].len(), r[3].len(), r[1].len()), (12, 11, 0));
        let e = m.erode(1);
        // Columns 2 and 3 touch the other colour; (4, 2), (5, 2), (4, 3) touch the black
        // pixel.
        let r = e.regions();
        assert_eq!(r[0].len(), 8, "{:?}", e.labels);
        assert_eq!(r[3].len(), 4, "{:?}", e.labels);
        let auto = LabelMap::from_image(&picture(), None, "m.png").unwrap();
        assert_eq!(auto.legend.entries.len(), 2);
        assert_eq!(auto.legend.entries[1].name, "m_00ff00");
        assert_eq!(auto.get(5, 3), None);
        assert!(auto.check_size(6, 4, "x").is_ok());
        assert!(auto.check_size(6, 5, "x").is_err());
    }

    #[test]
    fn masks_decode_from_memory_as_from_disk() {
        let mut png = Vec::new();
        picture()
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        let m = LabelMap::from_bytes(&png, None, "m.png").unwrap();
        assert_eq!(m, LabelMap::from_image(&picture(), None, "m.png").unwrap());
        let d = tempfile::tempdir().unwrap();
        let path = d.path().join("m.png");
        std::fs::write(&path, &png).unwrap();
        assert_eq!(LabelMap::open(&path, None).unwrap().labels, m.labels);
        let e = LabelMap::from_bytes(&png[..png.len() / 2], None, "cut.png")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("cut.png: not a PNG mask picture"), "{e}");
    }
}
