//! ASCII matrix data: a streaming number tokenizer and C-style `%.Ne` output.
//!
//! Radiance reads ascii matrices with `fscanf("%f")` (`rmatrix.c: rmx_load_ascii`), so any
//! white space (blanks, tabs, newlines, blank lines) separates numbers and the line layout
//! carries no meaning. We read one line at a time from a buffered reader (never the whole
//! file), split it into white-space separated tokens, and parse each token with nom's
//! `recognize_float_or_exceptions` (decimal, exponent, `nan`, `inf`, as `%f` accepts), so a bad
//! token is reported with its file line and column:
//! `dc.mtx:17:5: expected a number, found 'nan?'`.
//!
//! Writers print numbers as C's `%.7e` (`rmx_write_ascii`: `" %.7e"`), which Rust's `{:e}`
//! does not reproduce (no exponent sign or padding); [`push_e`] does.

use crate::error::{Error, Location, Result};
use nom::{
    IResult, Parser,
    bytes::complete::{take_while, take_while1},
    number::complete::recognize_float_or_exceptions,
};
use std::io::BufRead;

/// Longest ascii data line we accept. A row of 8760 RGB columns at `%.7e` is ~400 kB; this
/// bound only keeps a binary file mistaken for ascii from eating all memory.
pub const MAX_LINE: usize = 64 << 20;

/// Splits `input` into (leading white space, token, rest).
fn token(input: &[u8]) -> IResult<&[u8], &[u8]> {
    let (input, _) = take_while(|b: u8| b.is_ascii_whitespace()).parse(input)?;
    take_while1(|b: u8| !b.is_ascii_whitespace()).parse(input)
}

/// Parse one token as a number; the whole token must be consumed.
pub fn parse_number(tok: &[u8]) -> Option<f64> {
    let parsed: IResult<&[u8], &[u8]> = recognize_float_or_exceptions(tok);
    match parsed {
        Ok((&[], num)) => {
            let s = std::str::from_utf8(num).ok()?;
            // Rust's parser takes "nan"/"inf"/"infinity" in any case, like strtod.
            s.parse::<f64>().ok()
        }
        _ => None,
    }
}

/// Reads white-space separated numbers from a buffered stream, line by line.
pub struct AsciiScanner {
    line: Vec<u8>,
    pos: usize,
    /// File line number of `line` (1-based), counting header lines.
    line_no: usize,
    eof: bool,
}

impl AsciiScanner {
    /// `first_line` is the file line number of the first data line (header lines + 1).
    pub fn new(first_line: usize) -> Self {
        AsciiScanner {
            line: Vec::new(),
            pos: 0,
            line_no: first_line.saturating_sub(1),
            eof: false,
        }
    }

    /// Current file line (of the last token read).
    pub fn line_no(&self) -> usize {
        self.line_no
    }

    /// Load the next line; false at end of input.
    fn next_line<R: BufRead>(&mut self, r: &mut R, name: &str) -> Result<bool> {
        self.line.clear();
        self.pos = 0;
        if self.eof {
            return Ok(false);
        }
        loop {
            let buf = r.fill_buf().map_err(|e| Error::io(name, e))?;
            if buf.is_empty() {
                self.eof = true;
                if self.line.is_empty() {
                    return Ok(false);
                }
                self.line_no += 1;
                return Ok(true);
            }
            let (take, done) = match buf.iter().position(|&b| b == b'\n') {
                Some(i) => (i + 1, true),
                None => (buf.len(), false),
            };
            self.line.extend_from_slice(&buf[..take]);
            r.consume(take);
            if self.line.len() > MAX_LINE {
                return Err(Error::parse(
                    Location::line(name, self.line_no + 1),
                    format!("ascii data line longer than {MAX_LINE} bytes: is this binary data?"),
                ));
            }
            if done {
                self.line_no += 1;
                return Ok(true);
            }
        }
    }

    /// The next number, or `None` at the end of the input.
    pub fn next_number<R: BufRead>(&mut self, r: &mut R, name: &str) -> Result<Option<f64>> {
        loop {
            let rest = &self.line[self.pos.min(self.line.len())..];
            if let Ok((after, tok)) = token(rest) {
                let start = self.line.len() - after.len() - tok.len();
                self.pos = self.line.len() - after.len();
                return match parse_number(tok) {
                    Some(v) => Ok(Some(v)),
                    None => Err(self.bad_token(name, start, tok)),
                };
            }
            if !self.next_line(r, name)? {
                return Ok(None);
            }
        }
    }

    /// Number of tokens on the next non-blank line, without consuming it (used to infer
    /// NCOLS of headerless ascii, where rcontrib/rtrace write one record per line).
    pub fn count_first_line<R: BufRead>(&mut self, r: &mut R, name: &str) -> Result<usize> {
        loop {
            let rest = &self.line[self.pos.min(self.line.len())..];
            let mut n = 0;
            let mut input = rest;
            while let Ok((after, _)) = token(input) {
                n += 1;
                input = after;
            }
            if n > 0 {
                return Ok(n);
            }
            if !self.next_line(r, name)? {
                return Ok(0);
            }
        }
    }

    /// True when only white space remains in the input.
    pub fn at_end<R: BufRead>(&mut self, r: &mut R, name: &str) -> Result<bool> {
        Ok(self.count_first_line(r, name)? == 0)
    }

    fn bad_token(&self, name: &str, start: usize, tok: &[u8]) -> Error {
        const SHOW: usize = 40;
        let shown = String::from_utf8_lossy(&tok[..tok.len().min(SHOW)]);
        let more = if tok.len() > SHOW { "..." } else { "" };
        // Column in characters of the line before the token (bytes if not text).
        let col = String::from_utf8(self.line[..start].to_vec())
            .map(|s| s.chars().count())
            .unwrap_or(start)
            + 1;
        Error::parse(
            Location::at(name, self.line_no, col),
            format!("expected a number, found '{shown}{more}'"),
        )
    }
}

/// Append `v` formatted as C's `printf("%.{digits}e", v)`: `-1.2345678e+03`, `nan`, `inf`.
pub fn push_e(out: &mut Vec<u8>, v: f64, digits: usize) {
    use std::io::Write;
    if v.is_nan() {
        out.extend_from_slice(b"nan");
        return;
    }
    if v.is_infinite() {
        out.extend_from_slice(if v > 0.0 { b"inf" } else { b"-inf" });
        return;
    }
    let s = format!("{v:.digits$e}");
    let (mant, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let sign = if exp < 0 { '-' } else { '+' };
    let _ = write!(out, "{mant}e{sign}{:02}", exp.unsigned_abs());
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    fn scan_all(text: &str) -> Result<Vec<f64>> {
        let mut r = Cursor::new(text.as_bytes());
        let mut s = AsciiScanner::new(1);
        let mut v = Vec::new();
        while let Some(x) = s.next_number(&mut r, "t.mtx")? {
            v.push(x);
        }
        Ok(v)
    }

    #[test]
    fn c_style_exponents() {
        let cases = [
            (1234.5678, 7, "1.2345678e+03"),
            (0.0, 7, "0.0000000e+00"),
            (-3.5e-12, 3, "-3.500e-12"),
            (1e100, 2, "1.00e+100"),
        ];
        for (v, d, want) in cases {
            let mut out = Vec::new();
            push_e(&mut out, v, d);
            assert_eq!(String::from_utf8(out).unwrap(), want);
        }
    }

    #[test]
    fn any_white_space_layout() {
        let v = scan_all("1 2\t3\n\n 4.5e-1\r\n-6E+2\n").unwrap();
        assert_eq!(v, vec![1.0, 2.0, 3.0, 0.45, -600.0]);
    }

    #[test]
    fn bad_token_has_line_and_column() {
        let e = scan_all("1 2 3\n4 nan? 6\n").unwrap_err().to_string();
        assert_eq!(e, "t.mtx:2:3: expected a number, found 'nan?'");
        let e = scan_all("1.0.0").unwrap_err().to_string();
        assert_eq!(e, "t.mtx:1:1: expected a number, found '1.0.0'");
    }

    #[test]
    fn counts_first_line_without_consuming() {
        let mut r = Cursor::new(&b"\n1 2 3 4 5 6\n7 8 9\n"[..]);
        let mut s = AsciiScanner::new(1);
        assert_eq!(s.count_first_line(&mut r, "t").unwrap(), 6);
        assert_eq!(s.next_number(&mut r, "t").unwrap(), Some(1.0));
        assert_eq!(s.line_no(), 2);
    }
}
