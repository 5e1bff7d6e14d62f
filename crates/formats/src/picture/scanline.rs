//! Scanline codecs for 4-byte pixels (RGBE, XYZE, and the rows of `32-bit_rle_rgbe`
//! matrices): flat, old run-length and new run-length encodings.
//!
//! Source: Radiance `src/common/color.c` (`fwritecolrs`, `freadcolrs`, `oldreadcolrs`) and
//! `doc/filefmts.md` (Picture File Format).
//!
//! ```text
//! flat     len x (r g b e)                          written for len < 17 or len > 32767
//! new RLE  2 2 len>>8 len&255                       len>>8 < 128, so never a valid pixel
//!          then the r plane, g plane, b plane, e plane, each exactly len bytes, coded as
//!          chunks:  c > 128: one byte repeated c-128 times   c <= 128: c literal bytes
//! old RLE  pixels, where (1,1,1,n) repeats the previous pixel n << 8k times, k counting
//!          the consecutive repeat pixels before it (a little-endian count)
//! ```
//! A reader tells new from old by the first 4 bytes; anything else is read as old/flat
//! (flat is old RLE without repeat pixels).
//!
//! The writer makes exactly the choices `fwritecolrs` makes, so re-encoding a picture that
//! Radiance wrote reproduces its bytes: runs of at least 4 (`MINRUN`) up to 127, literal
//! chunks of at most 128, and a run of 2 or 3 equal bytes written as a run when it is all
//! that stands between the previous chunk and the next long run (or the end of the plane).
//!
//! Reading reports every malformed case as a [`ScanlineError`]: a new-RLE length that does not
//! match the picture, a chunk that overruns the scanline, or a stream that ends early. One
//! case follows Radiance rather than rejecting: an old-RLE repeat count that runs past the
//! end of the scanline is cut at the end (`oldreadcolrs`: "silently ignored").

use std::fmt;
use std::io::{self, BufRead, Write};

/// Shortest scanline Radiance run-length encodes (`MINELEN`).
pub const MIN_RLE_LEN: usize = 17;
/// Longest scanline Radiance run-length encodes (`MAXELEN`, 0x7fff).
pub const MAX_RLE_LEN: usize = 0x7fff;
/// Shortest run written as a run (`MINRUN`).
const MIN_RUN: usize = 4;
/// Longest run in one chunk (count byte 128 + 127 = 255).
const MAX_RUN: usize = 127;
/// Longest literal chunk.
const MAX_LITERAL: usize = 128;

/// Why a scanline could not be read. The caller adds file and scanline number.
#[derive(Debug)]
pub enum ScanlineError {
    /// The stream ended before the scanline was complete.
    Eof,
    /// The bytes are not a valid scanline; the text says what was found and expected.
    Corrupt(String),
    /// The underlying reader failed.
    Io(io::Error),
}

impl fmt::Display for ScanlineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ScanlineError::Eof => write!(f, "ends early"),
            ScanlineError::Corrupt(m) => write!(f, "{m}"),
            ScanlineError::Io(e) => write!(f, "{e}"),
        }
    }
}

impl From<io::Error> for ScanlineError {
    fn from(e: io::Error) -> Self {
        if e.kind() == io::ErrorKind::UnexpectedEof {
            ScanlineError::Eof
        } else {
            ScanlineError::Io(e)
        }
    }
}

/// Read one byte, `Eof` at the end of the stream.
#[inline]
fn byte<R: BufRead + ?Sized>(r: &mut R) -> Result<u8, ScanlineError> {
    loop {
        match r.fill_buf() {
            Ok([]) => return Err(ScanlineError::Eof),
            Ok(buf) => {
                let b = buf[0];
                r.consume(1);
                return Ok(b);
            }
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e.into()),
        }
    }
}

/// Read one scanline of `line.len()` pixels in any of the three encodings (`freadcolrs`).
pub fn read_colrs<R: BufRead + ?Sized>(
    r: &mut R,
    line: &mut [[u8; 4]],
) -> Result<(), ScanlineError> {
    let len = line.len();
    if len == 0 {
        return Ok(());
    }
    let mut first = [0u8; 4];
    r.read_exact(&mut first)?;
    if first[0] != 2 || first[1] != 2 || first[2] & 0x80 != 0 {
        line[0] = first;
        return read_old(r, line, 1);
    }
    let coded = (first[2] as usize) << 8 | first[3] as usize;
    if coded != len {
        return Err(ScanlineError::Corrupt(format!(
            "run-length scanline says {coded} pixels; expected {len}"
        )));
    }
    for plane in 0..4 {
        let mut j = 0;
        while j < len {
            let code = byte(r)? as usize;
            if code > 128 {
                let n = code & 127;
                let val = byte(r)?;
                if j + n > len {
                    return Err(overrun(plane, j, n, len));
                }
                for px in &mut line[j..j + n] {
                    px[plane] = val;
                }
                j += n;
            } else {
                if j + code > len {
                    return Err(overrun(plane, j, code, len));
                }
                let mut buf = [0u8; MAX_LITERAL];
                r.read_exact(&mut buf[..code])?;
                for (px, &v) in line[j..j + code].iter_mut().zip(&buf[..code]) {
                    px[plane] = v;
                }
                j += code;
            }
        }
    }
    Ok(())
}

fn overrun(plane: usize, at: usize, n: usize, len: usize) -> ScanlineError {
    ScanlineError::Corrupt(format!(
        "run-length chunk of {n} at pixel {at} of component {plane} overruns the scanline \
         of {len} pixels"
    ))
}

/// Old-style (and flat) scanline from pixel `start` on (`oldreadcolrs`).
fn read_old<R: BufRead + ?Sized>(
    r: &mut R,
    line: &mut [[u8; 4]],
    start: usize,
) -> Result<(), ScanlineError> {
    let len = line.len();
    let mut j = start;
    let mut shift = 0u32;
    while j < len {
        let mut px = [0u8; 4];
        r.read_exact(&mut px)?;
        if px[0] == 1 && px[1] == 1 && px[2] == 1 {
            // A repeat pixel. `start >= 1` so a previous pixel exists. Counts beyond the
            // line are cut off, as Radiance does; shifts past 32 bits can only overrun.
            let count = if shift >= 32 {
                usize::MAX
            } else {
                ((px[3] as u64) << shift).min(usize::MAX as u64) as usize
            };
            let n = count.min(len - j);
            let prev = line[j - 1];
            line[j..j + n].fill(prev);
            j += n;
            shift += 8;
        } else {
            line[j] = px;
            j += 1;
            shift = 0;
        }
    }
    Ok(())
}

/// Write one scanline as `fwritecolrs` does: flat when shorter than 17 or longer than 32767
/// pixels, new RLE otherwise.
pub fn write_colrs<W: Write + ?Sized>(w: &mut W, line: &[[u8; 4]]) -> io::Result<()> {
    let mut out = Vec::with_capacity(line.len() * 4 + 4);
    encode_colrs(line, &mut out);
    w.write_all(&out)
}

/// Write one scanline flat (4 bytes per pixel, no encoding).
pub fn write_flat<W: Write + ?Sized>(w: &mut W, line: &[[u8; 4]]) -> io::Result<()> {
    w.write_all(line.as_flattened())
}

/// Append the `fwritecolrs` encoding of `line` to `out`.
pub fn encode_colrs(line: &[[u8; 4]], out: &mut Vec<u8>) {
    let len = line.len();
    if !(MIN_RLE_LEN..=MAX_RLE_LEN).contains(&len) {
        out.extend_from_slice(line.as_flattened());
        return;
    }
    out.extend_from_slice(&[2, 2, (len >> 8) as u8, (len & 0xff) as u8]);
    // Planes in order R, G, B, E.
    for plane in [0, 1, 2, 3] {
        let at = |k: usize| line[k][plane];
        let mut j = 0;
        while j < len {
            // Find the next run of at least MIN_RUN equal bytes, starting at `beg`.
            let mut beg = j;
            let mut cnt = 0;
            while beg < len {
                cnt = 1;
                while cnt < MAX_RUN && beg + cnt < len && at(beg + cnt) == at(beg) {
                    cnt += 1;
                }
                if cnt >= MIN_RUN {
                    break;
                }
                beg += cnt;
            }
            // A short run of 2-3 equal bytes just before the long run (or the end).
            if beg - j > 1 && beg - j < MIN_RUN && (j + 1..beg).all(|k| at(k) == at(j)) {
                out.push((128 + beg - j) as u8);
                out.push(at(j));
                j = beg;
            }
            while j < beg {
                let n = (beg - j).min(MAX_LITERAL);
                out.push(n as u8);
                out.extend((j..j + n).map(at));
                j += n;
            }
            if cnt >= MIN_RUN {
                out.push((128 + cnt) as u8);
                out.push(at(beg));
                j = beg + cnt;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn px(v: u8) -> [u8; 4] {
        [v, v, v, 128]
    }

    fn decode(bytes: &[u8], len: usize) -> Result<Vec<[u8; 4]>, ScanlineError> {
        let mut line = vec![[0u8; 4]; len];
        let mut c = Cursor::new(bytes);
        read_colrs(&mut c, &mut line)?;
        assert_eq!(c.position() as usize, bytes.len(), "consumed everything");
        Ok(line)
    }

    #[test]
    fn short_lines_are_flat() {
        let line: Vec<_> = (0..16).map(|i| px(i as u8 + 130)).collect();
        let mut out = Vec::new();
        encode_colrs(&line, &mut out);
        assert_eq!(out, line.as_flattened());
        assert_eq!(decode(&out, 16).unwrap(), line);
    }

    #[test]
    fn rle_layout_by_hand() {
        // 20 pixels: r plane = 5 x 200 then 15 distinct; g plane all 7; b plane alternates;
        // e plane 2,2 then 18 x 9 (short run before a long run).
        let mut line = vec![[0u8; 4]; 20];
        for (i, p) in line.iter_mut().enumerate() {
            p[0] = if i < 5 { 200 } else { i as u8 };
            p[1] = 7;
            p[2] = (i % 2) as u8;
            p[3] = if i < 2 { 2 } else { 9 };
        }
        let mut out = Vec::new();
        encode_colrs(&line, &mut out);
        let mut want = vec![2, 2, 0, 20];
        want.extend([128 + 5, 200, 15]);
        want.extend(5..20u8);
        want.extend([128 + 20, 7]);
        want.push(20);
        want.extend((0..20).map(|i| (i % 2) as u8));
        want.extend([128 + 2, 2, 128 + 18, 9]);
        assert_eq!(out, want);
        assert_eq!(decode(&out, 20).unwrap(), line);
    }

    #[test]
    fn long_runs_split_at_127_and_literals_at_128() {
        let mut line = vec![[5u8, 0, 0, 0]; 300];
        for (i, p) in line.iter_mut().enumerate() {
            p[1] = i as u8; // 300 distinct-ish bytes: literal chunks of 128, 128, 44
        }
        let mut out = Vec::new();
        encode_colrs(&line, &mut out);
        // r: 127 + 127 + 46
        assert_eq!(&out[4..10], &[255, 5, 255, 5, 128 + 46, 5]);
        assert_eq!(out[10], 128);
        assert_eq!(out[10 + 129], 128);
        assert_eq!(out[10 + 258], 44);
        assert_eq!(decode(&out, 300).unwrap(), line);
    }

    #[test]
    fn old_rle_repeats_with_shifts() {
        // pixel A, repeat 2, then B, then (1,1,1,1)(1,1,1,1): 1 + (1<<8) = 257 repeats.
        let a = [10, 20, 30, 130];
        let b = [40, 50, 60, 131];
        let mut bytes = Vec::new();
        bytes.extend(a);
        bytes.extend([1, 1, 1, 2]);
        bytes.extend(b);
        bytes.extend([1, 1, 1, 1, 1, 1, 1, 1]);
        let line = decode(&bytes, 261).unwrap();
        assert_eq!(&line[..3], &[a, a, a]);
        assert!(line[3..].iter().all(|&p| p == b));
        // Overlong repeats are cut at the end of the line, as in Radiance.
        let line = decode(&bytes, 100).unwrap();
        assert!(line[3..].iter().all(|&p| p == b));
    }

    #[test]
    fn malformed_new_rle_is_an_error() {
        // Length mismatch.
        assert!(matches!(
            decode(&[2, 2, 0, 18], 17),
            Err(ScanlineError::Corrupt(_))
        ));
        // Run overrun.
        let mut bytes = vec![2, 2, 0, 17, 128 + 18, 1];
        assert!(matches!(decode(&bytes, 17), Err(ScanlineError::Corrupt(_))));
        // Literal overrun.
        bytes = vec![2, 2, 0, 17, 18];
        assert!(matches!(decode(&bytes, 17), Err(ScanlineError::Corrupt(_))));
        // Premature end.
        bytes = vec![2, 2, 0, 17, 128 + 17, 1, 128 + 17];
        assert!(matches!(decode(&bytes, 17), Err(ScanlineError::Eof)));
        assert!(matches!(decode(&[130, 0], 17), Err(ScanlineError::Eof)));
    }

    #[test]
    fn zero_literal_chunks_are_accepted() {
        // A zero count is a legal (useless) literal chunk for Radiance's reader.
        let mut bytes = vec![2, 2, 0, 17];
        for _ in 0..4 {
            bytes.extend([0, 128 + 17, 9]);
        }
        assert_eq!(decode(&bytes, 17).unwrap(), vec![[9u8; 4]; 17]);
    }
}
