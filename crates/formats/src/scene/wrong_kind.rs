//! Files given as scene text that are something else, named for what they are.
//!
//! Radiance's own programs take octrees where rdaylight takes `.rad` files, so `rdc room.oct`
//! is an easy mistake; the parser used to read the octree's header line `oconv room.rad` as
//! an object and answer "undefined modifier 'oconv'" (issue #21). Before parsing, the first
//! bytes of every scene input are checked for the kinds a user is likely to give by mistake,
//! each recognised by its content, never by its name:
//!
//! | kind | recognised by |
//! |---|---|
//! | octree (`oconv`) | a `#?` header with `FORMAT=Radiance_octree`, or an `oconv` command line and binary data after the header (`src/ot/writeoct.c`) |
//! | picture | a `#?` header with `FORMAT=32-bit_rle_rgbe`, `32-bit_rle_xyze` or `Radiance_spectra` |
//! | matrix | a `#?` header with `FORMAT=ascii`, `float` or `double` |
//! | PNG, JPEG, OpenEXR | their magic bytes |
//! | weather file | an EPW's `LOCATION,` record, or a `.wea`'s `place` and `latitude` lines |
//! | other binary data | a NUL byte in the first 4 KiB (scene text never holds one) |
//!
//! A `#?` line without one of these formats is a comment to the scene grammar and is left to
//! the parser, as Radiance's `readobj` would.

use crate::error::{Error, Result};

/// How much of an input is looked at: headers are short, and a scene's first lines decide.
const HEAD: usize = 4096;

/// An error naming what `bytes` (input `name`) is when it is clearly not scene text.
pub fn check(bytes: &[u8], name: &str) -> Result<()> {
    match what(&bytes[..bytes.len().min(HEAD)]) {
        None => Ok(()),
        Some(Kind::Octree) => Err(Error::Usage(format!(
            "{name} is a Radiance octree (oconv output); give the .rad scene files instead"
        ))),
        Some(Kind::Compiled) => Err(Error::Usage(format!(
            "{name} is a compiled scene (rdc --compile output): give it to rdc as its only \
             scene input, or give the .rad scene files instead"
        ))),
        Some(kind) => Err(Error::Usage(format!(
            "{name} is {}, not a scene description; give the .rad scene files instead",
            kind.describe()
        ))),
    }
}

/// True when `head` (a file's first bytes) is a Radiance octree.
pub fn is_octree(head: &[u8]) -> bool {
    what(&head[..head.len().min(HEAD)]) == Some(Kind::Octree)
}

#[derive(Debug, Clone, PartialEq, Eq)]
enum Kind {
    Octree,
    Compiled,
    Picture(String),
    Matrix(String),
    Photo(&'static str),
    Weather(&'static str),
    Binary,
}

impl Kind {
    fn describe(&self) -> String {
        match self {
            Kind::Octree => "a Radiance octree".into(),
            Kind::Compiled => "a compiled scene".into(),
            Kind::Picture(f) => format!("a Radiance picture (FORMAT={f})"),
            Kind::Matrix(f) => format!("a Radiance matrix (FORMAT={f})"),
            Kind::Photo(f) => format!("a {f} picture"),
            Kind::Weather(f) => format!("a weather file ({f})"),
            Kind::Binary => "binary data".into(),
        }
    }
}

fn what(head: &[u8]) -> Option<Kind> {
    if head.starts_with(b"#?") {
        return radiance(head);
    }
    for (magic, name) in [
        (&b"\x89PNG\r\n\x1a\n"[..], "PNG"),
        (&[0xff, 0xd8, 0xff][..], "JPEG"),
        (&[0x76, 0x2f, 0x31, 0x01][..], "OpenEXR"),
    ] {
        if head.starts_with(magic) {
            return Some(Kind::Photo(name));
        }
    }
    let text = String::from_utf8_lossy(head);
    if text.starts_with("LOCATION,") {
        return Some(Kind::Weather("EPW"));
    }
    let mut lines = text.lines().map(str::trim_start);
    if lines.next().is_some_and(|l| l.starts_with("place "))
        && lines.next().is_some_and(|l| l.starts_with("latitude "))
    {
        return Some(Kind::Weather(".wea"));
    }
    if head.contains(&0) {
        return Some(Kind::Binary);
    }
    None
}

/// A file with a Radiance header: what its `FORMAT=` (or its `oconv` line) says it is.
fn radiance(head: &[u8]) -> Option<Kind> {
    let mut format = None;
    let mut oconv = false;
    let mut rest = head;
    let mut closed = false;
    while let Some(end) = rest.iter().position(|&b| b == b'\n') {
        let line = String::from_utf8_lossy(&rest[..end]);
        let line = line.trim_end_matches('\r');
        rest = &rest[end + 1..];
        if line.is_empty() {
            closed = true;
            break;
        }
        if let Some(f) = line.strip_prefix("FORMAT=") {
            format = Some(f.trim().to_string());
        }
        oconv |= line.split_whitespace().next() == Some("oconv");
    }
    match format.as_deref() {
        Some("Radiance_octree") => Some(Kind::Octree),
        Some(super::compiled::FORMAT) => Some(Kind::Compiled),
        Some(f @ ("32-bit_rle_rgbe" | "32-bit_rle_xyze" | "Radiance_spectra")) => {
            Some(Kind::Picture(f.into()))
        }
        Some(f @ ("ascii" | "float" | "double")) => Some(Kind::Matrix(f.into())),
        _ if oconv && closed && rest.contains(&0) => Some(Kind::Octree),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn msg(bytes: &[u8]) -> String {
        check(bytes, "x").unwrap_err().to_string()
    }

    #[test]
    fn octrees_by_format_or_by_their_oconv_line() {
        let oct = b"#?RADIANCE\noconv room.rad sky.rad\nFORMAT=Radiance_octree\n\n\x01\x1f-20.0\0";
        assert_eq!(
            msg(oct),
            "x is a Radiance octree (oconv output); give the .rad scene files instead"
        );
        // Octrees from before FORMAT= lines: the oconv command and binary data.
        assert!(msg(b"#?RADIANCE\noconv a.rad\n\n\x01\x1f\0\0").contains("octree"));
    }

    #[test]
    fn pictures_matrices_photos_weather_and_binary() {
        let pic = b"#?RADIANCE\nrpict -vta\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n";
        assert!(msg(pic).contains("a Radiance picture (FORMAT=32-bit_rle_rgbe)"));
        let mtx = b"#?RADIANCE\nNROWS=1\nNCOLS=1\nNCOMP=3\nFORMAT=ascii\n\n1 2 3\n";
        assert!(msg(mtx).contains("a Radiance matrix (FORMAT=ascii)"));
        assert!(msg(b"\x89PNG\r\n\x1a\n\0\0").contains("a PNG picture"));
        assert!(msg(b"LOCATION,LONDON,-,GBR\n").contains("a weather file (EPW)"));
        let wea = b"place London\nlatitude 51.1\nlongitude 0.1\n";
        assert!(msg(wea).contains("a weather file (.wea)"));
        assert!(msg(b"void plastic m\0").contains("binary data"));
    }

    #[test]
    fn scene_text_passes() {
        for ok in [
            &b""[..],
            b"# a comment\nvoid plastic m 0 0 5 .5 .5 .5 0 0\n",
            // A comment that happens to look like a header line, with no FORMAT=.
            b"#?RADIANCE\nvoid plastic m 0 0 5 .5 .5 .5 0 0\n",
            // A modifier called `place` is still a scene.
            b"place polygon p 0 0 9 0 0 0 1 0 0 0 1 0\n",
            b"!oconv -h\n",
        ] {
            assert!(check(ok, "x").is_ok(), "{}", String::from_utf8_lossy(ok));
        }
    }
}
