//! Writing uplifted spectra, and reading `name R G B` colour lists.
//!
//! - Radiance 6 scene text (`doc/ray.1`; `src/rt/p_data.c:p_spectrum`, which multiplies the
//!   material colour by the spectrum converted to the working colour space, with no
//!   normalisation): a `spectrum` pattern `void spectrum NAME_spec 0 0 83 380 780 s1..s81`
//!   and `NAME_spec plastic NAME 0 0 5 1 1 1 SPEC ROUGH`, so the plastic's diffuse reflectance
//!   is exactly the spectrum (its RGB is left at 1 1 1).
//! - `specfile` data (the format of [`crate::scene::specdata`]): `1`, `380 780 81`, values.
//! - CSV: `nm,NAME1,NAME2,...`, one row per wavelength.
//! - Materials estimated from pictures ([`MaterialRow`]): RGB `plastic`s (or spectra through
//!   an uplifter) and a CSV table.
//!
//! Batch input: one colour per line, `name R G B` (whitespace-separated), `#` comments and
//! blank lines ignored; errors name file and line.

use std::io::Write;

use nom::{
    Parser,
    bytes::complete::take_while1,
    character::complete::{space0, space1},
    number::complete::double,
};

use crate::colour::cie::{N, Spectrum, WL_MAX, WL_MIN, wavelengths};
use crate::error::{Error, Location, Result};

/// Values per line in the scene and data outputs.
const PER_LINE: usize = 9;

fn fmt(v: f64) -> String {
    // 6 significant digits: far below measurement noise of reflectance (~1e-3).
    format!("{:.6}", v)
        .trim_end_matches('0')
        .trim_end_matches('.')
        .to_string()
}

fn values(w: &mut dyn Write, s: &Spectrum, indent: &str) -> std::io::Result<()> {
    for chunk in s.chunks(PER_LINE) {
        let line: Vec<String> = chunk.iter().map(|v| fmt(*v)).collect();
        writeln!(w, "{indent}{}", line.join(" "))?;
    }
    Ok(())
}

/// Write a `spectrum` pattern and a `plastic` using it.
pub fn write_rad(
    w: &mut dyn Write,
    name: &str,
    s: &Spectrum,
    specularity: f64,
    roughness: f64,
) -> std::io::Result<()> {
    writeln!(
        w,
        "void spectrum {name}_spec\n0\n0\n{} {WL_MIN} {WL_MAX}",
        N + 2
    )?;
    values(w, s, "\t")?;
    writeln!(
        w,
        "\n{name}_spec plastic {name}\n0\n0\n5 1 1 1 {} {}\n",
        fmt(specularity),
        fmt(roughness)
    )?;
    Ok(())
}

/// Write a Radiance data file for `specfile`.
pub fn write_specfile(w: &mut dyn Write, comment: &str, s: &Spectrum) -> std::io::Result<()> {
    for line in comment.lines() {
        writeln!(w, "# {line}")?;
    }
    writeln!(w, "1\n{WL_MIN} {WL_MAX} {N}")?;
    values(w, s, "")?;
    Ok(())
}

/// Write spectra as CSV columns.
pub fn write_csv(w: &mut dyn Write, spectra: &[(String, Spectrum)]) -> std::io::Result<()> {
    let names: Vec<&str> = spectra.iter().map(|(n, _)| n.as_str()).collect();
    writeln!(w, "nm,{}", names.join(","))?;
    for (i, l) in wavelengths().iter().enumerate() {
        let row: Vec<String> = spectra.iter().map(|(_, s)| fmt(s[i])).collect();
        writeln!(w, "{l},{}", row.join(","))?;
    }
    Ok(())
}

/// One material estimated from pictures (photo or illuminance-proxy methods).
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialRow {
    pub name: String,
    /// Radiance RGB reflectance (grey methods repeat one value).
    pub rgb: [f64; 3],
    /// Pixels averaged.
    pub pixels: usize,
    /// What the estimate rests on (white reference, kriging zone, ...).
    pub note: String,
}

/// Photopic (luminous) reflectance of a Radiance RGB reflectance (Radiance's
/// `luminance()` weights, [`crate::radiometry::RGB_PHOTOPIC`]).
pub fn photopic(rgb: [f64; 3]) -> f64 {
    (0..3)
        .map(|c| crate::radiometry::RGB_PHOTOPIC[c] * rgb[c])
        .sum()
}

/// Write `plastic` materials with the estimated RGB, or, with an uplifter, each as a
/// `spectrum` + `plastic` pair (see [`write_rad`]). Reflectances are clamped to 0..1 (a
/// plastic above 1 creates energy); the clamping is noted in a comment.
pub fn write_materials(
    w: &mut dyn Write,
    rows: &[MaterialRow],
    uplifter: Option<&super::Uplifter>,
    specularity: f64,
    roughness: f64,
) -> std::io::Result<()> {
    for r in rows {
        let rgb = r.rgb.map(|v| v.clamp(0.0, 1.0));
        write!(
            w,
            "# {}: rgb {} {} {}, {} pixels, {}",
            r.name,
            fmt(r.rgb[0]),
            fmt(r.rgb[1]),
            fmt(r.rgb[2]),
            r.pixels,
            r.note
        )?;
        if rgb != r.rgb {
            write!(w, " (clamped to 0..1)")?;
        }
        writeln!(w)?;
        match uplifter {
            Some(u) => {
                let up = u.uplift_rgb(rgb);
                write_rad(w, &r.name, &up.spectrum, specularity, roughness)?;
            }
            None => writeln!(
                w,
                "void plastic {}\n0\n0\n5 {} {} {} {} {}\n",
                r.name,
                fmt(rgb[0]),
                fmt(rgb[1]),
                fmt(rgb[2]),
                fmt(specularity),
                fmt(roughness)
            )?,
        }
    }
    Ok(())
}

/// Write the materials as CSV: `name,pixels,r,g,b,photopic,note`.
pub fn write_material_table(w: &mut dyn Write, rows: &[MaterialRow]) -> std::io::Result<()> {
    writeln!(w, "name,pixels,r,g,b,photopic,note")?;
    for r in rows {
        writeln!(
            w,
            "{},{},{:.4},{:.4},{:.4},{:.4},{}",
            r.name,
            r.pixels,
            r.rgb[0],
            r.rgb[1],
            r.rgb[2],
            photopic(r.rgb),
            r.note.replace(',', ";")
        )?;
    }
    Ok(())
}

/// Parse a batch of `name R G B` lines.
pub fn parse_batch(text: &str, file: &str) -> Result<Vec<(String, [f64; 3])>> {
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let parsed = (
            take_while1::<_, &str, nom::error::Error<&str>>(|c: char| !c.is_whitespace()),
            space1,
            double,
            space1,
            double,
            space1,
            double,
            space0,
        )
            .parse(line);
        match parsed {
            Ok(("", (name, _, r, _, g, _, b, _))) if [r, g, b].iter().all(|v| v.is_finite()) => {
                out.push((name.to_string(), [r, g, b]))
            }
            _ => {
                return Err(Error::parse(
                    Location::line(file, i + 1),
                    format!("expected 'name R G B' (a word and three numbers), found '{line}'"),
                ));
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batch_lines() {
        let b = parse_batch(
            "# colours\nwall 0.5 0.4 0.3\n\nfloor .2 .2 .1 # oak\n",
            "c.txt",
        )
        .unwrap();
        assert_eq!(b.len(), 2);
        assert_eq!(b[1], ("floor".to_string(), [0.2, 0.2, 0.1]));
        let e = parse_batch("wall 0.5 0.4\n", "c.txt")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.txt:1: expected 'name R G B'"), "{e}");
        let e = parse_batch("a 1 2 3\nb 1 x 3\n", "c.txt")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.txt:2: "), "{e}");
        let text = "wall 0.5 0.4 0.3\nfloor .2 .2 .1\n";
        for cut in 0..text.len() {
            let _ = parse_batch(&text[..cut], "cut");
        }
    }

    #[test]
    fn specfile_output_parses() {
        let s: Spectrum = std::array::from_fn(|i| i as f64 / 100.0);
        let mut buf = Vec::new();
        write_specfile(&mut buf, "test\nsecond line", &s).unwrap();
        let text = String::from_utf8(buf).unwrap();
        let d = crate::scene::specdata::SpecData::parse(&text, "t.dat").unwrap();
        assert_eq!(d.wavelengths.len(), N);
        assert_eq!(d.wavelengths[1], 385.0);
        assert!((d.values[80] - 0.8).abs() < 1e-12);
    }
}
