//! Radiance's information header, shared by pictures, matrices and rtrace-style output.
//!
//! Layout (Radiance `src/common/header.c`, `doc/filefmts.md`):
//! ```text
//! #?RADIANCE            magic line: "#?" then an identifier
//! <any text lines>      program command lines, NAME=value variables (only at column 0)
//! FORMAT=<type>         at most one; trailing blanks are alignment padding, not part of it
//! <empty line>          ends the header ("\n", or "\r\n")
//! ```
//! Variables we interpret: `FORMAT`, `NROWS`, `NCOLS`, `NCOMP`, `WAVELENGTH_SPLITS`,
//! `BigEndian` (byte order of binary data; absent means native), `EXPOSURE` (cumulative,
//! multiply all), `COLORCORR`, `PIXASPECT`, `PRIMARIES`, `VIEW` (cumulative).
//! A line copied from another file's header by Radiance's filters is indented with a TAB,
//! which is exactly what keeps it from being read as a variable, so we only ever match at
//! column 0 as Radiance does.

use crate::error::{Error, Location, Result};
use crate::radiometry::{Channels, DEFAULT_SPLITS};
use nom::{
    IResult, Parser,
    bytes::complete::{tag, take_while, take_while1},
    character::complete::char,
    combinator::{opt, rest},
    sequence::preceded,
};
use std::io::{BufRead, Write};

/// The magic line Radiance writes (`newheader("RADIANCE", fp)`).
pub const MAGIC: &str = "#?RADIANCE";

/// Longest header line we accept. Radiance splits lines over 2048 bytes when writing; this
/// larger bound only exists so a binary file mistaken for a header cannot eat all memory.
const MAX_LINE: usize = 1 << 16;

/// One header line, classified.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HeaderLine<'a> {
    /// `NAME=value` at column 0. `value` is everything after `=`, untrimmed.
    Var { key: &'a str, value: &'a str },
    /// Anything else: command lines, comments, indented copies.
    Text(&'a str),
}

/// `NAME=value` where NAME is a word of letters, digits and `_` starting at column 0.
fn var_line(input: &str) -> IResult<&str, (&str, &str)> {
    let (input, key) = take_while1(|c: char| c.is_ascii_alphanumeric() || c == '_')(input)?;
    let (input, value) = preceded(char('='), rest).parse(input)?;
    Ok((input, (key, value)))
}

/// Classify a header line (without its newline).
pub fn classify(line: &str) -> HeaderLine<'_> {
    match var_line(line) {
        Ok((_, (key, value))) => HeaderLine::Var { key, value },
        Err(_) => HeaderLine::Text(line),
    }
}

/// Parse the magic line `#?IDENT`.
fn magic_line(input: &str) -> IResult<&str, &str> {
    preceded(tag("#?"), take_while(|c: char| !c.is_whitespace())).parse(input)
}

/// The information header of a Radiance file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Header {
    /// The identifier after `#?` (`RADIANCE`, or e.g. `RGBE` in other writers' files);
    /// `None` when the stream had no header at all (rcontrib `-h` output).
    pub magic: Option<String>,
    /// Header lines in order, without the magic line, the newline, or the empty end line.
    pub lines: Vec<String>,
    /// How many lines of the file the header took (magic and empty line included), so that
    /// readers of line-oriented data after it can report file line numbers.
    pub nlines: usize,
}

impl Header {
    /// A new header as Radiance programs start theirs.
    pub fn new() -> Self {
        Header {
            magic: Some("RADIANCE".into()),
            lines: Vec::new(),
            nlines: 0,
        }
    }

    /// Read a header if the stream starts with `#?`; otherwise return an empty header with
    /// `magic == None` and consume nothing (headerless data, as `-h` writes).
    pub fn read<R: BufRead>(r: &mut R, name: &str) -> Result<Header> {
        let buf = r.fill_buf().map_err(|e| Error::io(name, e))?;
        if !buf.starts_with(b"#?") {
            if buf.len() == 1 && buf[0] == b'#' {
                // A one-byte buffer cannot decide; read the header the slow way below.
            } else {
                return Ok(Header {
                    magic: None,
                    lines: Vec::new(),
                    nlines: 0,
                });
            }
        }
        let mut header = Header {
            magic: None,
            lines: Vec::new(),
            nlines: 0,
        };
        let mut raw = Vec::new();
        loop {
            raw.clear();
            let n = read_limited_line(r, &mut raw, name)?;
            header.nlines += 1;
            let line_no = header.nlines;
            if n == 0 {
                return Err(Error::parse(
                    Location::line(name, line_no),
                    "file ends inside the header: expected an empty line to close it",
                ));
            }
            if raw.last() == Some(&b'\n') {
                raw.pop();
                if raw.last() == Some(&b'\r') {
                    raw.pop();
                }
            } else if raw.len() >= MAX_LINE {
                return Err(Error::parse(
                    Location::line(name, line_no),
                    format!("header line longer than {MAX_LINE} bytes: is this a Radiance file?"),
                ));
            } else {
                return Err(Error::parse(
                    Location::line(name, line_no),
                    "file ends inside the header: expected an empty line to close it",
                ));
            }
            let line = std::str::from_utf8(&raw).map_err(|_| {
                Error::parse(
                    Location::line(name, line_no),
                    "header line is not text (UTF-8)",
                )
            })?;
            if line_no == 1 {
                let (_, ident) = magic_line(line).map_err(|_| {
                    Error::parse(
                        Location::line(name, 1),
                        "expected a header starting with '#?'",
                    )
                })?;
                header.magic = Some(ident.to_string());
                continue;
            }
            if line.is_empty() {
                return Ok(header);
            }
            header.lines.push(line.to_string());
        }
    }

    /// Iterate over the variables `(key, raw value)` in order.
    pub fn vars(&self) -> impl Iterator<Item = (&str, &str)> {
        self.lines.iter().filter_map(|l| match classify(l) {
            HeaderLine::Var { key, value } => Some((key, value)),
            HeaderLine::Text(_) => None,
        })
    }

    /// All values of variable `key`, in order, untrimmed.
    pub fn get_all<'a, 'k>(&'a self, key: &'k str) -> impl Iterator<Item = &'a str> + use<'a, 'k> {
        self.vars().filter(move |(k, _)| *k == key).map(|(_, v)| v)
    }

    /// The last value of `key`, trimmed at both ends (Radiance's `formatval` trims the
    /// trailing alignment blanks of `FORMAT=`; for numbers trimming is harmless).
    pub fn get(&self, key: &str) -> Option<&str> {
        self.get_all(key).last().map(str::trim)
    }

    /// The data format (`FORMAT=` value), trimmed.
    pub fn format(&self) -> Option<&str> {
        self.get("FORMAT")
    }

    /// Parse an integer variable, reporting the header line on failure.
    pub fn get_usize(&self, key: &str, name: &str) -> Result<Option<usize>> {
        match self.get(key) {
            None => Ok(None),
            Some(v) => v.parse::<usize>().map(Some).map_err(|_| {
                Error::parse(
                    Location::line(name, self.line_of(key).unwrap_or(1)),
                    format!("{key}={v}: expected a non-negative integer"),
                )
            }),
        }
    }

    /// File line number (1-based) of the last occurrence of variable `key`.
    pub fn line_of(&self, key: &str) -> Option<usize> {
        self.lines
            .iter()
            .rposition(|l| matches!(classify(l), HeaderLine::Var { key: k, .. } if k == key))
            .map(|i| i + 2)
    }

    /// `BigEndian=1|0`; `None` when absent (data is then in native order).
    pub fn big_endian(&self, name: &str) -> Result<Option<bool>> {
        match self.get("BigEndian") {
            None => Ok(None),
            Some("1") => Ok(Some(true)),
            Some("0") => Ok(Some(false)),
            Some(v) => Err(Error::parse(
                Location::line(name, self.line_of("BigEndian").unwrap_or(1)),
                format!("BigEndian={v}: expected 0 or 1"),
            )),
        }
    }

    /// Product of all `EXPOSURE=` values (cumulative, `color.h`), 1 when absent.
    pub fn exposure(&self) -> f64 {
        self.get_all("EXPOSURE")
            .filter_map(|v| parse_f64(v.trim()))
            .product()
    }

    /// Product of all `COLORCORR=` triples (cumulative), `[1,1,1]` when absent.
    pub fn colorcorr(&self) -> [f64; 3] {
        let mut cc = [1.0; 3];
        for v in self.get_all("COLORCORR") {
            let vals: Vec<f64> = v.split_whitespace().filter_map(parse_f64).collect();
            if vals.len() == 3 {
                for i in 0..3 {
                    cc[i] *= vals[i];
                }
            }
        }
        cc
    }

    /// Product of all `PIXASPECT=` values, 1 when absent.
    pub fn pixaspect(&self) -> f64 {
        self.get_all("PIXASPECT")
            .filter_map(|v| parse_f64(v.trim()))
            .product()
    }

    /// The channel layout a file declares: `NCOMP` (default 3, as Radiance's readers
    /// assume) and `WAVELENGTH_SPLITS` (default [`DEFAULT_SPLITS`]).
    pub fn channels(&self, name: &str) -> Result<Channels> {
        let ncomp = self.get_usize("NCOMP", name)?.unwrap_or(3);
        if ncomp == 0 {
            return Err(Error::parse(
                Location::line(name, self.line_of("NCOMP").unwrap_or(1)),
                "NCOMP=0: expected at least one component",
            ));
        }
        let splits = self.wavelength_splits(name)?.unwrap_or(DEFAULT_SPLITS);
        Ok(Channels { ncomp, splits })
    }

    /// Write `NCOMP=` and, for spectral layouts, `WAVELENGTH_SPLITS=` (note Radiance's blank
    /// after `=`, `fputwlsplit`).
    pub fn set_channels(&mut self, c: Channels) {
        self.set("NCOMP", c.ncomp);
        if c.ncomp > 3 {
            let s = c.splits;
            self.set(
                "WAVELENGTH_SPLITS",
                format!(" {} {} {} {}", s[0], s[1], s[2], s[3]),
            );
        } else {
            self.remove("WAVELENGTH_SPLITS");
        }
    }

    /// `WAVELENGTH_SPLITS= lmax lRG lGB lmin`, if present and well formed.
    pub fn wavelength_splits(&self, name: &str) -> Result<Option<[f64; 4]>> {
        let Some(v) = self.get("WAVELENGTH_SPLITS") else {
            return Ok(None);
        };
        let vals: Vec<f64> = v.split_whitespace().filter_map(parse_f64).collect();
        if vals.len() != 4 {
            return Err(Error::parse(
                Location::line(name, self.line_of("WAVELENGTH_SPLITS").unwrap_or(1)),
                format!("WAVELENGTH_SPLITS={v}: expected 4 wavelengths in nm"),
            ));
        }
        Ok(Some([vals[0], vals[1], vals[2], vals[3]]))
    }

    /// Remove every occurrence of variable `key` at column 0.
    pub fn remove(&mut self, key: &str) {
        self.lines
            .retain(|l| !matches!(classify(l), HeaderLine::Var { key: k, .. } if k == key));
    }

    /// Replace variable `key` (all occurrences) by one `key=value` line at the end.
    pub fn set(&mut self, key: &str, value: impl std::fmt::Display) {
        self.remove(key);
        self.lines.push(format!("{key}={value}"));
    }

    /// Append a text line (a command line, a comment).
    pub fn push(&mut self, line: impl Into<String>) {
        self.lines.push(line.into());
    }

    /// Append the command line of the running program, as Radiance's `printargs` does
    /// (words containing blanks are quoted).
    pub fn push_command<I, S>(&mut self, args: I)
    where
        I: IntoIterator<Item = S>,
        S: AsRef<str>,
    {
        let words: Vec<String> = args.into_iter().map(|a| quote_word(a.as_ref())).collect();
        // No command (a library caller's config): no line, since an empty line would end
        // the header there and leave the lines after it in the data.
        if !words.is_empty() {
            self.lines.push(words.join(" "));
        }
    }

    /// Append `CAPDATE=` and `GMT=` lines (both UTC here; Radiance writes local time in
    /// CAPDATE, which on servers is usually UTC anyway). `SOURCE_DATE_EPOCH` (seconds; the
    /// reproducible-builds convention) replaces the clock, so that runs on different
    /// machines or at different times, e.g. the shards of one job, can match byte for byte.
    pub fn push_dates(&mut self) {
        let epoch = std::env::var("SOURCE_DATE_EPOCH")
            .ok()
            .and_then(|s| s.trim().parse::<i64>().ok());
        let now = epoch.unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|d| d.as_secs() as i64)
                .unwrap_or(0)
        });
        let stamp = format_utc(now);
        self.lines.push(format!("CAPDATE= {stamp}"));
        self.lines.push(format!("GMT= {stamp}"));
    }

    /// Copy another file's header under a `name:` line, indented with a TAB so that none of
    /// its variables take effect (what pcomb, rcomb and pfilt do).
    pub fn push_indented(&mut self, name: &str, other: &Header) {
        self.lines.push(format!("{name}:"));
        for l in &other.lines {
            self.lines.push(format!("\t{l}"));
        }
    }

    /// Write the header: magic, lines in order with any `FORMAT=` line moved last, empty
    /// line. With `align > 1` the FORMAT line is padded with blanks so that the data starts
    /// at a multiple of `align` bytes, as `fputformat` does for seekable binary matrices.
    pub fn write<W: Write + ?Sized>(&self, w: &mut W, align: usize) -> std::io::Result<usize> {
        let mut out = Vec::with_capacity(256);
        out.extend_from_slice(b"#?");
        out.extend_from_slice(self.magic.as_deref().unwrap_or("RADIANCE").as_bytes());
        out.push(b'\n');
        let mut format = None;
        for l in &self.lines {
            if let HeaderLine::Var {
                key: "FORMAT",
                value,
            } = classify(l)
            {
                format = Some(value.trim().to_string());
                continue;
            }
            out.extend_from_slice(l.as_bytes());
            out.push(b'\n');
        }
        if let Some(f) = format {
            out.extend_from_slice(b"FORMAT=");
            out.extend_from_slice(f.as_bytes());
            if align > 1 {
                // +2 for the newline ending FORMAT and the empty line.
                let len = out.len() + 2;
                let pad = (align - len % align) % align;
                out.extend(std::iter::repeat_n(b' ', pad));
            }
            out.push(b'\n');
        }
        out.push(b'\n');
        w.write_all(&out)?;
        Ok(out.len())
    }
}

/// Read one line (up to and including `\n`) but never more than `MAX_LINE` bytes.
fn read_limited_line<R: BufRead>(r: &mut R, out: &mut Vec<u8>, name: &str) -> Result<usize> {
    let mut total = 0;
    loop {
        let buf = r.fill_buf().map_err(|e| Error::io(name, e))?;
        if buf.is_empty() {
            return Ok(total);
        }
        let room = MAX_LINE - out.len();
        let (take, done) = match buf.iter().take(room).position(|&b| b == b'\n') {
            Some(i) => (i + 1, true),
            None => (buf.len().min(room), buf.len() >= room),
        };
        out.extend_from_slice(&buf[..take]);
        r.consume(take);
        total += take;
        if done {
            return Ok(total);
        }
    }
}

/// Quote a word for a header command line if it contains blanks or quotes.
fn quote_word(w: &str) -> String {
    if w.is_empty() {
        "''".into()
    } else if w
        .chars()
        .any(|c| c.is_whitespace() || c == '"' || c == '\'')
    {
        if w.contains('"') {
            format!("'{w}'")
        } else {
            format!("\"{w}\"")
        }
    } else {
        w.to_string()
    }
}

/// Parse a float the way C's `atof` accepts well-formed numbers (no trailing garbage).
pub fn parse_f64(s: &str) -> Option<f64> {
    let s = s.trim();
    if s.is_empty() {
        return None;
    }
    s.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// `YYYY:MM:DD HH:MM:SS` in UTC (Radiance's `fputnow` layout).
fn format_utc(secs: i64) -> String {
    let days = secs.div_euclid(86_400);
    let sod = secs.rem_euclid(86_400);
    // Civil-from-days (H. Hinnant's algorithm, public domain description).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let y = yoe + era * 400;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = if m <= 2 { y + 1 } else { y };
    format!(
        "{y:04}:{m:02}:{d:02} {:02}:{:02}:{:02}",
        sod / 3600,
        (sod / 60) % 60,
        sod % 60
    )
}

/// Parse a `FORMAT=` value into its name, ignoring padding (for callers holding raw values).
pub fn format_name(value: &str) -> &str {
    let parsed: IResult<&str, Option<&str>> =
        opt(take_while1(|c: char| !c.is_whitespace())).parse(value.trim_start());
    match parsed {
        Ok((_, Some(v))) => v,
        _ => "",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    #[test]
    fn reads_rcontrib_header_with_padding() {
        let data = b"#?RADIANCE\nrcontrib -I+ -ab 1\nSOFTWARE= RADIANCE 6.0a\nNCOMP=3\nNCOLS=145\nBigEndian=0\nFORMAT=float  \n\nDATA";
        let mut r = Cursor::new(&data[..]);
        let h = Header::read(&mut r, "t").unwrap();
        assert_eq!(h.magic.as_deref(), Some("RADIANCE"));
        assert_eq!(h.format(), Some("float"));
        assert_eq!(h.get_usize("NCOLS", "t").unwrap(), Some(145));
        assert_eq!(h.big_endian("t").unwrap(), Some(false));
        assert_eq!(h.nlines, 8);
        let mut rest = String::new();
        std::io::Read::read_to_string(&mut r, &mut rest).unwrap();
        assert_eq!(rest, "DATA");
    }

    #[test]
    fn indented_lines_are_not_variables() {
        let data = b"#?RADIANCE\nin.hdr:\n\tEXPOSURE=4\nEXPOSURE=2\nEXPOSURE=3\n\n";
        let h = Header::read(&mut Cursor::new(&data[..]), "t").unwrap();
        assert_eq!(h.exposure(), 6.0);
    }

    #[test]
    fn headerless_stream_consumes_nothing() {
        let data = b"1.0 2.0 3.0\n";
        let mut r = Cursor::new(&data[..]);
        let h = Header::read(&mut r, "t").unwrap();
        assert!(h.magic.is_none());
        assert_eq!(r.position(), 0);
    }

    #[test]
    fn truncated_header_is_an_error_with_line() {
        let data = b"#?RADIANCE\nNCOLS=3\n";
        let e = Header::read(&mut Cursor::new(&data[..]), "m.mtx").unwrap_err();
        assert!(e.to_string().starts_with("m.mtx:3:"), "{e}");
    }

    #[test]
    fn padding_aligns_data_start() {
        for align in [4usize, 8] {
            let mut h = Header::new();
            h.push("rmtx -ff x");
            h.set("NCOMP", 3);
            h.set("FORMAT", if align == 4 { "float" } else { "double" });
            let mut out = Vec::new();
            let n = h.write(&mut out, align).unwrap();
            assert_eq!(n % align, 0);
            let back = Header::read(&mut Cursor::new(&out[..]), "t").unwrap();
            assert_eq!(back.format(), h.format());
        }
    }

    #[test]
    fn write_read_round_trip() {
        let mut h = Header::new();
        h.push_command(["rdc", "-ab", "5", "a b.rad"]);
        h.set("NROWS", 2);
        h.set("FORMAT", "ascii");
        h.set("NCOLS", 146);
        let mut out = Vec::new();
        h.write(&mut out, 1).unwrap();
        let text = String::from_utf8(out.clone()).unwrap();
        assert!(text.ends_with("FORMAT=ascii\n\n"), "{text}");
        assert!(text.contains("rdc -ab 5 \"a b.rad\"\n"));
        let back = Header::read(&mut Cursor::new(&out[..]), "t").unwrap();
        assert_eq!(back.get_usize("NCOLS", "t").unwrap(), Some(146));
    }

    #[test]
    fn empty_command_keeps_the_header_whole() {
        // A library config without a command line (SkyMatrixConfig::new) once wrote an
        // empty line here, which ended the header before LATLONG= and FORMAT=.
        let mut h = Header::new();
        h.push_command(Vec::<String>::new());
        h.set("NCOLS", 8760);
        let mut out = Vec::new();
        h.write(&mut out, 1).unwrap();
        let back = Header::read(&mut Cursor::new(&out[..]), "t").unwrap();
        assert_eq!(back.get_usize("NCOLS", "t").unwrap(), Some(8760));
    }

    #[test]
    fn utc_format() {
        assert_eq!(format_utc(0), "1970:01:01 00:00:00");
        assert_eq!(format_utc(1_700_000_000), "2023:11:14 22:13:20");
    }

    #[test]
    fn channels_round_trip() {
        let c = Channels::spectral(9, 380.0, 780.0).unwrap();
        let mut h = Header::new();
        h.set_channels(c);
        assert!(
            h.lines
                .iter()
                .any(|l| l == "WAVELENGTH_SPLITS= 780 588 480 380")
        );
        assert_eq!(h.channels("t").unwrap(), c);
    }
}
