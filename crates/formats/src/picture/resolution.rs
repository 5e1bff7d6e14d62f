//! The picture resolution string: which way the scanlines run.
//!
//! Source: Radiance `src/common/resolu.[ch]` (`str2resolu`, `resolu2str`) and
//! `doc/filefmts.md` (Picture File Format, "Resolution String").
//!
//! ```text
//! -Y N +X M\n     standard: N scanlines of M pixels, top scanline first, left to right
//! ```
//! The first axis is the scanline axis (`YMAJOR` when it is Y), a `-` before an axis means
//! that coordinate decreases along the file (`XDECR`, `YDECR`). Picture coordinates have
//! their origin at the bottom left, x to the right and y up. The eight orientations:
//!
//! | string | meaning (doc/filefmts.md) |
//! |---|---|
//! | `-Y N +X M` | standard |
//! | `-Y N -X M` | flipped left-right |
//! | `+Y N -X M` | rotated 180 degrees |
//! | `+Y N +X M` | flipped top-bottom |
//! | `+X M +Y N` | rotated 90 degrees clockwise |
//! | `-X M +Y N` | rotated 90 degrees clockwise, then flipped top-bottom |
//! | `-X M -Y N` | rotated 90 degrees counter-clockwise |
//! | `+X M -Y N` | rotated 90 degrees counter-clockwise, then flipped top-bottom |
//!
//! Radiance's own reader is looser (it finds the last `X` and `Y` on the line and `atoi`s
//! what follows); ours insists on the written shape `[+-][XY] int [+-][YX] int` with any
//! blanks between, which every Radiance writer produces (`"%cY %8d %cX %8d\n"`).

use crate::error::{Error, Location, Result};
use nom::{
    IResult, Parser,
    branch::alt,
    bytes::complete::tag,
    character::complete::{digit1, one_of, space0, space1},
    combinator::{eof, map_res, opt},
};
use std::io::BufRead;

/// X decreases along the file (`XDECR`).
pub const XDECR: u8 = 1;
/// Y decreases along the file (`YDECR`).
pub const YDECR: u8 = 2;
/// Scanlines run along X, i.e. each scanline is a row (`YMAJOR`).
pub const YMAJOR: u8 = 4;
/// Standard order: rows from the top down, left to right (`PIXSTANDARD`).
pub const STANDARD: u8 = YMAJOR | YDECR;

/// Largest resolution we accept on either axis. Radiance has no limit beyond `int`; this
/// bound keeps a corrupt header from asking for gigabytes for a single scanline.
pub const MAX_RES: usize = 1 << 20;

/// Picture dimensions and scanline order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Resolution {
    /// Orientation flags (`XDECR | YDECR | YMAJOR`).
    pub order: u8,
    /// Width: number of pixels along X.
    pub xres: usize,
    /// Height: number of pixels along Y.
    pub yres: usize,
}

impl Resolution {
    /// A standard-order resolution (`-Y height +X width`).
    pub fn standard(width: usize, height: usize) -> Self {
        Resolution {
            order: STANDARD,
            xres: width,
            yres: height,
        }
    }

    /// Pixels per scanline in the file (`scanlen`).
    pub fn scan_len(&self) -> usize {
        if self.order & YMAJOR != 0 {
            self.xres
        } else {
            self.yres
        }
    }

    /// Number of scanlines in the file (`numscans`).
    pub fn num_scans(&self) -> usize {
        if self.order & YMAJOR != 0 {
            self.yres
        } else {
            self.xres
        }
    }

    /// Where pixel `pos` of file scanline `scan` goes in standard orientation, as
    /// `(row, col)` with row 0 the top row.
    pub fn to_standard(&self, scan: usize, pos: usize) -> (usize, usize) {
        let (a, b) = (scan, pos);
        let (x, y) = if self.order & YMAJOR != 0 {
            (b, a)
        } else {
            (a, b)
        };
        // Coordinates counted along the file; undo the decreasing axes to get picture
        // coordinates with the origin at the bottom left.
        let x = if self.order & XDECR != 0 {
            self.xres - 1 - x
        } else {
            x
        };
        let y = if self.order & YDECR != 0 {
            self.yres - 1 - y
        } else {
            y
        };
        (self.yres - 1 - y, x)
    }

    /// The line Radiance writes (`resolu2str`), newline included.
    pub fn to_line(&self) -> String {
        let sign = |flag: u8| if self.order & flag != 0 { '-' } else { '+' };
        if self.order & YMAJOR != 0 {
            format!(
                "{}Y {:8} {}X {:8}\n",
                sign(YDECR),
                self.yres,
                sign(XDECR),
                self.xres
            )
        } else {
            format!(
                "{}X {:8} {}Y {:8}\n",
                sign(XDECR),
                self.xres,
                sign(YDECR),
                self.yres
            )
        }
    }

    /// Parse a resolution line (without or with its newline).
    pub fn parse(line: &str) -> std::result::Result<Resolution, String> {
        match resolution_line(line) {
            Ok((_, r)) => {
                if r.xres == 0 || r.yres == 0 {
                    Err(format!(
                        "resolution '{}' has a zero size; expected positive sizes",
                        line.trim_end()
                    ))
                } else if r.xres > MAX_RES || r.yres > MAX_RES {
                    Err(format!(
                        "resolution '{}' is larger than {MAX_RES} pixels on a side",
                        line.trim_end()
                    ))
                } else {
                    Ok(r)
                }
            }
            Err(_) => Err(format!(
                "bad resolution string '{}'; expected e.g. '-Y 512 +X 768'",
                line.trim_end().escape_default()
            )),
        }
    }

    /// Read the resolution line that follows the header. `line_no` is its file line.
    pub fn read<R: BufRead + ?Sized>(r: &mut R, name: &str, line_no: usize) -> Result<Self> {
        // Radiance reads at most 31 bytes (`RESOLU_BUFLEN` 32 with fgets); allow a little
        // more slack for generous spacing but never an unbounded line.
        const MAX_LINE: u64 = 64;
        let mut raw = Vec::new();
        let mut limited = std::io::Read::take(&mut *r, MAX_LINE);
        limited
            .read_until(b'\n', &mut raw)
            .map_err(|e| Error::io(name, e))?;
        let loc = Location::line(name, line_no);
        if raw.is_empty() {
            return Err(Error::parse(
                loc,
                "file ends after the header; expected a resolution string such as '-Y 512 +X 768'",
            ));
        }
        if raw.last() != Some(&b'\n') {
            return Err(Error::parse(
                loc,
                "resolution string not ended by a newline within 64 bytes; expected e.g. \
                 '-Y 512 +X 768'",
            ));
        }
        let text = String::from_utf8_lossy(&raw);
        Resolution::parse(&text).map_err(|m| Error::parse(loc, m))
    }
}

/// `[+-]` then an axis letter.
fn signed_axis(input: &str) -> IResult<&str, (char, char)> {
    (one_of("+-"), one_of("XY")).parse(input)
}

fn number(input: &str) -> IResult<&str, usize> {
    map_res(digit1, str::parse::<usize>).parse(input)
}

/// `[+-]A n [+-]B m` with A != B, optional trailing blanks and newline.
fn resolution_line(input: &str) -> IResult<&str, Resolution> {
    let (rest, ((s1, a1), _, n1, _, (s2, a2), _, n2, _, _, _)) = (
        signed_axis,
        space1,
        number,
        space1,
        signed_axis,
        space1,
        number,
        space0,
        opt(alt((tag("\r\n"), tag("\n")))),
        eof,
    )
        .parse(input)?;
    if a1 == a2 {
        return Err(nom::Err::Error(nom::error::Error::new(
            input,
            nom::error::ErrorKind::Verify,
        )));
    }
    let mut order = 0;
    let (xs, ys, xres, yres) = if a1 == 'Y' {
        order |= YMAJOR;
        (s2, s1, n2, n1)
    } else {
        (s1, s2, n1, n2)
    };
    if xs == '-' {
        order |= XDECR;
    }
    if ys == '-' {
        order |= YDECR;
    }
    Ok((rest, Resolution { order, xres, yres }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_eight_orientations_parse_and_print_back() {
        for order in 0..8u8 {
            let r = Resolution {
                order,
                xres: 7,
                yres: 5,
            };
            let line = r.to_line();
            assert_eq!(Resolution::parse(&line).unwrap(), r, "{line}");
        }
        assert_eq!(
            Resolution::standard(32, 16).to_line(),
            "-Y       16 +X       32\n"
        );
        let r = Resolution::parse("+X 3 -Y 2\n").unwrap();
        assert_eq!(r.order, YDECR);
        assert_eq!((r.xres, r.yres, r.scan_len(), r.num_scans()), (3, 2, 2, 3));
    }

    #[test]
    fn standard_mapping_is_identity() {
        let r = Resolution::standard(4, 3);
        for s in 0..3 {
            for p in 0..4 {
                assert_eq!(r.to_standard(s, p), (s, p));
            }
        }
        // +Y: first scanline is the bottom row.
        let r = Resolution::parse("+Y 3 +X 4").unwrap();
        assert_eq!(r.to_standard(0, 0), (2, 0));
        // -Y -X: flipped left-right.
        let r = Resolution::parse("-Y 3 -X 4").unwrap();
        assert_eq!(r.to_standard(0, 0), (0, 3));
        // +X +Y: scanline 0 is the left column, read bottom to top.
        let r = Resolution::parse("+X 4 +Y 3").unwrap();
        assert_eq!(r.to_standard(0, 0), (2, 0));
        assert_eq!(r.to_standard(3, 2), (0, 3));
    }

    #[test]
    fn bad_strings() {
        for bad in [
            "",
            "-Y 10",
            "-Y 10 +Y 10",
            "Y 10 X 10",
            "-Y 0 +X 10",
            "-Y 10 +X 10 junk",
            "-Y 99999999999999999999999 +X 1",
            "-Y 2000000 +X 1",
        ] {
            assert!(Resolution::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn read_reports_line() {
        let mut c = std::io::Cursor::new(&b"-Y 2 X 3\n"[..]);
        let e = Resolution::read(&mut c, "a.hdr", 7)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("a.hdr:7: bad resolution string"), "{e}");
        let mut c = std::io::Cursor::new(&b""[..]);
        assert!(Resolution::read(&mut c, "a.hdr", 7).is_err());
    }
}
